#!/usr/bin/python3
"""Mutation testing for geomint: `make mutation` (docs/TESTING.md, "Mutation testing").

Applies each seeded bug of tests/mutation/mutants.toml to a scratch copy of the tracked sources
(never to the working tree), rebuilds incrementally only the targets the mutant needs, runs the
affected fast tests, the committed-row regression test and the affected scenes in their CI-sized
variant followed by the gates, reverts, and records who killed it. Writes
<scratch>/mutation-report.{csv,md}; exits 1 when a mutant survives, 2 on a broken list or a
baseline that does not build.

Kill criteria, each step under a timeout (a timeout is a kill, reported as such):
  tests       a behavioural test (the mutant's `tests` entries, committed-row test excluded) fails
              or the test binary crashes or times out;
  regression  tests/committed_results_test.cpp (Results/CommittedScene.*) fails — it catches any
              change of a published number, so it is reported in its own column;
  gates       a gate of results/gates.toml that PASSES on the unmutated baseline (same run, same
              scenes, quick variant) FAILS on the mutant.
A mutant is killed when any of the three kills it.

The gates' own figure. The gates are what users run in their CI, so the report also says how many
of the bugs a gate could see the gates kill on their own (the target is GATE_KILL_TARGET, 80%):
  gate-visible  the mutant lists at least one scene AND its effect reaches that scene's CI-sized
                tables: some cell of some quick CSV of its scenes differs from the unmutated
                baseline of the same run (timing and machine columns, TIMING_COLUMNS, and the
                `#` provenance lines are not compared), or a scene's quick sweep fails or times
                out on the mutant and not on the baseline. A mutant whose listed scenes come out
                identical is reported as "not visible" (a note asks to fix its `scenes`), since
                no band on those tables can tell it from the correct code; a mutant that lists no
                scene is not gate-visible by declaration (its effect is meant for tests only).
  gate-killed   gate-visible and killed by the gates column above, whatever the tests did.
Figure = gate-killed / gate-visible over the mutants run. A run of the whole list (no
--only/--shard/--budget-min) exits 1 when the figure is below the target, as for a survivor: the
figure is a property of the list and the gates file together, and a gates file that lost its
reach must not pass `make mutation`. A subset run prints the figure over the mutants it ran, says
that it is a subset, and only warns (a subset picked to study missed mutants is below target by
construction, and a budgeted CI run covers a different sample on every commit).
--gates-only (MUTATION_GATES_ONLY=1) measures the figure alone: it builds only geomint, runs no
test, skips the mutants without scenes (not gate-visible by declaration) and does not fail on
survivors, only on the figure of a whole-list run.

Python 3.11 standard library only (tomllib).
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

TEST_BINARIES = {
    "problems_test": "problems/problems_test",
    "integrators_test": "integrators/integrators_test",
    "harness_test": "harness/harness_test",
    "suite_test": "tests/suite_test",
}
REGRESSION_FILTER = "Results/CommittedScene.*"
REGRESSION_BINARY = "suite_test"
# Columns that measure the machine, not the numerics: never compared for gate visibility.
TIMING_COLUMNS = {"wall_s", "seconds_per_step", "gradient_elements_per_s", "peak_rss_mib"}
GATE_KILL_TARGET = 0.80


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def env_float(name: str, default: float) -> float:
    value = os.environ.get(name, "")
    return float(value) if value else default


# ---------------------------------------------------------------------------------------------
# Mutant list


@dataclass
class Edit:
    file: str
    find: str
    replace: str


@dataclass
class Mutant:
    id: str
    klass: str
    description: str
    edits: list[Edit]
    tests: list[str]
    scenes: list[str]


class ListError(Exception):
    pass


def load_mutants(path: Path, source_root: Path) -> list[Mutant]:
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise ListError(f"{path}: {error}") from error
    mutants: list[Mutant] = []
    seen: set[str] = set()
    errors: list[str] = []
    for index, entry in enumerate(data.get("mutant", [])):
        where = f"{path.name}: mutant #{index + 1} ({entry.get('id', '?')})"
        mutant_id = entry.get("id", "")
        if not re.fullmatch(r"[a-z0-9_]+", mutant_id or ""):
            errors.append(f"{where}: 'id' must be lowercase letters, digits and _")
            continue
        if mutant_id in seen:
            errors.append(f"{where}: duplicate id")
        seen.add(mutant_id)
        for key in ("description", "class"):
            if not isinstance(entry.get(key), str) or not entry[key]:
                errors.append(f"{where}: '{key}' is required")
        raw_edits = entry.get("edit", [])
        if "find" in entry or "file" in entry:
            raw_edits = [{k: entry.get(k) for k in ("file", "find", "replace")}] + raw_edits
        edits = []
        if not raw_edits:
            errors.append(f"{where}: give file/find/replace or [[mutant.edit]] tables")
        for raw in raw_edits:
            if not all(isinstance(raw.get(k), str) for k in ("file", "find", "replace")):
                errors.append(f"{where}: every edit needs string file, find and replace")
                continue
            edit = Edit(raw["file"], raw["find"], raw["replace"])
            if edit.find == edit.replace:
                errors.append(f"{where}: find and replace are identical")
            target = source_root / edit.file
            if not target.is_file():
                errors.append(f"{where}: file '{edit.file}' does not exist")
            else:
                count = target.read_text().count(edit.find)
                if count != 1:
                    errors.append(
                        f"{where}: 'find' occurs {count} times in {edit.file} (must be exactly "
                        f"once); update the mutant to the current code:\n---\n{edit.find}\n---")
            edits.append(edit)
        tests = entry.get("tests", [])
        for spec in tests:
            binary = spec.split(":", 1)[0]
            if binary not in TEST_BINARIES:
                errors.append(f"{where}: unknown test binary '{binary}' "
                              f"(one of {', '.join(TEST_BINARIES)})")
        scenes = entry.get("scenes", [])
        for scene in scenes:
            if not (source_root / "results" / scene / "scene.toml").is_file():
                errors.append(f"{where}: scene '{scene}' has no results/{scene}/scene.toml")
        mutants.append(Mutant(mutant_id, entry.get("class", ""), entry.get("description", ""),
                              edits, list(tests), list(scenes)))
    if not mutants and not errors:
        errors.append(f"{path}: no [[mutant]] entries")
    if errors:
        raise ListError("\n".join(errors))
    return mutants


# ---------------------------------------------------------------------------------------------
# Processes with timeouts (the whole process group is killed on timeout)


@dataclass
class Outcome:
    code: int | None  # None: timed out
    seconds: float
    output: str


LIVE: set[int] = set()  # process groups of running children, killed on SIGINT/SIGTERM


def run(command: list[str], cwd: Path, timeout: float, log_path: Path | None = None) -> Outcome:
    start = time.monotonic()
    with subprocess.Popen(command, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, errors="replace", start_new_session=True) as process:
        LIVE.add(process.pid)
        try:
            output, _ = process.communicate(timeout=timeout)
            code: int | None = process.returncode
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            output, _ = process.communicate()
            code = None
        finally:
            LIVE.discard(process.pid)
    seconds = time.monotonic() - start
    if log_path is not None:
        log_path.parent.mkdir(parents=True, exist_ok=True)
        with log_path.open("a") as stream:
            stream.write(f"$ {' '.join(command)}   (cwd {cwd})\n{output}\n"
                         f"-> {'timeout' if code is None else code} in {seconds:.1f} s\n\n")
    return Outcome(code, seconds, output)


def run_parallel(jobs: list[tuple[list[str], Path, float, Path | None]],
                 width: int) -> list[Outcome]:
    """Runs commands `width` at a time, each with its own timeout; results in input order."""
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=max(1, width)) as pool:
        return list(pool.map(lambda job: run(*job), jobs))


# ---------------------------------------------------------------------------------------------
# Scratch copy and build


def sync_sources(repo: Path, src: Path) -> None:
    """Copies the working-tree content of every tracked file into src, touching only files whose
    content differs (unchanged files keep their mtime, so the scratch build stays incremental),
    and removes files that are no longer tracked (generated quick/ outputs are kept apart)."""
    listed = subprocess.run(["git", "ls-files", "-z"], cwd=repo, check=True,
                            capture_output=True).stdout.decode().split("\0")
    tracked = {name for name in listed if name and (repo / name).is_file()}
    src.mkdir(parents=True, exist_ok=True)
    changed = 0
    for name in sorted(tracked):
        source, target = repo / name, src / name
        data = source.read_bytes()
        if target.is_file() and target.read_bytes() == data:
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
        shutil.copymode(source, target)
        changed += 1
    removed = 0
    for path in src.rglob("*"):
        if not path.is_file() or path.is_relative_to(src / "build"):
            continue
        relative = path.relative_to(src).as_posix()
        if relative not in tracked and "/quick/" not in relative:
            path.unlink()
            removed += 1
    log(f"mutation: scratch copy {src}: {changed} file(s) updated, {removed} removed")


def configure(src: Path, build: Path, log_path: Path) -> None:
    if (build / "CMakeCache.txt").is_file():
        return
    outcome = run(["cmake", "-S", str(src), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                   "-DGEOMINT_BUILD_BENCH=OFF", "-DGEOMINT_BUILD_TESTS=ON"], src, 600, log_path)
    if outcome.code != 0:
        raise SystemExit(f"mutation: cmake configure failed (see {log_path})")


def build_targets(build: Path, targets: list[str], jobs: int, timeout: float,
                  log_path: Path) -> Outcome:
    command = ["cmake", "--build", str(build), "-j", str(jobs), "--target", *targets]
    return run(command, build, timeout, log_path)


# ---------------------------------------------------------------------------------------------
# Tests


def test_invocations(mutant_tests: list[str]) -> dict[str, str]:
    """binary -> gtest filter (union of the mutant's entries, committed-row test excluded)."""
    filters: dict[str, list[str]] = {}
    for spec in mutant_tests:
        binary, _, pattern = spec.partition(":")
        filters.setdefault(binary, []).append(pattern or "*")
    result = {}
    for binary, patterns in filters.items():
        positive = ":".join(sorted(set(patterns))) if "*" not in patterns else "*"
        negative = REGRESSION_FILTER if binary == REGRESSION_BINARY else ""
        result[binary] = positive + (f"-{negative}" if negative else "")
    return result


def failed_tests(binary: str, outcome: Outcome, json_path: Path) -> list[str]:
    """Names of the failed tests; a crash or timeout is reported as such."""
    if outcome.code is None:
        return [f"{binary}: TIMEOUT after {outcome.seconds:.0f} s"]
    names: list[str] = []
    if json_path.is_file():
        try:
            report = json.loads(json_path.read_text())
            for suite in report.get("testsuites", []):
                for case in suite.get("testsuite", []):
                    if case.get("failures"):
                        names.append(f"{suite['name']}.{case['name']}")
        except (json.JSONDecodeError, KeyError):
            pass
    if outcome.code != 0 and not names:
        # Crashed before writing its report (signal, abort, uncaught exception).
        how = f"signal {-outcome.code}" if outcome.code < 0 else f"exit {outcome.code}"
        running = re.findall(r"\[ RUN      \] (\S+)", outcome.output)
        names.append(f"{binary}: CRASH ({how})" + (f" in {running[-1]}" if running else ""))
    return names


def run_tests(build: Path, invocations: dict[str, str], tag: str, work: Path, timeout: float,
              width: int, log_path: Path) -> tuple[dict[str, list[str]], float]:
    jobs, keys = [], []
    for binary, gtest_filter in invocations.items():
        json_path = work / f"{tag}-{binary}.json"
        json_path.unlink(missing_ok=True)
        command = [str(build / TEST_BINARIES[binary]), f"--gtest_filter={gtest_filter}",
                   f"--gtest_output=json:{json_path}", "--gtest_brief=1"]
        jobs.append((command, build, timeout, log_path))
        keys.append((binary, json_path))
    start = time.monotonic()
    outcomes = run_parallel(jobs, width)
    failures = {binary: failed_tests(binary, outcome, json_path)
                for (binary, json_path), outcome in zip(keys, outcomes)}
    return failures, time.monotonic() - start


# ---------------------------------------------------------------------------------------------
# Scenes and gates


def gate_mode(geomint: Path, src: Path) -> str:
    """'dirs': `geomint gate` takes scene folders (results/<scene>/quick) and checks only their
    scenes' gates (issue 13 part 1). 'staged': it matches files by the path suffix
    <scene>/summary.csv, so the quick CSVs are copied to <stage>/<scene>/<table>.csv."""
    forced = os.environ.get("MUTATION_GATE_MODE", "auto")
    if forced in ("dirs", "staged"):
        return forced
    help_text = run([str(geomint), "gate", "--help"], src, 60).output.lower()
    return "dirs" if ("quick" in help_text or "folder" in help_text
                      or "dir_or_csv" in help_text) else "staged"


def stage_gate_inputs(stage: Path, mode: str, outputs: dict[str, Path]) -> list[str]:
    """Copies each scene's quick CSVs (scene -> folder) into a fresh stage; returns the
    arguments for `geomint gate`."""
    if stage.exists():
        shutil.rmtree(stage)
    arguments = []
    for scene, folder in sorted(outputs.items()):
        target = stage / "results" / scene / "quick" if mode == "dirs" else stage / scene
        target.mkdir(parents=True)
        for table in sorted(folder.glob("*.csv")):
            shutil.copy2(table, target / table.name)
            if mode == "staged":
                arguments.append(str(target / table.name))
        if mode == "dirs":
            arguments.append(str(target))
    return arguments


GATE_LINE = re.compile(r"^(PASS|FAIL)\s+(.*?)(\s+\(\d+ row\(s\)\))?\s*$")


def gate_results(output: str) -> dict[str, bool]:
    results = {}
    for line in output.splitlines():
        match = GATE_LINE.match(line)
        if match:
            results[match.group(2)] = match.group(1) == "PASS"
    return results


def sweep_scenes(geomint: Path, src: Path, scenes: list[str], jobs: int, timeout: float,
                 log_path: Path, keep: Path | None) -> tuple[dict[str, Path], list[str], float]:
    """Runs each scene's quick sweep in the scratch copy; returns scene -> output folder (copied
    to keep/<scene> when given), the scenes that timed out or failed, and the seconds spent."""
    outputs, broken = {}, []
    start = time.monotonic()
    for scene in scenes:
        folder = src / "results" / scene / "quick"
        if folder.exists():
            shutil.rmtree(folder)
        outcome = run([str(geomint), "sweep", f"results/{scene}/scene.toml", "--quick", "--jobs",
                       str(jobs)], src, timeout, log_path)
        if outcome.code is None:
            broken.append(f"{scene}: sweep TIMEOUT after {outcome.seconds:.0f} s")
            continue
        if outcome.code != 0:
            broken.append(f"{scene}: sweep exit {outcome.code}")
            continue
        # The scene's post-processing, as scripts/reproduce.sh runs it (its tables are gated too).
        post = src / "scripts" / f"{scene}.py"
        if post.exists():
            outcome = run(["/usr/bin/python3", str(post), str(folder)], src, timeout, log_path)
            if outcome.code != 0:
                broken.append(f"{scene}: {post.name} exit {outcome.code}")
                continue
        if keep is not None:
            if (keep / scene).exists():
                shutil.rmtree(keep / scene)
            shutil.copytree(folder, keep / scene)
            outputs[scene] = keep / scene
        else:
            outputs[scene] = folder
    return outputs, broken, time.monotonic() - start


def table_cells(path: Path) -> list[list[str]] | None:
    """A quick CSV without its `#` provenance lines and timing columns, as rows of cells."""
    try:
        lines = [line for line in path.read_text(errors="replace").splitlines()
                 if not line.startswith("#")]
    except OSError:
        return None
    rows = list(csv.reader(lines))
    if not rows:
        return []
    keep = [i for i, name in enumerate(rows[0]) if name not in TIMING_COLUMNS]
    return [[row[i] if i < len(row) else "" for i in keep] for row in rows]


def changed_tables(baseline: Path, mutant: Path) -> list[str]:
    """Names of the quick CSVs (top level of the scene folder) whose compared cells differ
    between the baseline and the mutant; a table present on one side only counts as changed."""
    names = sorted({p.name for p in baseline.glob("*.csv")} | {p.name for p in mutant.glob("*.csv")})
    return [name for name in names
            if table_cells(baseline / name) != table_cells(mutant / name)]


def run_gates(geomint: Path, src: Path, gates_file: str, mode: str, stage: Path,
              outputs: dict[str, Path], timeout: float, log_path: Path) -> dict[str, bool] | None:
    if not outputs:
        return {}
    arguments = stage_gate_inputs(stage, mode, outputs)
    outcome = run([str(geomint), "gate", gates_file, *arguments], src, timeout, log_path)
    if outcome.code == 2 and "applies to the results given" in outcome.output:
        return {}  # no gate covers these scenes
    if outcome.code is None or outcome.code not in (0, 1):
        return None  # timeout, crash or malformed gates file
    return gate_results(outcome.output)


# ---------------------------------------------------------------------------------------------
# Selection


def rotation_key() -> str:
    key = os.environ.get("MUTATION_ROTATION_KEY", "")
    if key:
        return key
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                              check=True, cwd=Path(__file__).resolve().parent).stdout.strip()
    except (subprocess.CalledProcessError, FileNotFoundError):
        return "0"


