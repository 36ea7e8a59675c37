#!/usr/bin/python3
"""`--format json` of run, order and sweep (docs/USAGE.md "JSON tables"): every JSON table equals
its CSV parsed (provenance, columns, every cell; numbers bit-identical), validates against
docs/schema/table.schema.json, and stays valid JSON when a spec or path holds control characters
or invalid UTF-8. Usage: json_tables_test.py GEOMINT SOURCE_DIR CHECK (sweep, run_order, escape)."""
import csv
import io
import json
import os
import struct
import subprocess
import sys
import tempfile

import jsonschema

GEOMINT, SOURCE, CHECK = sys.argv[1], sys.argv[2], sys.argv[3]
with open(os.path.join(SOURCE, "docs", "schema", "table.schema.json"), encoding="utf-8") as f:
    SCHEMA = json.load(f)
jsonschema.Draft202012Validator.check_schema(SCHEMA)
VALIDATOR = jsonschema.Draft202012Validator(SCHEMA)
NON_FINITE = {"nan", "-nan", "inf", "-inf"}
failures = []


def fail(message):
    failures.append(message)
    print("FAIL:", message)


def geomint(*arguments, expect=0, **kwargs):
    arguments = (arguments[0], "--quiet", *arguments[1:])  # the verb first
    done = subprocess.run([GEOMINT, *arguments], capture_output=True, timeout=300, **kwargs)
    if expect is not None and done.returncode != expect:
        fail(f"{arguments}: exit {done.returncode}, expected {expect}: {done.stderr!r}")
    return done


def parse_csv(data):
    """The CSV as geomint writes it: `# key: value` lines, a header, rows; empty cell → None."""
    text = data.decode("utf-8", errors="surrogateescape")
    provenance, body = {}, []
    for line in text.splitlines(keepends=True):
        if line.startswith("# ") and not body and ": " in line:
            key, value = line[2:].rstrip("\n").split(": ", 1)
            provenance.setdefault(key, value)
        elif not line.startswith("#"):
            body.append(line)
    rows = list(csv.reader(io.StringIO("".join(body))))
    columns = rows[0]
    return provenance, columns, [[cell if cell else None for cell in row] for row in rows[1:]]


def bits(value):
    return struct.pack("<d", float(value))


def fixed(text):
    """What the JSON writer makes of a CSV string: invalid UTF-8 → U+FFFD."""
    return text.encode("utf-8", errors="surrogateescape").decode("utf-8", errors="replace")


def compare(csv_bytes, json_bytes, name, ignore=()):
    """The JSON document equals the CSV parsed (but the provenance keys `ignore`, which differ
    between two invocations); it is strict JSON and valid against the schema."""
    try:
        document = json.loads(json_bytes.decode("utf-8"),
                              parse_constant=lambda c: fail(f"{name}: bare {c} in JSON"))
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        fail(f"{name}: not valid UTF-8 JSON: {error}")
        return None
    for error in VALIDATOR.iter_errors(document):
        fail(f"{name}: schema: {error.message} at {list(error.absolute_path)}")
    provenance, columns, rows = parse_csv(csv_bytes)
    json_provenance = {k: v for k, v in document["provenance"].items() if k not in ignore}
    if json_provenance != {fixed(k): fixed(v) for k, v in provenance.items() if k not in ignore}:
        fail(f"{name}: provenance differs")
    if list(document["provenance"]) != [fixed(k) for k in provenance]:
        fail(f"{name}: provenance order differs")
    if document["columns"] != columns:
        fail(f"{name}: columns {document['columns']} != {columns}")
    if list(document["types"]) != columns:
        fail(f"{name}: types do not list the columns in order")
    if len(document["rows"]) != len(rows):
        fail(f"{name}: {len(document['rows'])} rows, the CSV has {len(rows)}")
    for index, (json_row, csv_row) in enumerate(zip(document["rows"], rows)):
        if list(json_row) != columns:
            fail(f"{name} row {index}: keys {list(json_row)} != columns")
        for column, cell in zip(columns, csv_row):
            value = json_row.get(column)
            where = f"{name} row {index} column {column}"
            if cell is None:
                if value is not None:
                    fail(f"{where}: {value!r} for an empty cell")
            elif document["types"][column] == "number":
                if isinstance(value, str):
                    if value not in NON_FINITE or value != cell:
                        fail(f"{where}: {value!r} for {cell!r}")
                elif not isinstance(value, (int, float)) or bits(value) != bits(cell):
                    fail(f"{where}: {value!r} is not the double of {cell!r}")
            elif value != fixed(cell):
                fail(f"{where}: {value!r} != {cell!r}")
    return document


