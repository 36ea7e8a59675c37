#!/usr/bin/env python3
"""Post-processing of results/articulated_full (scripts/reproduce.sh runs it): the wall time per
step of its long-chain runs, one file per method in long_curves/ (n, wall_s_per_step) for
scripts/articulated_full.gp. MuJoCo's and DART's 1024-link steps are the difference of their 120-
and 24-step runs over the 96 steps between them, which leaves out the model build (README).

usage: articulated_full.py FOLDER | --selftest"""
import csv
import os
import re
import shutil
import sys

from articulated import curve_name
from geomint_tables import read_table


def links(problem):
    """n of a chain spec (its n= parameter)."""
    match = re.search(r"(?:^|[:,])n=(\d+)", problem)
    return int(match.group(1)) if match else None


def per_step_points(summary):
    """{curve name: [(n, seconds per step)]} of the timed rows of summary.csv."""
    points, short_long = {}, {}
    for row in summary:
        label = row["label"]
        if not label.startswith("cost_") or row["status"] != "ok" or not row.get("wall_s"):
            continue
        n, steps, wall = links(row["problem"]), int(row["steps"]), float(row["wall_s"])
        if label.endswith(("_short", "_long")):
            # The block ("cost_mujoco" of "cost_mujoco_1024_short") and the method name a pair.
            pair = (label.split("_1024")[0], row["method"])
            short_long.setdefault(pair, {})[label.rsplit("_", 1)[1]] = (n, steps, wall)
            continue
        name = curve_name(label.split("_1024")[0], row["method"])
        points.setdefault(name, []).append((n, wall / steps))
    for (block, method), runs in short_long.items():
        if "short" in runs and "long" in runs:
            (n, steps_short, wall_short), (_, steps_long, wall_long) = runs["short"], runs["long"]
            if steps_long <= steps_short:
                continue  # the quick form runs both to the same step count: no difference to take
            name = curve_name(block, method)
            points.setdefault(name, []).append(
                (n, (wall_long - wall_short) / (steps_long - steps_short)))
    return {name: sorted(values) for name, values in points.items()}


def main(folder):
    summary, _ = read_table(os.path.join(folder, "summary.csv"))
    out = os.path.join(folder, "long_curves")
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    for name, values in per_step_points(summary).items():
        with open(os.path.join(out, name + ".csv"), "w", newline="") as handle:
            writer = csv.writer(handle, lineterminator="\n")
            writer.writerow(["n", "wall_s_per_step"])
            for n, seconds in values:
                writer.writerow([n, f"{seconds:.6g}"])


def selftest():
    summary = [
        {"label": "cost_mujoco", "problem": "rod_chain:coordinates=joint,n=256", "steps": "240",
         "wall_s": "1.2", "status": "ok", "method": "mujoco:defaults=clean,integrator=rk4"},
        {"label": "cost_mujoco_1024_short", "problem": "rod_chain:n=1024", "steps": "24",
         "wall_s": "10", "status": "ok", "method": "mujoco:integrator=rk4"},
        {"label": "cost_mujoco_1024_long", "problem": "rod_chain:n=1024", "steps": "120",
         "wall_s": "34", "status": "ok", "method": "mujoco:integrator=rk4"},
        {"label": "rope_1024", "problem": "rope:n=1024", "steps": "100000", "wall_s": "",
         "status": "ok", "method": "rk4"},
    ]
    summary += [
        {"label": "cost_dart_1024_short", "problem": "rod_chain:n=1024", "steps": "24",
         "wall_s": "2", "status": "ok", "method": "dart:integrator=world"},
        {"label": "cost_dart_1024_long", "problem": "rod_chain:n=1024", "steps": "120",
         "wall_s": "2.96", "status": "ok", "method": "dart:integrator=world"},
    ]
    points = per_step_points(summary)
    assert points["cost_mujoco__mujoco_integrator_rk4"] == [(256, 0.005), (1024, 0.25)], points
    assert points["cost_dart__dart_integrator_world"] == [(1024, 0.01)], points
    assert len(points) == 2, points
    del summary[-2:]
    summary[2]["steps"] = "24"  # the quick form: both runs equally long
    assert per_step_points(summary) == {"cost_mujoco__mujoco_integrator_rk4": [(256, 0.005)]}
    print("articulated_full.py selftest: ok")


if __name__ == "__main__":
    if len(sys.argv) == 2 and sys.argv[1] == "--selftest":
        selftest()
    elif len(sys.argv) == 2:
        main(sys.argv[1])
    else:
        sys.exit(__doc__)
