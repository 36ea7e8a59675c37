#!/usr/bin/python3
"""`make readme-tables` (docs/METHODS.md, "Adding a method or a problem"): rewrites the method
table of docs/METHODS.md (the lines between <!-- methods:begin --> / <!-- methods:end -->) and the
problem table of docs/PROBLEMS.md (<!-- problems:begin --> / <!-- problems:end -->) with
`geomint list {methods,problems} --markdown`. tests/cli_test.cpp
(Readme.TablesAreTheOutputOfListMarkdown) fails until they agree.

Usage: readme_tables.py GEOMINT METHODS.md PROBLEMS.md   (Python 3 standard library only)
"""
import os
import subprocess
import sys
import tempfile


def replace_block(lines: list[str], marker: str, rows: list[str], readme: str) -> list[str]:
    begin, end = f"<!-- {marker}:begin -->", f"<!-- {marker}:end -->"
    if lines.count(begin) != 1 or lines.count(end) != 1 or lines.index(begin) > lines.index(end):
        sys.exit(f"readme_tables: {readme} needs exactly one '{begin}' before one '{end}'")
    return lines[: lines.index(begin) + 1] + rows + lines[lines.index(end) :]


def rewrite(geomint: str, marker: str, path: str) -> None:
    with open(path, encoding="utf-8") as file:
        text = file.read()
    listing = subprocess.run([geomint, "list", marker, "--markdown"], check=True,
                             capture_output=True, text=True, encoding="utf-8").stdout
    lines = replace_block(text.split("\n"), marker, listing.rstrip("\n").split("\n"), path)
    new_text = "\n".join(lines)
    if new_text == text:
        print(f"readme_tables: the {marker} table of {path} is up to date")
        return
    # Written next to the file and renamed onto it, so an interrupted run leaves it intact.
    folder = os.path.dirname(os.path.abspath(path))
    with tempfile.NamedTemporaryFile("w", encoding="utf-8", dir=folder, delete=False) as file:
        file.write(new_text)
    os.chmod(file.name, os.stat(path).st_mode)
    os.replace(file.name, path)
    print(f"readme_tables: rewrote the {marker} table of {path}")


def main() -> None:
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    geomint, methods, problems = sys.argv[1:]
    rewrite(geomint, "methods", methods)
    rewrite(geomint, "problems", problems)


if __name__ == "__main__":
    main()
