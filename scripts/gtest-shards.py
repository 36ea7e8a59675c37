#!/usr/bin/python3
"""Runs a build's GoogleTest tests in shards, a few processes per test executable, instead of
ctest's one process per test (docs/TESTING.md "Testing" and "Sanitizers and fuzzing").

A test process costs 15-50 ms of CPU before its test starts in a Release build (loading the shared
libraries, building the registry's test parameters) and 0.1-0.2 s under ASan + UBSan: with
~4000 tests, a process each is a third of `make test`'s ctest CPU time and of the sanitizer
suite's. Here each executable runs its tests with the filter its ctest tests were discovered with,
written by tests/slow_tests.cmake: `--labels fast` (the sanitizer suite) takes
<build>/gtest-fast-filter.txt (`-<slow>:<nosan>`), `--labels fast,nosan` (`make test`: all but the
`slow` tests) <build>/gtest-notslow-filter.txt (`-<slow>`). Tests are split by
GTEST_TOTAL_SHARDS / GTEST_SHARD_INDEX and run in ctest's working folder and environment. Before
running, the script checks that the executables' filtered test lists are exactly the tests
ctest would run with those labels, so the shards neither skip nor add a test. A shard that fails,
crashes (a sanitizer report ends the process) or outlives its time budget fails the run; its
failed tests and the end of its log are printed. With --others, the tests that are no GoogleTest
tests (Python, shell and CMake checks) and carry none of the labels left out (`slow`, and `nosan`
unless selected) run first, through ctest (`ctest -I` with their numbers).

usage: gtest-shards.py BUILD_DIR JOBS [--labels fast|fast,nosan] [--others] [--exclude REGEX]
                       [--shard-seconds S]
"""

import argparse
import json
import os
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed

# Tests per shard: enough that process start-up is a small share, few enough that two cores stay
# busy to the end (shards run longest-first).
TESTS_PER_SHARD = 120
MAX_SHARDS = 16


# The label sets a run may select, and the filter file tests/slow_tests.cmake writes for each.
FILTER_FILES = {"fast": "gtest-fast-filter.txt", "fast,nosan": "gtest-notslow-filter.txt"}


def fail(message):
    print(f"gtest-shards: {message}", file=sys.stderr)
    sys.exit(2)


def ctest_tests(build_dir, labels):
    """{executable: {"names": [gtest names], "cwd": folder, "env": {..}}} of `ctest -L <labels>`."""
    label_regex = "^(" + "|".join(labels.split(",")) + ")$"
    listing = subprocess.run(["ctest", "--show-only=json-v1", "-L", label_regex], cwd=build_dir,
                             capture_output=True, text=True, check=True).stdout
    executables = {}
    for test in json.loads(listing)["tests"]:
        command = test.get("command") or []
        filters = [arg[len("--gtest_filter="):] for arg in command
                   if arg.startswith("--gtest_filter=")]
        properties = {p["name"]: p["value"] for p in test.get("properties", [])}
        if not filters and "fast" not in properties.get("LABELS", []):
            continue  # a `nosan` test of ctest's own (Python, shell): --others runs it
        if len(filters) != 1:
            fail(f"ctest test '{test['name']}' is labelled fast but is no GoogleTest test: "
                 f"{command}")
        env = dict(item.split("=", 1) for item in properties.get("ENVIRONMENT", []))
        cwd = properties.get("WORKING_DIRECTORY", build_dir)
        entry = executables.setdefault(command[0], {"names": [], "cwd": cwd, "env": env,
                                                    "ctest_names": {}})
        if entry["cwd"] != cwd or entry["env"] != env:
            fail(f"{command[0]}: its tests differ in working folder or environment; "
                 "run them with ctest (SAN_PER_TEST=1)")
        entry["names"].append(filters[0])
        entry["ctest_names"][filters[0]] = test["name"]
    return executables


def is_gtest(test):
    return any(arg.startswith("--gtest_filter=") for arg in test.get("command") or [])


def run_other_tests(build_dir, labels, jobs):
    """Runs through ctest the tests that are no GoogleTest tests and carry no left-out label."""
    left_out = {"slow", "nosan"} - set(labels.split(","))
    listing = subprocess.run(["ctest", "--show-only=json-v1"], cwd=build_dir, capture_output=True,
                             text=True, check=True).stdout
    numbers = []
    for number, test in enumerate(json.loads(listing)["tests"], start=1):
        test_labels = set()
        for p in test.get("properties", []):
            if p["name"] == "LABELS":
                test_labels.update(p["value"])
        if not is_gtest(test) and not test_labels & left_out:
            numbers.append(str(number))
    if not numbers:
        return 0
    print(f"gtest-shards: {len(numbers)} other tests through ctest", flush=True)
    return subprocess.run(["ctest", "--output-on-failure", "-j", str(jobs),
                           "-I", "0,0,0," + ",".join(numbers)], cwd=build_dir).returncode


def listed_tests(executable, gtest_filter, cwd, env):
    """The names `executable --gtest_list_tests` prints under gtest_filter."""
    output = subprocess.run([executable, "--gtest_list_tests", f"--gtest_filter={gtest_filter}",
                             "--gtest_also_run_disabled_tests"],
                            cwd=cwd, env=env, capture_output=True, text=True, check=True).stdout
    names, suite = [], None
    for line in output.splitlines():
        if not line.strip():
            continue
        if not line.startswith(" "):
            suite = line.split("#")[0].strip()
        else:
            names.append(suite + line.split("#")[0].strip())
    return names