def select(mutants: list[Mutant], only: str, shard: str) -> list[Mutant]:
    if only:
        wanted = [name.strip() for name in only.split(",") if name.strip()]
        unknown = [name for name in wanted if name not in {m.id for m in mutants}]
        if unknown:
            raise ListError(f"unknown mutant id(s): {', '.join(unknown)}; "
                            f"known: {', '.join(m.id for m in mutants)}")
        return [m for m in mutants if m.id in wanted]
    if shard:
        match = re.fullmatch(r"(\d+)/(\d+)", shard)
        if not match or not 1 <= int(match.group(1)) <= int(match.group(2)):
            raise ListError(f"MUTATION_SHARD must be i/N with 1 <= i <= N (got '{shard}')")
        i, n = int(match.group(1)), int(match.group(2))
        return [m for k, m in enumerate(mutants) if k % n == i - 1]
    return list(mutants)


def rotate(mutants: list[Mutant], key: str) -> list[Mutant]:
    """Orders the mutants starting at an offset derived from the key (the commit hash), so that a
    time-budgeted run covers a different part of the list on every commit."""
    if not mutants:
        return mutants
    offset = int(hashlib.sha256(key.encode()).hexdigest(), 16) % len(mutants)
    return mutants[offset:] + mutants[:offset]


