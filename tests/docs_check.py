#!/usr/bin/python3
"""Checks that keep the documentation honest (registered in tests/CMakeLists.txt as ctest tests):

  docs_check.py links SOURCE_DIR      every relative link or image of every *.md file resolves to
                                      an existing file, and a #fragment to a heading of that file
  docs_check.py citations SOURCE_DIR  every section a source file cites, `docs/USAGE.md "Exit codes"`
                                      or `docs/DESIGN.md §3`, exists in the cited file
  docs_check.py version SOURCE_DIR    CITATION.cff's `version` is CMakeLists.txt's project(VERSION)
  docs_check.py readme SOURCE_DIR     README.md stays a five-minute read: at most 250 lines, and
                                      every cell of its headline table at most 400 characters
                                      (the claim and the current number; history goes to docs/)
  docs_check.py csv SOURCE_DIR        every CSV under results/ reads with pandas' comment="#" (as
                                      docs/USAGE.md "Reading the CSV files" shows): `# ` lines
                                      only before the header, no `#` in a header or data row
  docs_check.py tracker SOURCE_DIR    user documentation (README.md, docs/, results/) cites no
                                      internal tracker numbers ("issue 29 item 5"), which readers
                                      cannot see
  docs_check.py selftest SCRATCH_DIR  each check above fails on a seeded error in a scratch tree

Exit 0 when everything resolves, 1 with one line per broken link or citation. Python 3 standard
library only.
"""
import os
import re
import sys

SKIPPED_FOLDERS = {".git", "site", "node_modules"}


def walk(root: str, keep) -> list[str]:
    """Files under root for which keep(relative path) holds, build folders left out."""
    found = []
    for folder, subfolders, files in os.walk(root):
        subfolders[:] = sorted(d for d in subfolders
                               if d not in SKIPPED_FOLDERS and not d.startswith("build"))
        for name in sorted(files):
            relative = os.path.relpath(os.path.join(folder, name), root)
            if keep(relative):
                found.append(relative)
    return found