SCENE = """title = 'json tables'
[[runs]]
label = 'a'
problems = ['pendulum:theta0=1.5', 'kepler:e=0.6']
methods = ['stormer_verlet', 'rk4', 'explicit_euler']
dt = 0.05
t_end = 2.0
[[runs]]
label = 'blowup'
problems = ['harmonic']
methods = ['explicit_euler']
dt = 3.0
t_end = 200.0
[[orders]]
label = 'o'
problems = ['harmonic']
methods = ['stormer_verlet', 'explicit_euler']
dt0 = 0.1
levels = 4
t_end = 1.0
[[stability]]
label = 's'
problems = ['harmonic']
methods = ['stormer_verlet']
homega_min = 0.5
homega_max = 4.0
periods = 5.0
min_steps = 100
"""


def check_sweep(work):
    scene = os.path.join(work, "scene", "scene.toml")
    os.makedirs(os.path.dirname(scene))
    with open(scene, "w", encoding="utf-8") as f:
        f.write(SCENE)
    csv_only = os.path.join(work, "csv")
    both = os.path.join(work, "both")
    geomint("sweep", scene, "--out", csv_only, "--no-timing")
    geomint("sweep", scene, "--out", both, "--no-timing", "--format", "json")
    tables = ["summary", "order", "order_points", "stability"]
    for table in tables:
        csv_path = os.path.join(both, table + ".csv")
        json_path = os.path.join(both, table + ".json")
        if not os.path.exists(json_path):
            fail(f"sweep --format json wrote no {table}.json")
            continue
        if os.path.exists(os.path.join(csv_only, table + ".json")):
            fail(f"sweep without --format json wrote {table}.json")
        with open(csv_path, "rb") as c, open(json_path, "rb") as j:
            compare(c.read(), j.read(), f"sweep {table}")
    # Non-finite or empty cells must have been met (the blow-up run), or the check proved little.
    with open(os.path.join(both, "summary.json"), encoding="utf-8") as f:
        summary = json.load(f)
    cells = [v for row in summary["rows"] for v in row.values()]
    if None not in cells:
        fail("the sweep's summary has no empty cell to check")
    # CSV stays as it was: the same tables, and the same cells but provenance (date, command).
    for table in tables:
        with open(os.path.join(csv_only, table + ".csv"), "rb") as a, \
                open(os.path.join(both, table + ".csv"), "rb") as b:
            if parse_csv(a.read())[1:] != parse_csv(b.read())[1:]:
                fail(f"{table}.csv differs with --format json")
    # The JSON of a folder already swept (a merged one, say): --markdown-only --format json.
    for table in tables:
        os.remove(os.path.join(both, table + ".json"))
    geomint("sweep", scene, "--out", both, "--markdown-only", "--format", "json")
    for table in tables:
        with open(os.path.join(both, table + ".csv"), "rb") as c, \
                open(os.path.join(both, table + ".json"), "rb") as j:
            compare(c.read(), j.read(), f"sweep --markdown-only {table}")
    # A later sweep without --format json rewrites the CSVs: no JSON of the earlier one may stay.
    geomint("sweep", scene, "--out", both, "--no-timing")
    stale = [table + ".json" for table in tables
             if os.path.exists(os.path.join(both, table + ".json"))]
    if stale:
        fail(f"sweep without --format json left the earlier JSON tables: {stale}")
    leftovers = [name for name in os.listdir(both) if name.endswith(".tmp")]
    if leftovers:
        fail(f"temporaries left: {leftovers}")