# ---------------------------------------------------------------------------------------------
# Report


@dataclass
class Record:
    mutant: Mutant
    build: str = "ok"  # ok | failed | timeout
    tests: list[str] = field(default_factory=list)
    regression: list[str] = field(default_factory=list)
    gates: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)
    changed: list[str] = field(default_factory=list)  # scene/table.csv that the mutant moved

    @property
    def gate_visible(self) -> bool:
        return bool(self.mutant.scenes) and self.build == "ok" and bool(self.changed)

    @property
    def gate_killed(self) -> bool:
        return self.gate_visible and bool(self.gates)

    @property
    def verdict(self) -> str:
        if self.build != "ok":
            return "invalid"
        if self.tests or self.gates:
            return "killed"
        if self.regression:
            return "killed (regression only)"
        return "SURVIVED"

    @property
    def total_seconds(self) -> float:
        return sum(self.seconds.values())


def short(items: list[str], limit: int = 4) -> str:
    if not items:
        return "-"
    text = "; ".join(items[:limit])
    return text + (f"; +{len(items) - limit} more" if len(items) > limit else "")


def write_reports(records: list[Record], scratch: Path, header: list[str]) -> tuple[Path, Path]:
    csv_path, md_path = scratch / "mutation-report.csv", scratch / "mutation-report.md"
    with csv_path.open("w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["id", "class", "verdict", "killed_by_tests", "killed_by_regression",
                         "killed_by_gates", "gate_visible", "changed_tables", "notes", "build_s",
                         "tests_s", "scenes_s", "total_s"])
        for r in records:
            visible = "yes" if r.gate_visible else ("no" if r.mutant.scenes else "no scenes")
            writer.writerow([r.mutant.id, r.mutant.klass, r.verdict, " | ".join(r.tests),
                             " | ".join(r.regression), " | ".join(r.gates), visible,
                             " | ".join(r.changed), " | ".join(r.notes),
                             f"{r.seconds.get('build', 0):.1f}", f"{r.seconds.get('tests', 0):.1f}",
                             f"{r.seconds.get('scenes', 0):.1f}", f"{r.total_seconds:.1f}"])
    lines = ["# Mutation testing report", ""] + [f"- {line}" for line in header] + [""]
    lines += ["| mutant | killed by tests | killed by regression test | gate-visible "
              "| killed by gates | verdict | time (s) |", "|---|---|---|---|---|---|---|"]
    for r in records:
        visible = "yes" if r.gate_visible else ("no" if r.mutant.scenes else "no scene")
        cells = [f"`{r.mutant.id}`", short(r.tests), "yes" if r.regression else "-", visible,
                 short(r.gates),
                 r.verdict + (f" ({'; '.join(r.notes)})" if r.notes else ""),
                 f"{r.total_seconds:.0f}"]
        lines.append("| " + " | ".join(cell.replace("|", "/") for cell in cells) + " |")
    md_path.write_text("\n".join(lines) + "\n")
    return csv_path, md_path