def strip_code(text: str) -> str:
    """Markdown without fenced blocks and inline code spans, where a link is only text."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.M | re.S)
    return re.sub(r"`[^`\n]*`", "", text)


def headings(path: str) -> list[str]:
    """The heading texts of a Markdown file (outside fenced code)."""
    with open(path, encoding="utf-8") as file:
        text = re.sub(r"^```.*?^```", "", file.read(), flags=re.M | re.S)
    return [m.group(1).strip() for m in re.finditer(r"^#{1,6} +(.+)$", text, flags=re.M)]


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"[`*_]", lambda m: "_" if m.group(0) == "_" else "", heading.lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def check_links(root: str) -> list[str]:
    problems = []
    link = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
    for relative in walk(root, lambda p: p.endswith(".md")):
        path = os.path.join(root, relative)
        with open(path, encoding="utf-8") as file:
            text = strip_code(file.read())
        for number, line in enumerate(text.split("\n"), 1):
            for match in link.finditer(line):
                target = match.group(1)
                if re.match(r"^[a-zA-Z][a-zA-Z+.-]*:", target):
                    continue  # http:, https:, mailto: are not checked offline
                file_part, _, fragment = target.partition("#")
                resolved = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) \
                    if file_part else path
                if not os.path.exists(resolved):
                    problems.append(f"{relative}: link to {target}: no file {file_part}")
                elif fragment and resolved.endswith(".md") and \
                        fragment not in {slug(h) for h in headings(resolved)}:
                    problems.append(f"{relative}: link to {target}: "
                                    f"{os.path.relpath(resolved, root)} has no heading #{fragment}")
    return problems


# A citation names a Markdown file of the repository, then (after a comma, spaces or a comment
# marker that wraps the line) a quoted section title or a § number.
CITATION = re.compile(
    r"(?<![\w/.\"])(README(?:\.md)?|docs/[A-Za-z_]+\.md|results/[a-z0-9_]+/README\.md)"
    r"(,?(?:\s|//|#)*)(?:\\?\"([^\"\\]+)|§(\d+))")
CITED_EXTENSIONS = (".cpp", ".hpp", ".h", ".py", ".sh", ".cmake", ".txt", ".gp", ".awk", ".toml",
                    ".in", ".md", "Makefile", ".ci/run")


def normalise(title: str) -> str:
    """A cited title as it reads: line-wrap comment markers and runs of spaces dropped."""
    return re.sub(r"\s+", " ", re.sub(r"\n\s*(//|#)", " ", title)).strip().lower()


def section_exists(path: str, title: str | None, number: str | None) -> bool:
    if number is not None:
        return any(re.match(rf"§{number}\b", h) for h in headings(path))
    wanted = normalise(title)
    if any(normalise(h).startswith(wanted) for h in headings(path)):
        return True
    # A bold run-in heading, as in "**Exit codes** (also listed ...)".
    with open(path, encoding="utf-8") as file:
        text = file.read()
    return any(normalise(m.group(1)).startswith(wanted)
               for m in re.finditer(r"\*\*([^*]+)\*\*", text))


def check_citations(root: str, files: list[str] | None = None) -> list[str]:
    problems = []
    keep = lambda p: p.endswith(CITED_EXTENSIONS) and not p.startswith("results/") \
        and not p.startswith("fuzz/corpus/") and p != "tests/docs_check.py"
    for relative in files if files is not None else walk(root, keep):
        with open(os.path.join(root, relative), encoding="utf-8", errors="replace") as file:
            text = file.read()
        for match in CITATION.finditer(text):
            cited, title, number = match.group(1), match.group(3), match.group(4)
            if cited == "README":
                cited = "README.md"
            line = text.count("\n", 0, match.start()) + 1
            what = f'"{normalise(title)}"' if title is not None else f"§{number}"
            target = os.path.join(root, cited)
            if not os.path.isfile(target):
                problems.append(f"{relative}:{line}: cites {cited} {what}: no such file")
            elif not section_exists(target, title, number):
                problems.append(f"{relative}:{line}: cites {cited} {what}: no such section")
    return problems


def check_version(root: str) -> list[str]:
    with open(os.path.join(root, "CMakeLists.txt"), encoding="utf-8") as file:
        project = re.search(r"project\(\s*geomint\s+VERSION\s+([0-9][0-9.]*)", file.read())
    cff_path = os.path.join(root, "CITATION.cff")
    if not os.path.isfile(cff_path):
        return ["CITATION.cff is missing"]
    with open(cff_path, encoding="utf-8") as file:
        cff = file.read()
    problems = []
    if not re.search(r"^cff-version: *\"?1\.2\.0\"?$", cff, flags=re.M):
        problems.append("CITATION.cff: cff-version must be 1.2.0")
    version = re.search(r"^version: *\"?([^\"\n]+?)\"?\s*$", cff, flags=re.M)
    if project is None:
        problems.append("CMakeLists.txt: no project(geomint VERSION x.y.z)")
    elif version is None:
        problems.append("CITATION.cff: no top-level `version:`")
    elif version.group(1) != project.group(1):
        problems.append(f"CITATION.cff: version {version.group(1)} is not the project version "
                        f"{project.group(1)} of CMakeLists.txt")
    return problems


README_MAX_LINES = 250
HEADLINE_CELL_MAX_CHARS = 400


def headline_rows(text: str) -> list[tuple[int, list[str]]]:
    """The body rows of README.md's "Headline results" table: (line number, cells)."""
    section = re.search(r"^## Headline results\n(.*?)(?=^## )", text, flags=re.M | re.S)
    if section is None:
        return []
    first_line = text.count("\n", 0, section.start(1)) + 1
    rows = []
    for offset, line in enumerate(section.group(1).split("\n")):
        if not line.startswith("|") or re.match(r"^\|[-| :]+\|$", line):
            continue
        cells = [cell.strip() for cell in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
        rows.append((first_line + offset, cells))
    return rows[1:]  # the header row


def check_readme(root: str) -> list[str]:
    with open(os.path.join(root, "README.md"), encoding="utf-8") as file:
        text = file.read()
    problems = []
    lines = text.count("\n")
    if lines > README_MAX_LINES:
        problems.append(f"README.md: {lines} lines, more than {README_MAX_LINES}: move detail to docs/")
    rows = headline_rows(text)
    if not rows:
        problems.append("README.md: no '## Headline results' table")
    for line, cells in rows:
        for cell in cells:
            if len(cell) > HEADLINE_CELL_MAX_CHARS:
                problems.append(f"README.md:{line}: headline cell of {len(cell)} characters, more "
                                f"than {HEADLINE_CELL_MAX_CHARS}: give the claim and the current "
                                f"number, move the history to docs/PERF.md or the scene README")
    return problems


def check_csv(root: str) -> list[str]:
    problems = []
    for relative in walk(root, lambda p: p.startswith("results/") and p.endswith(".csv")):
        with open(os.path.join(root, relative), encoding="utf-8", errors="replace") as file:
            in_provenance = True
            for number, line in enumerate(file, start=1):
                if in_provenance and line.startswith("# "):
                    continue
                in_provenance = False
                if "#" in line:
                    problems.append(f"{relative}:{number}: '#' in a header or data row: pandas' "
                                    f"comment=\"#\" would cut the row there")
                    break
    return problems


# "issue 29", "issues 5, 29", "Issue 30's": numbers of a tracker the readers of these files cannot see.
TRACKER_REFERENCE = re.compile(r"\bissues? #?\d+", flags=re.I)


def user_docs(root: str) -> list[str]:
    return walk(root, lambda p: p.endswith(".md") and (
        p == "README.md" or p.startswith("docs/") or p.startswith("results/")
        or p.startswith("examples/")))


def check_tracker(root: str) -> list[str]:
    problems = []
    for relative in user_docs(root):
        with open(os.path.join(root, relative), encoding="utf-8") as file:
            for number, line in enumerate(file, start=1):
                for match in TRACKER_REFERENCE.finditer(line):
                    problems.append(f"{relative}:{number}: cites the internal tracker "
                                    f"('{match.group(0)}'): say what is measured and why instead")
    return problems


def write(root: str, relative: str, text: str) -> None:
    path = os.path.join(root, relative)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as file:
        file.write(text)


def selftest(scratch: str) -> list[str]:
    """A tree that passes every check, then one seeded error per check that must be reported."""
    import shutil
    root = os.path.join(scratch, "docs_check_selftest")
    shutil.rmtree(root, ignore_errors=True)
    write(root, "CMakeLists.txt", "project(geomint VERSION 1.2.3 LANGUAGES CXX)\n")
    write(root, "CITATION.cff", 'cff-version: 1.2.0\nversion: "1.2.3"\n')
    write(root, "README.md", "# t\n\nSee [usage](docs/USAGE.md#exit-codes-and-rows).\n\n"
                             "## Headline results\n\n| claim | measured |\n|---|---|\n| a | 1.0 |\n\n"
                             "## End\n")
    write(root, "docs/USAGE.md", "# Usage\n\n## Exit codes and rows\n\n* **Step budgets.** x\n")
    write(root, "results/s/summary.csv", "# version: 1\nproblem,status\nx,ok\n")
    write(root, "a.cpp", '// docs/USAGE.md "Exit codes"; docs/USAGE.md\n// "Step budgets"\n')
    checks = {"links": check_links, "citations": check_citations, "version": check_version,
              "readme": check_readme, "tracker": check_tracker, "csv": check_csv}
    problems = [f"selftest: {name} fails on the clean tree: {found}"
                for name, check in checks.items() if (found := check(root))]
    seeded = {
        "links": ("README.md", "# t\n\nSee [usage](docs/USAGE.md#exit-code).\n"),
        "citations": ("a.cpp", '// docs/USAGE.md "Exit status"\n'),
        "version": ("CITATION.cff", 'cff-version: 1.2.0\nversion: "1.2.4"\n'),
        "readme": ("README.md", "line\n" * (README_MAX_LINES + 1)),
        "tracker": ("docs/USAGE.md", "# Usage\n\nAs issue 29 item 5 asked.\n"),
        "csv": ("results/s/summary.csv", "# version: 1\nproblem,status\nx#1,ok\n"),
    }
    for name, (relative, text) in seeded.items():
        with open(os.path.join(root, relative), encoding="utf-8") as file:
            clean = file.read()
        write(root, relative, text)
        if not checks[name](root):
            problems.append(f"selftest: {name} passes a seeded error in {relative}")
        write(root, relative, clean)
    with open(os.path.join(root, "README.md"), encoding="utf-8") as file:
        clean = file.read()
    write(root, "README.md", clean.replace("| a | 1.0 |", f"| a | {'9' * 401} |"))
    if not check_readme(root):
        problems.append("selftest: readme passes a 401-character headline cell")
    write(root, "README.md", clean.replace("## Headline results", "## Results"))
    if not check_readme(root):
        problems.append("selftest: readme passes a README without its headline table")
    write(root, "README.md", clean)
    write(root, "docs/GONE.md", "[x](missing.md)\n")
    if not check_links(root):
        problems.append("selftest: links passes a link to a missing file")
    shutil.rmtree(root)
    return problems


def main() -> None:
    checks = {"links": check_links, "citations": check_citations, "version": check_version,
              "readme": check_readme, "tracker": check_tracker, "csv": check_csv,
              "selftest": selftest}
    if len(sys.argv) != 3 or sys.argv[1] not in checks:
        sys.exit(__doc__)
    root = os.path.abspath(sys.argv[2])
    problems = checks[sys.argv[1]](root)
    for problem in problems:
        print(problem)
    if problems:
        sys.exit(f"docs_check {sys.argv[1]}: {len(problems)} problem(s)")
    print(f"docs_check {sys.argv[1]}: ok")


if __name__ == "__main__":
    main()
