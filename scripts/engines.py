#!/usr/bin/python3
"""Splits results/engines' summary.csv into the per-method tables its figures draw
(scripts/engines.gp): wp/<method>.csv (error and wall time over the step ladder of the block
"wp") and chain/<method>.csv (energy error and wall time per step against the number of links,
block "chain"). <method> is the name the series files use: mujoco_integrator_euler, del, ...
Usage: engines.py FOLDER (results/engines or results/engines/quick); --selftest checks the names."""
import csv
import os
import re
import sys


def series_name(method):
    """The series file name of a canonical method spec: an engine keeps its options but the
    default defaults=clean, geomint's methods keep their name only (their options are defaults)."""
    name, _, options = method.partition(":")
    if name not in ("mujoco", "ode", "bullet", "dart"):
        return name
    parts = [o for o in options.split(",") if o and o != "defaults=clean"]
    # Options in the order the series files write them (the spec's own option first).
    parts.sort(key=lambda o: o.startswith("defaults="))
    return "_".join([name] + [re.sub(r"[=,:]", "_", o) for o in parts])


def read_rows(path):
    with open(path, newline="") as table:
        return list(csv.DictReader(line for line in table if not line.startswith("#")))


def write_tables(folder, rows, label, key, columns):
    by_method = {}
    for row in rows:
        if row["label"] == label and row["status"] == "ok":
            by_method.setdefault(series_name(row["method"]), []).append(row)
    out = os.path.join(folder, label)
    os.makedirs(out, exist_ok=True)
    for name in os.listdir(out):
        if name.endswith(".csv"):
            os.remove(os.path.join(out, name))
    for name, method_rows in by_method.items():
        method_rows.sort(key=key)
        with open(os.path.join(out, name + ".csv"), "w", newline="") as table:
            writer = csv.writer(table, lineterminator="\n")
            writer.writerow([c for c, _ in columns])
            for row in method_rows:
                writer.writerow([f(row) for _, f in columns])


def links(row):
    return int(re.search(r"(?:^|[:,])n=(\d+)", row["problem"]).group(1))


def main(folder):
    rows = read_rows(os.path.join(folder, "summary.csv"))
    write_tables(folder, rows, "wp", lambda r: -float(r["dt"]),
                 [("dt", lambda r: r["dt"]), ("error_final", lambda r: r["error_final"]),
                  ("energy_err_max", lambda r: r["energy_err_max"]),
                  ("wall_s", lambda r: r["wall_s"]), ("wall_s_iqr", lambda r: r["wall_s_iqr"])])
    write_tables(folder, rows, "chain", links,
                 [("n", links), ("energy_err_max", lambda r: r["energy_err_max"]),
                  ("us_per_step",
                   lambda r: "%.6g" % (1e6 * float(r["wall_s"]) / int(r["steps"]))
                   if r["wall_s"] else "nan")])


def selftest():
    cases = {
        "mujoco:defaults=clean,integrator=euler": "mujoco_integrator_euler",
        "mujoco:defaults=shipped,integrator=euler": "mujoco_integrator_euler_defaults_shipped",
        "ode:defaults=clean,step=quick": "ode_step_quick",
        "bullet:defaults=shipped,integrator=rk4": "bullet_integrator_rk4_defaults_shipped",
        "del:force_at=midpoint,tol=1e-12": "del",
        "dart:defaults=clean,integrator=world": "dart_integrator_world",
        "dart:defaults=shipped,integrator=world": "dart_integrator_world_defaults_shipped",
        "rk4": "rk4",
    }
    for spec, expected in cases.items():
        assert series_name(spec) == expected, (spec, series_name(spec), expected)
    print("engines.py selftest: ok")


if __name__ == "__main__":
    if len(sys.argv) == 2 and sys.argv[1] == "--selftest":
        selftest()
    elif len(sys.argv) == 2:
        main(sys.argv[1])
    else:
        sys.exit("usage: engines.py FOLDER | --selftest")