# ---------------------------------------------------------------------------------------------


class Interrupted(Exception):
    pass


def on_signal(number, _frame):
    for group in list(LIVE):
        try:
            os.killpg(group, signal.SIGKILL)
        except ProcessLookupError:
            pass
    raise Interrupted(f"signal {number}")


def count_tests(build: Path, binary: str, gtest_filter: str) -> int:
    outcome = run([str(build / TEST_BINARIES[binary]), "--gtest_list_tests",
                   f"--gtest_filter={gtest_filter}"], build, 120)
    return sum(1 for line in outcome.output.splitlines() if line.startswith("  "))


def main() -> int:
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    repo = Path(__file__).resolve().parent.parent
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--list", default=str(repo / "tests/mutation/mutants.toml"),
                        help="mutant list (default tests/mutation/mutants.toml)")
    parser.add_argument("--only", default=os.environ.get("MUTATION_ONLY", ""),
                        help="comma-separated mutant ids (env MUTATION_ONLY)")
    parser.add_argument("--shard", default=os.environ.get("MUTATION_SHARD", ""),
                        help="i/N: every N-th mutant starting at the i-th (env MUTATION_SHARD)")
    parser.add_argument("--budget-min", type=float,
                        default=env_float("MUTATION_BUDGET_MIN", 0.0),
                        help="stop starting mutants when the next one would not fit; the order is "
                        "rotated by the commit hash (env MUTATION_BUDGET_MIN; 0 = no budget)")
    parser.add_argument("--scratch", default=os.environ.get("MUTATION_DIR",
                                                            str(repo / "build-mutation")),
                        help="scratch folder (default build-mutation/, env MUTATION_DIR)")
    parser.add_argument("--jobs", type=int, default=int(env_float("MUTATION_JOBS", 2)),
                        help="build and sweep parallelism, tests run this many binaries at once")
    parser.add_argument("--gates", default="results/gates.toml", help="gates file (in the copy)")
    parser.add_argument("--check", action="store_true",
                        help="only validate the list against the working tree (no build)")
    parser.add_argument("--no-test-baseline", action="store_true",
                        help="skip running the selected tests on the unmutated build first")
    parser.add_argument("--gates-only", action="store_true",
                        default=os.environ.get("MUTATION_GATES_ONLY", "") not in ("", "0"),
                        help="build only geomint and run only the quick scenes and gates (no "
                        "tests): the gates' figure in a fraction of the time; survivors do not "
                        "fail the run (env MUTATION_GATES_ONLY=1)")
    args = parser.parse_args()

    timeouts = {
        "build": env_float("MUTATION_TIMEOUT_BUILD", 1800),
        "test": env_float("MUTATION_TIMEOUT_TEST", 600),
        "sweep": env_float("MUTATION_TIMEOUT_SWEEP", 300),
        "gate": env_float("MUTATION_TIMEOUT_GATE", 120),
    }
    try:
        mutants = load_mutants(Path(args.list), repo)
        selected = select(mutants, args.only, args.shard)
    except ListError as error:
        log(f"mutation: broken mutant list:\n{error}")
        return 2
    if args.check:
        log(f"mutation: {len(mutants)} mutant(s) in {args.list}; every 'find' occurs once")
        return 0
    key = rotation_key()
    if args.budget_min > 0 and not args.only:
        selected = rotate(selected, key)

    started = time.monotonic()
    scratch = Path(args.scratch).resolve()
    # The build folder sits inside the scratch copy as build/ does in the repository, so every
    # compiler command seen from its build folder is the same as the main build's, paths relative
    # to CCACHE_BASEDIR included: with ccache (.ci/run sets it up) only the mutated files and the
    # few test files with absolute paths compiled in miss the cache.
    src, build, work = scratch / "src", scratch / "src" / "build", scratch / "work"
    log_path = scratch / "mutation.log"
    scratch.mkdir(parents=True, exist_ok=True)
    work.mkdir(exist_ok=True)
    log_path.write_text("")
    sync_sources(repo, src)
    # Validate again against the copy (identical content, but this is what gets mutated).
    try:
        load_mutants(Path(args.list), src)
    except ListError as error:
        log(f"mutation: broken mutant list:\n{error}")
        return 2
    geomint = build / "geomint"

    # Baseline: build what the selected mutants need, run their tests and scenes unmutated.
    binaries = sorted({REGRESSION_BINARY} | {spec.split(":", 1)[0] for m in selected
                                             for spec in m.tests})
    if args.gates_only:
        binaries = []
    scenes = sorted({scene for m in selected for scene in m.scenes})
    configure(src, build, log_path)
    log(f"mutation: building the baseline (geomint {' '.join(binaries)}), log {log_path}")
    outcome = build_targets(build, ["geomint", *binaries], args.jobs, timeouts["build"], log_path)
    if outcome.code != 0:
        log(f"mutation: the unmutated copy does not build (see {log_path})")
        return 2
    log(f"mutation: baseline build {outcome.seconds:.0f} s")
    empty = sorted({f"{m.id}: {spec}" for m in selected for spec in m.tests
                    if not args.gates_only and count_tests(build, spec.split(":", 1)[0],
                                   test_invocations([spec])[spec.split(":", 1)[0]]) == 0})
    if empty:
        log("mutation: broken mutant list: these test entries select no test (gtest filters "
            "match the full name, e.g. Registry/EveryMethod.X/rk4: write *EveryMethod.*):\n  "
            + "\n  ".join(empty))
        return 2
    mode = gate_mode(geomint, src)

    baseline_failures: dict[str, set[str]] = {}
    # The behavioural tests' baseline: skipped with --no-test-baseline and in budget mode (CI runs
    # `make test` first, so they are known to pass); the regression test's is always taken,
    # since the committed tables may lag behind the code (then those scenes cannot kill).
    seconds = 0.0
    if not args.no_test_baseline and not args.budget_min > 0 and not args.gates_only:
        union: dict[str, list[str]] = {}
        for m in selected:
            for binary, gtest_filter in test_invocations(m.tests).items():
                union.setdefault(binary, []).append(gtest_filter)
        invocations = {}
        for binary, filters in union.items():
            positives = sorted({f.split("-", 1)[0] for f in filters})
            positive = "*" if "*" in positives else ":".join(positives)
            invocations[binary] = positive + (f"-{REGRESSION_FILTER}"
                                              if binary == REGRESSION_BINARY else "")
        failures, seconds = run_tests(build, invocations, "baseline", work, timeouts["test"],
                                      args.jobs, log_path)
        for binary, names in failures.items():
            baseline_failures[binary] = set(names)
    reg, reg_seconds = ({REGRESSION_BINARY: []}, 0.0) if args.gates_only else run_tests(
        build, {REGRESSION_BINARY: REGRESSION_FILTER}, "baseline-regression", work,
        timeouts["test"], 1, log_path)
    baseline_failures["#regression"] = set(reg[REGRESSION_BINARY])
    broken = sorted({n for names in baseline_failures.values() for n in names})
    log(f"mutation: baseline tests {seconds + reg_seconds:.0f} s, "
        f"{len(broken)} failing on the unmutated copy (they cannot kill)" +
        (": " + "; ".join(broken) if broken else ""))

    baseline_outputs, broken_scenes, seconds = sweep_scenes(
        geomint, src, scenes, args.jobs, timeouts["sweep"], log_path, work / "baseline")
    baseline_broken = {line.split(":", 1)[0] for line in broken_scenes}
    baseline_gates = run_gates(geomint, src, args.gates, mode, work / "stage-baseline",
                               baseline_outputs, timeouts["gate"], log_path) or {}
    passing = sorted(name for name, ok in baseline_gates.items() if ok)
    log(f"mutation: baseline quick scenes {seconds:.0f} s ({len(scenes)} scene(s)), gate mode "
        f"{mode}: {len(passing)} of {len(baseline_gates)} gate(s) pass on the baseline" +
        (f"; scenes broken on the baseline: {'; '.join(broken_scenes)}" if broken_scenes else ""))
    baseline_seconds = time.monotonic() - started

    records: list[Record] = []
    skipped: list[str] = []
    budget = args.budget_min * 60
    for index, mutant in enumerate(selected):
        elapsed = time.monotonic() - started
        if budget > 0 and records:
            # The slowest mutant so far, so that the budget is an upper bound, not a mean.
            per_mutant = max(r.total_seconds for r in records)
            if elapsed + per_mutant > budget:
                skipped = [m.id for m in selected[index:]]
                break
        log(f"mutation: [{index + 1}/{len(selected)}] {mutant.id}: {mutant.description}")
        record = Record(mutant)
        if args.gates_only and not mutant.scenes:
            # Nothing a gate could see and no test to run: not worth a rebuild.
            record.notes.append("no scene (tests only); not built with --gates-only")
            records.append(record)
            continue
        originals = {}
        try:
            for edit in mutant.edits:
                path = src / edit.file
                if path not in originals:
                    originals[path] = path.read_text()
                text = path.read_text()
                if text.count(edit.find) != 1:
                    raise ListError(f"{mutant.id}: 'find' no longer occurs once in {edit.file}")
                path.write_text(text.replace(edit.find, edit.replace, 1))

            targets = ["geomint", *sorted({REGRESSION_BINARY} |
                                          {s.split(":", 1)[0] for s in mutant.tests})]
            if args.gates_only:
                targets = ["geomint"]
            outcome = build_targets(build, targets, args.jobs, timeouts["build"], log_path)
            record.seconds["build"] = outcome.seconds
            if outcome.code != 0:
                record.build = "timeout" if outcome.code is None else "failed"
                record.notes.append(f"mutant does not build ({record.build}); fix the list")
                continue

            invocations = {} if args.gates_only else test_invocations(mutant.tests)
            start = time.monotonic()
            failures, _ = run_tests(build, invocations, mutant.id, work, timeouts["test"],
                                    args.jobs, log_path)
            regression, _ = ({REGRESSION_BINARY: []}, 0.0) if args.gates_only else run_tests(
                build, {REGRESSION_BINARY: REGRESSION_FILTER}, mutant.id + "-regression", work,
                timeouts["test"], 1, log_path)
            record.seconds["tests"] = time.monotonic() - start
            for binary, names in failures.items():
                known = baseline_failures.get(binary, set())
                record.tests += [n if n.startswith(binary) else f"{binary}:{n}"
                                 for n in names if n not in known]
            record.regression = [n for n in regression[REGRESSION_BINARY]
                                 if n not in baseline_failures.get("#regression", set())]

            outputs, broken, seconds = sweep_scenes(geomint, src, mutant.scenes, args.jobs,
                                                    timeouts["sweep"], log_path, None)
            record.seconds["scenes"] = seconds
            newly_broken = [line for line in broken
                            if line.split(":", 1)[0] not in baseline_broken]
            record.gates += newly_broken
            record.changed += [f"{line.split(':', 1)[0]}: sweep failed" for line in newly_broken]
            for scene, folder in outputs.items():
                if scene in baseline_outputs:
                    record.changed += [f"{scene}/{name}" for name in
                                       changed_tables(baseline_outputs[scene], folder)]
            if mutant.scenes and not record.changed:
                record.notes.append("no quick table of its scenes changed: not gate-visible "
                                    "(list a scene the bug moves, or none)")
            if mutant.scenes:
                composed = dict(baseline_outputs)
                composed.update(outputs)
                for scene in mutant.scenes:
                    if scene not in outputs:
                        composed.pop(scene, None)
                gates = run_gates(geomint, src, args.gates, mode, work / "stage-mutant",
                                  composed, timeouts["gate"], log_path)
                if gates is None:
                    record.gates.append("geomint gate: timeout or crash")
                else:
                    record.gates += [name for name in passing if not gates.get(name, False)]
        except ListError as error:
            log(f"mutation: {error}")
            return 2
        finally:
            for path, text in originals.items():
                path.write_text(text)  # new mtime: the next build recompiles the original
            records.append(record)
            log(f"mutation:   -> {record.verdict}: tests {short(record.tests, 2)}; regression "
                f"{'yes' if record.regression else '-'}; gates {short(record.gates, 2)} "
                f"({record.total_seconds:.0f} s)")

    total = time.monotonic() - started
    killed = [r for r in records if r.verdict.startswith("killed")]
    behavioural = [r for r in records if r.tests or r.gates]
    header = [
        f"list: {Path(args.list).relative_to(repo) if Path(args.list).is_relative_to(repo) else args.list}"
        f" ({len(mutants)} mutants); run: {len(records)} of {len(selected)} selected"
        + (f", skipped for the {args.budget_min:g}-minute budget: {', '.join(skipped)}"
           if skipped else ""),
        f"killed {len(killed)} of {len(records)}; by a behavioural test or a gate: "
        f"{len(behavioural)}; by the committed-row regression test only: "
        f"{sum(1 for r in records if r.verdict == 'killed (regression only)')}",
        ("tests not run (--gates-only); " if args.gates_only else "") +
        f"gate mode {mode}; {len(passing)} gate(s) pass on the baseline of scenes "
        f"{', '.join(scenes) or '-'}",
        f"time: {total:.0f} s in all, baseline {baseline_seconds:.0f} s, mutants "
        f"{sum(r.total_seconds for r in records):.0f} s "
        f"({(sum(r.total_seconds for r in records) / max(1, len(records))):.0f} s each on average); "
        f"rotation key {key[:12]}",
    ]
    whole_list = not (args.only or args.shard or skipped or len(records) < len(mutants))
    visible = [r for r in records if r.gate_visible]
    gate_killed = [r for r in records if r.gate_killed]
    missed = [r.mutant.id for r in visible if not r.gates]
    fraction = len(gate_killed) / len(visible) if visible else float("nan")
    below = bool(visible) and fraction < GATE_KILL_TARGET
    figure = (f"gates alone kill {len(gate_killed)} of {len(visible)} gate-visible mutants "
              f"({100 * fraction:.0f}%; target {100 * GATE_KILL_TARGET:.0f}%) "
              if visible else "no gate-visible mutant among those run ")
    figure += ("over the whole list" if whole_list else
               f"over the {len(records)} mutant(s) run, a subset of the {len(mutants)}: not the "
               f"list's figure")
    figure += (f"; {sum(1 for r in records if not r.mutant.scenes)} list no scene, "
               f"{sum(1 for r in records if r.mutant.scenes and not r.gate_visible)} list scenes "
               f"whose quick tables they do not move")
    if missed:
        figure += f"; missed by the gates: {', '.join(missed)}"
    header.insert(2, figure)
    csv_path, md_path = write_reports(records, scratch, header)
    print(md_path.read_text())
    print(f"mutation: report {md_path} and {csv_path}; log {log_path}")
    log(f"mutation: {figure}")
    code = 0
    bad = [r.mutant.id for r in records if r.verdict in ("SURVIVED", "invalid")]
    if args.gates_only:
        print("mutation: gates only (--gates-only): no test was run, so 'SURVIVED' means "
              "'not killed by a gate' and does not fail the run")
    elif bad:
        print(f"mutation: FAILED: not killed: {', '.join(bad)}")
        code = 1
    if below and whole_list:
        print(f"mutation: FAILED: the gates alone kill {100 * fraction:.0f}% of the gate-visible "
              f"mutants, below the {100 * GATE_KILL_TARGET:.0f}% target")
        code = 1
    elif below:
        print(f"mutation: WARNING: over this subset the gates alone kill "
              f"{100 * fraction:.0f}% of the gate-visible mutants (target "
              f"{100 * GATE_KILL_TARGET:.0f}% for the whole list; a subset does not fail on it)")
    return code


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Interrupted as interruption:
        log(f"mutation: interrupted ({interruption}); the scratch copy was restored")
        sys.exit(130)