def check_run_order(work):
    # The last blows up to non-finite values (inf, -nan cells and the status nan).
    cases = [("pendulum:theta0=1.5", "stormer_verlet", "0.05", "3"),
             ("kepler:e=0.6", "rk4", "0.01", "3"),
             ("harmonic", "explicit_euler", "3.0", "3"),
             ("spring_chain:n=4", "implicit_midpoint", "0.05", "3"),
             ("harmonic", "explicit_euler", "3.0", "20000")]
    non_finite_seen = set()
    for problem, method, dt, t_end in cases:
        common = ["--problem", problem, "--method", method, "--dt", dt, "--t-end", t_end,
                  "--diverge-factor", "0"]
        csv_out = os.path.join(work, "run.csv")
        json_out = os.path.join(work, "run.json")
        first = geomint("run", *common, "--timing-repeats", "0", "--out", csv_out, expect=None)
        if first.returncode not in (0, 1):
            fail(f"run {problem} {method}: exit {first.returncode}: {first.stderr!r}")
            continue
        geomint("run", *common, "--timing-repeats", "0", "--format", "json", "--out",
                json_out, expect=first.returncode)
        with open(csv_out, "rb") as c, open(json_out, "rb") as j:
            csv_doc, json_doc = c.read(), j.read()
        # Two invocations of the same run: all agrees but the command and date lines.
        document = compare(csv_doc, json_doc, f"run {problem} {method}",
                           ignore=("command", "date"))
        if document:
            non_finite_seen |= {v for row in document["rows"] for v in row.values()
                                if isinstance(v, str) and v in NON_FINITE}
            if document["types"].get("status") != "string":
                fail(f"run {problem} {method}: status is not a string column")
        # Without --out the same document goes to stdout.
        stdout = geomint("run", *common, "--timing-repeats", "0", "--format", "json",
                         expect=first.returncode).stdout
        compare(csv_doc, stdout, f"run stdout {problem} {method}", ignore=("command", "date"))
        ladder_csv = os.path.join(work, "order.csv")
        ladder_json = os.path.join(work, "order.json")
        if t_end != "3":
            continue
        order = ["--problem", problem, "--method", method, "--dt", dt, "--t-end", "1",
                 "--levels", "3"]
        first = geomint("order", *order, "--out", ladder_csv, expect=None)
        if first.returncode not in (0, 1):
            fail(f"order {problem} {method}: exit {first.returncode}: {first.stderr!r}")
            continue
        geomint("order", *order, "--out", ladder_json, "--format", "json",
                expect=first.returncode)
        with open(ladder_csv, "rb") as c, open(ladder_json, "rb") as j:
            compare(c.read(), j.read(), f"order {problem} {method}", ignore=("command", "date"))


    if "inf" not in non_finite_seen or not {"nan", "-nan"} & non_finite_seen:
        fail(f"the runs met only the non-finite cells {non_finite_seen}")


def check_escape(work):
    # A path with control characters and invalid UTF-8 lands in the provenance's command line.
    odd = os.path.join(work.encode(), b"tab\tnl\nesc\x1bbad\xff\xfe.json")
    done = subprocess.run([GEOMINT.encode(), b"run", b"--quiet", b"--problem", b"harmonic",
                           b"--method", b"rk4", b"--dt", b"0.1", b"--t-end", b"1",
                           b"--timing-repeats", b"0", b"--format", b"json", b"--out", odd],
                          capture_output=True, timeout=120)
    if done.returncode != 0:
        fail(f"run --out ODD: exit {done.returncode}: {done.stderr!r}")
        return
    with open(odd, "rb") as f:
        data = f.read()
    try:
        document = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        fail(f"escape: not valid UTF-8 JSON: {error}")
        return
    for error in VALIDATOR.iter_errors(document):
        fail(f"escape: schema: {error.message}")
    # The CSV's `# command:` line is one line (a newline there would start the table early): the
    # newline is a space in CSV and JSON alike; the tab and escape are kept, the bytes → U+FFFD.
    command = document["provenance"]["command"]
    if "tab\tnl esc\x1bbad\ufffd\ufffd.json" not in command:
        fail(f"escape: the command line lost the odd path: {command!r}")
    if document["columns"][:2] != ["problem", "method"]:  # the header, not the path's tail
        fail(f"escape: columns {document['columns'][:2]}...")
    if b"\t" in data or b"\x1b" in data:
        fail("escape: a raw control character in the JSON text")


with tempfile.TemporaryDirectory(prefix="geomint-json-") as work:
    {"sweep": check_sweep, "run_order": check_run_order, "escape": check_escape}[CHECK](work)
if failures:
    print(f"{len(failures)} failure(s)")
    sys.exit(1)
print("ok")
