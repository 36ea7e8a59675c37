#!/usr/bin/env python3
"""Every published figure is drawn from the committed tables: re-renders each scene's
scripts/<scene>.gp through scripts/reproduce.sh (SWEEP=0) on a scratch copy of its folder, checks
that it writes exactly the committed figures (PNG, SVG and PDF of each), that the new SVGs pass
figure_layout_check.py, and that every scene of README.md's headline table has a figure.

Usage: render_test.py SOURCE_DIR SCRATCH_DIR. Exit 0 pass, 1 fail, 77 skip (no gnuplot).
"""
import pathlib
import re
import shutil
import subprocess
import sys

FIGURE_SUFFIXES = (".png", ".svg", ".pdf")
HERE = pathlib.Path(__file__).resolve().parent


def headline_scenes(readme):
    """Scenes linked from the rows of README.md's "## Headline results" table."""
    text = readme.read_text(encoding="utf-8")
    section = text.split("## Headline results", 1)[1].split("\n## ", 1)[0]
    scenes = []
    for line in section.splitlines():
        if line.startswith("|"):
            for scene in re.findall(r"\(results/([a-z0-9_]+)/README\.md\)", line):
                if scene not in scenes:
                    scenes.append(scene)
    return scenes


def figures_in(folder):
    return sorted(p.name for p in folder.iterdir() if p.suffix in FIGURE_SUFFIXES)


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    source = pathlib.Path(sys.argv[1]).resolve()
    scratch = pathlib.Path(sys.argv[2]).resolve()
    if shutil.which("gnuplot") is None:
        print("render_test: gnuplot not installed", file=sys.stderr)
        return 77
    failures = []

    headline = headline_scenes(source / "README.md")
    if not headline:
        failures.append("README.md: no scene found in the '## Headline results' table")
    for scene in headline:
        folder = source / "results" / scene
        if not folder.is_dir():
            failures.append(f"headline scene '{scene}' has no folder results/{scene}")
        elif not any(name.endswith(".png") for name in figures_in(folder)):
            failures.append(f"headline scene '{scene}' has no figure (results/{scene}/*.png)")

    # The scenes with a figure script and a results folder; scaling's figure is drawn by
    # scripts/scaling.sh, not by reproduce.sh (it has no scene.toml).
    scenes = sorted(p.stem for p in (source / "scripts").glob("*.gp")
                    if p.stem != "common" and (source / "results" / p.stem / "scene.toml").is_file())
    shutil.rmtree(scratch, ignore_errors=True)
    shutil.copytree(source / "scripts", scratch / "scripts")
    # scripts/work_precision_table.sh takes each method's provider from the methods table.
    (scratch / "docs").mkdir()
    shutil.copy(source / "docs" / "METHODS.md", scratch / "docs" / "METHODS.md")
    for scene in scenes:
        shutil.copytree(source / "results" / scene, scratch / "results" / scene,
                        ignore=lambda _, names: [n for n in names if n.endswith(FIGURE_SUFFIXES)])
    run = subprocess.run(["bash", str(scratch / "scripts" / "reproduce.sh"), "/bin/true", *scenes],
                         env={"PATH": "/usr/bin:/bin", "SWEEP": "0", "HOME": str(scratch)},
                         capture_output=True, text=True)
    if run.returncode != 0:
        failures.append(f"reproduce.sh SWEEP=0 failed ({run.returncode}):\n{run.stderr[-3000:]}")
    warnings = [line for line in run.stderr.splitlines() if re.search(r"warning|error", line, re.I)]
    for line in warnings:
        failures.append(f"gnuplot: {line}")
    for scene in scenes:
        committed = figures_in(source / "results" / scene)
        rendered = figures_in(scratch / "results" / scene)
        if committed != rendered:
            failures.append(f"results/{scene}: committed figures {committed}, "
                            f"scripts/{scene}.gp writes {rendered}")
        for name in rendered:
            if (scratch / "results" / scene / name).stat().st_size == 0:
                failures.append(f"results/{scene}/{name}: rendered empty")
    layout = subprocess.run([sys.executable, str(HERE / "figure_layout_check.py"), "--require-footer",
                             *[str(scratch / "results" / s) for s in scenes
                               if list((scratch / "results" / s).glob("*.svg"))]],
                            capture_output=True, text=True)
    if layout.returncode != 0:
        failures.append("re-rendered figures fail the layout check:\n" + layout.stdout + layout.stderr)

    for failure in failures:
        print(f"render_test: {failure}", file=sys.stderr)
    if failures:
        return 1
    print(f"render_test: {len(scenes)} scenes re-rendered from their tables; "
          f"{len(headline)} headline scenes each have a figure")
    return 0


if __name__ == "__main__":
    sys.exit(main())
