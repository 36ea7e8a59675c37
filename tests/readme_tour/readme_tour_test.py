#!/usr/bin/python3
"""README.md's "A short tour", run as a reader would: every command of its ```sh blocks (but the
slow ones of SLOW, named with the reason) runs in a sandbox folder holding a copy of results/ and
examples/ and the build; each must exit 0, write nothing but tour/, and leave every file of the
results/ copy byte-identical (the tour never rewrites published tables).
Usage: readme_tour_test.py SOURCE_DIR BUILD_DIR"""
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

# Command prefix -> why the test does not run it (each is run elsewhere).
SLOW = {
    "make gate-quick": "sweeps every CI-sized scene and gates them (minutes); `make test` ends "
                       "with it",
}
OUT = "tour"  # the one folder every tour command writes to (.gitignore lists it)


def tour_commands(readme):
    text = open(readme, encoding="utf-8").read()
    start = text.index("## A short tour")
    end = text.find("\n## ", start + 1)
    section = text[start:end if end >= 0 else len(text)]
    commands = []
    for block in re.findall(r"```sh\n(.*?)```", section, re.S):
        for line in block.replace("\\\n", " ").splitlines():
            line = re.sub(r"\s+#.*$", "", line).strip()
            if line:
                commands.append(re.sub(r"\s+", " ", line))
    return commands


def hashes(root):
    out = {}
    for folder, _, files in os.walk(root):
        for name in files:
            path = os.path.join(folder, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, root)] = hashlib.sha256(f.read()).hexdigest()
    return out


def main():
    source, build = sys.argv[1], os.path.abspath(sys.argv[2])
    commands = tour_commands(os.path.join(source, "README.md"))
    if not commands:
        sys.exit("no command found in README.md's \"A short tour\"")
    failures = []
    with tempfile.TemporaryDirectory(prefix="geomint-tour.") as sandbox:
        shutil.copytree(os.path.join(source, "results"), os.path.join(sandbox, "results"),
                        symlinks=True)
        shutil.copytree(os.path.join(source, "examples"), os.path.join(sandbox, "examples"),
                        symlinks=True)
        os.symlink(build, os.path.join(sandbox, "build"))
        before = hashes(os.path.join(sandbox, "results"))
        entries = set(os.listdir(sandbox))
        environment = dict(os.environ, HOME=os.path.join(sandbox, "home"))
        for command in commands:
            slow = next((why for prefix, why in SLOW.items() if command.startswith(prefix)), None)
            if slow:
                print(f"skipped (slow: {slow}): {command}")
                continue
            started = time.monotonic()
            run = subprocess.run(["bash", "-c", command], cwd=sandbox, env=environment,
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                 timeout=120)
            print(f"{time.monotonic() - started:6.1f} s  exit {run.returncode}  {command}")
            if run.returncode != 0:
                failures.append(f"'{command}' exited {run.returncode}:\n{run.stdout[-2000:]}")
        after = hashes(os.path.join(sandbox, "results"))
        changed = sorted(p for p in before.keys() | after.keys() if before.get(p) != after.get(p))
        if changed:
            failures.append("the tour changed files under results/ (only " + OUT + "/ may be "
                            "written): " + ", ".join(changed[:20]))
        stray = sorted(set(os.listdir(sandbox)) - entries - {OUT})
        if stray:
            failures.append("the tour wrote outside " + OUT + "/: " + ", ".join(stray))
        if not os.path.isdir(os.path.join(sandbox, OUT)):
            failures.append("no command wrote into " + OUT + "/")
    if failures:
        sys.exit("FAILED:\n" + "\n".join(failures))
    print(f"{len(commands)} tour commands checked")


if __name__ == "__main__":
    main()
