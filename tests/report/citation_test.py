#!/usr/bin/python3
"""CITATION.cff as cmake/citation.cmake generates it (scripts/citation.cmake): valid YAML with
the authors, title and version a citation needs, and `repository-code` exactly when a repository
URL is configured (never a made-up one). Also checks the committed file the same way.

Usage: citation_test.py CMAKE SOURCE_DIR VERSION SCRATCH_DIR
"""
import os
import subprocess
import sys

import yaml  # python3-yaml (scripts/install-deps.sh)


def generate(cmake: str, source: str, version: str, url: str, output: str):
    return subprocess.run(
        [cmake, f"-DVERSION={version}", f"-DREPOSITORY_URL={url}", f"-DOUTPUT={output}", "-P",
         os.path.join(source, "scripts", "citation.cmake")],
        capture_output=True, text=True)


def problems_of(path: str, version: str, url: str) -> list[str]:
    with open(path, encoding="utf-8") as f:
        try:
            cff = yaml.safe_load(f)
        except yaml.YAMLError as error:
            return [f"{path}: not YAML: {error}"]
    problems = []
    if str(cff.get("cff-version")) != "1.2.0":
        problems.append(f"{path}: cff-version is not 1.2.0")
    for key in ("title", "message", "license", "abstract"):
        if not cff.get(key):
            problems.append(f"{path}: no `{key}`")
    if str(cff.get("version")) != version:
        problems.append(f"{path}: version {cff.get('version')!r} is not {version}")
    authors = cff.get("authors") or []
    if not authors:
        problems.append(f"{path}: no authors")
    for author in authors:
        if not (author.get("name") or (author.get("family-names") and author.get("given-names"))):
            problems.append(f"{path}: author {author!r} has neither a name nor family and given names")
    if url:
        if cff.get("repository-code") != url:
            problems.append(f"{path}: repository-code is {cff.get('repository-code')!r}, not {url}")
    elif "repository-code" in cff:
        problems.append(f"{path}: repository-code {cff['repository-code']!r} with no URL configured")
    return problems


def main() -> int:
    cmake, source, version, scratch = sys.argv[1:5]
    os.makedirs(scratch, exist_ok=True)
    problems = []
    committed = os.path.join(source, "CITATION.cff")
    with open(committed, encoding="utf-8") as f:
        committed_url = (yaml.safe_load(f) or {}).get("repository-code", "")
    problems += problems_of(committed, version, committed_url)
    for url in ("", "https://example.org/geomint.git"):
        output = os.path.join(scratch, "with-url.cff" if url else "without-url.cff")
        result = generate(cmake, source, version, url, output)
        if result.returncode != 0:
            problems.append(f"generating with URL {url!r} failed: {result.stderr}")
            continue
        problems += problems_of(output, version, url)
    # A URL that would break the YAML or the BibTeX is refused, not written.
    bad = generate(cmake, source, version, "https://example.org/a b", os.path.join(scratch, "bad"))
    if bad.returncode == 0 or "GEOMINT_REPOSITORY_URL" not in bad.stderr:
        problems.append("a URL with a space was accepted")
    for problem in problems:
        print(problem)
    print(f"citation: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
