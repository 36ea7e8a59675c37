#!/usr/bin/python3
"""Runs a build's `fast` GoogleTest tests in shards, a few processes per test executable, instead
of ctest's one process per test (docs/TESTING.md "Sanitizers and fuzzing").

Under ASan + UBSan a test process costs 0.1-0.2 s before its test starts (loading and
instrumenting the shared libraries, the leak check at exit): a third of the sanitizer suite's
time when each of its ~3400 tests has a process of its own. Here each executable runs its tests
with the filter its ctest tests were discovered with (`-<slow>:<nosan>`, written by
tests/slow_tests.cmake to <build>/gtest-fast-filter.txt), split by GTEST_TOTAL_SHARDS /
GTEST_SHARD_INDEX, in ctest's working folder and environment. Before running, the script checks that
the executables' filtered test lists are exactly the tests `ctest -L fast` would run, so the shards
neither skip nor add a test. A shard that fails, crashes (a sanitizer report ends the process) or
outlives its time budget fails the run; its failed tests and the end of its log are printed.

usage: test-sanitize.py BUILD_DIR JOBS [--exclude REGEX] [--shard-seconds S]
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


def fail(message):
    print(f"test-sanitize: {message}", file=sys.stderr)
    sys.exit(2)


def ctest_fast_tests(build_dir):
    """{executable: {"names": [gtest names], "cwd": folder, "env": {..}}} of `ctest -L fast`."""
    listing = subprocess.run(["ctest", "--show-only=json-v1", "-L", "^fast$"], cwd=build_dir,
                             capture_output=True, text=True, check=True).stdout
    executables = {}
    for test in json.loads(listing)["tests"]:
        command = test.get("command") or []
        filters = [arg[len("--gtest_filter="):] for arg in command
                   if arg.startswith("--gtest_filter=")]
        if len(filters) != 1:
            fail(f"ctest test '{test['name']}' is labelled fast but is no GoogleTest test: "
                 f"{command}")
        properties = {p["name"]: p["value"] for p in test.get("properties", [])}
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
    parser.add_argument("--exclude", default="",
                        help="regex on ctest test names: matching tests are left out too")
    parser.add_argument("--shard-seconds", type=float, default=1800,
                        help="time budget of one shard (default 1800)")
    args = parser.parse_args()
    build_dir = os.path.abspath(args.build_dir)
    filter_file = os.path.join(build_dir, "gtest-fast-filter.txt")
    if not os.path.isfile(filter_file):
        fail(f"{filter_file} is missing: configure the build with tests on")
    with open(filter_file) as f:
        fast_filter = f.read().strip()
    if not fast_filter.startswith("-"):
        fail(f"{filter_file}: expected a negative GoogleTest filter, got '{fast_filter[:60]}'")
    exclude = re.compile(args.exclude) if args.exclude else None

    logs = os.path.join(build_dir, "sanitize-logs")
    os.makedirs(logs, exist_ok=True)
    jobs, expected_total = [], 0
    for executable, entry in sorted(ctest_fast_tests(build_dir).items()):
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
    print(f"test-sanitize: {expected_total} tests in {len(jobs)} shards, {args.jobs} at a time; "
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
        print(f"test-sanitize: {len(failed)} of {len(jobs)} shards failed", file=sys.stderr)
        sys.exit(1)
    print(f"test-sanitize: {ran_total} tests passed")


if __name__ == "__main__":
    main()