def run_shard(job):
    start = time.monotonic()
    with open(job["log"], "w") as log:
        try:
            status = subprocess.run(job["command"], cwd=job["cwd"], env=job["env"], stdout=log,
                                    stderr=subprocess.STDOUT, timeout=job["budget"]).returncode
        except subprocess.TimeoutExpired:
            status = "timeout"
    return job, status, time.monotonic() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("build_dir")
    parser.add_argument("jobs", type=int)
    parser.add_argument("--labels", default="fast", choices=sorted(FILTER_FILES),
                        help="the ctest labels whose GoogleTest tests run (default fast)")
    parser.add_argument("--others", action="store_true",
                        help="first run the tests that are no GoogleTest tests through ctest")
    parser.add_argument("--exclude", default="",
                        help="regex on ctest test names: matching tests are left out too")
    parser.add_argument("--shard-seconds", type=float, default=1800,
                        help="time budget of one shard (default 1800)")
    args = parser.parse_args()
    build_dir = os.path.abspath(args.build_dir)
    filter_file = os.path.join(build_dir, FILTER_FILES[args.labels])
    if not os.path.isfile(filter_file):
        fail(f"{filter_file} is missing: configure the build with tests on")
    with open(filter_file) as f:
        fast_filter = f.read().strip()
    if not fast_filter.startswith("-"):
        fail(f"{filter_file}: expected a negative GoogleTest filter, got '{fast_filter[:60]}'")
    exclude = re.compile(args.exclude) if args.exclude else None

    others_status = run_other_tests(build_dir, args.labels, args.jobs) if args.others else 0

    logs = os.path.join(build_dir, "gtest-shard-logs")
    os.makedirs(logs, exist_ok=True)
    jobs, expected_total = [], 0
    for executable, entry in sorted(ctest_tests(build_dir, args.labels).items()):
        env = dict(os.environ, **entry["env"])
        gtest_filter = fast_filter
        names = entry["names"]
        if exclude:
            left_out = [n for n in names if exclude.search(entry["ctest_names"][n])]
            names = [n for n in names if n not in left_out]
            if left_out:
                gtest_filter += ":" + ":".join(left_out)
        if not names:
            continue
        listed = listed_tests(executable, gtest_filter, entry["cwd"], env)
        if sorted(listed) != sorted(names):
            only_listed = sorted(set(listed) - set(names))[:5]
            only_ctest = sorted(set(names) - set(listed))[:5]
            fail(f"{executable}: its filtered test list differs from ctest's: only in the "
                 f"executable {only_listed}, only in ctest {only_ctest}")
        expected_total += len(names)
        shards = max(1, min(MAX_SHARDS, round(len(names) / TESTS_PER_SHARD)))
        for index in range(shards):
            shard_env = dict(env, GTEST_TOTAL_SHARDS=str(shards), GTEST_SHARD_INDEX=str(index))
            name = os.path.basename(executable)
            jobs.append({
                "label": f"{name} shard {index + 1}/{shards}",
                "command": [executable, f"--gtest_filter={gtest_filter}",
                            "--gtest_also_run_disabled_tests"],
                "cwd": entry["cwd"], "env": shard_env, "budget": args.shard_seconds,
                "log": os.path.join(logs, f"{name}.{index}.log"),
                "size": len(names) / shards})
    jobs.sort(key=lambda job: -job["size"])
    print(f"gtest-shards: {expected_total} tests in {len(jobs)} shards, {args.jobs} at a time; "
          f"logs in {logs}", flush=True)

    failed, ran_total = [], 0
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for future in as_completed([pool.submit(run_shard, job) for job in jobs]):
            job, status, seconds = future.result()
            with open(job["log"], errors="replace") as f:
                log = f.read()
            ran = sum(int(n) for n in re.findall(r"^\[==========\] (\d+) tests? from .* ran",
                                                   log, re.M))
            ran_total += ran
            verdict = "passed" if status == 0 else f"FAILED ({status})"
            print(f"  {job['label']}: {ran} tests, {seconds:.0f} s, {verdict}", flush=True)
            if status != 0:
                failed.append(job)
                failures = re.findall(r"^\[  FAILED  \] (\S+)", log, re.M)
                print("    failed tests: " + (", ".join(sorted(set(failures))) or "(none named: "
                                              "the process ended early, see below)"))
                print("    end of " + job["log"] + ":")
                print("\n".join("    | " + line for line in log.splitlines()[-60:]))
    if not failed and ran_total != expected_total:
        fail(f"the shards ran {ran_total} tests, ctest lists {expected_total}")
    if failed:
        print(f"gtest-shards: {len(failed)} of {len(jobs)} shards failed", file=sys.stderr)
    if others_status != 0:
        print("gtest-shards: some of the other tests (ctest, above) failed", file=sys.stderr)
    if failed or others_status != 0:
        sys.exit(1)
    print(f"gtest-shards: {ran_total} tests passed")


if __name__ == "__main__":
    main()
