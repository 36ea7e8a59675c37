#!/usr/bin/python3
"""`make readme-tables` (README.md, "Adding a method or a problem"): rewrites the method and
problem tables of README.md, the lines between <!-- methods:begin --> / <!-- methods:end --> and
<!-- problems:begin --> / <!-- problems:end -->, with `geomint list {methods,problems} --markdown`.
tests/cli_test.cpp (Readme.TablesAreTheOutputOfListMarkdown) fails until they agree.

Usage: readme_tables.py GEOMINT README.md   (Python 3 standard library only)
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


def main() -> None:
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    geomint, readme = sys.argv[1], sys.argv[2]
    with open(readme, encoding="utf-8") as file:
        text = file.read()
    lines = text.split("\n")
    for marker in ("methods", "problems"):
        listing = subprocess.run([geomint, "list", marker, "--markdown"], check=True,
                                 capture_output=True, text=True, encoding="utf-8").stdout
        lines = replace_block(lines, marker, listing.rstrip("\n").split("\n"), readme)
    new_text = "\n".join(lines)
    if new_text == text:
        print(f"readme_tables: {readme} is up to date")
        return
    # Written next to the README and renamed onto it, so an interrupted run leaves it intact.
    folder = os.path.dirname(os.path.abspath(readme))
    with tempfile.NamedTemporaryFile("w", encoding="utf-8", dir=folder, delete=False) as file:
        file.write(new_text)
    os.chmod(file.name, os.stat(readme).st_mode)
    os.replace(file.name, readme)
    print(f"readme_tables: rewrote the methods and problems tables of {readme}")


if __name__ == "__main__":
    main()
