"""Reading geomint's CSV tables from the scene post-processing scripts (scripts/*.py): the
provenance lines (`# geomint: ...`, `# date: ...`) and the rows, as docs/USAGE.md describes the
format."""
import csv


def read_table(path):
    """Rows of a geomint CSV (provenance lines start with '#') and its provenance lines."""
    with open(path, newline="") as handle:
        lines = handle.read().splitlines()
    provenance = [line for line in lines if line.startswith("#")]
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    return rows, provenance
