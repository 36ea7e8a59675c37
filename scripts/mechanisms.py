#!/usr/bin/env python3
"""Post-processing of results/mechanisms, run by scripts/reproduce.sh after the sweep: the elastic
rod's tip (series column `tip`) against d'Alembert's triangle wave, for every run with a series
(series/rod_*/), into rod_front.csv.

The continuum tip of a fixed-free rod at rest when the end load F is switched on rises at the speed
F c/(EA) to 2FL/(EA) at t = 2L/c and falls back to 0 at 4L/c (period 4L/c, c = sqrt(E/rho)).
Columns: tip_err_max and tip_err_mean = max and mean over the step points of |tip - u_dAlembert|
relative to the peak 2FL/(EA); tip_peak = the largest tip over the run relative to it; courant =
c dt / (L/N), the time step in units of an element's transit time.

Usage: mechanisms.py FOLDER   (results/mechanisms or results/mechanisms/quick)
"""
import csv
import math
import os
import sys


def read_series(path):
    """The comment lines (provenance: '# key: value') and the rows of a geomint series CSV."""
    with open(path, newline="") as handle:
        lines = handle.read().splitlines()
    comments = {}
    for line in lines:
        if line.startswith("# ") and ": " in line:
            key, value = line[2:].split(": ", 1)
            comments.setdefault(key, value)
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    return comments, rows


def parameters(spec):
    """The key=value pairs of a canonical problem spec 'name:k=v,k=v'."""
    _, _, body = spec.partition(":")
    return dict(item.split("=", 1) for item in body.split(",") if "=" in item)


def dalembert_tip(t, length, speed, load, axial):
    travel = 2 * length / speed
    phase = math.fmod(t, 2 * travel)
    rising = phase if phase <= travel else 2 * travel - phase
    return load / axial * speed * rising


def main():
    folder = sys.argv[1]
    with open(os.path.join(folder, "summary.csv")) as handle:
        provenance = [line.rstrip("\n") for line in handle if line.startswith("#")]
    provenance = [line for line in provenance if not line.startswith("# command:")]
    out_rows = []
    series_root = os.path.join(folder, "series")
    for label in sorted(os.listdir(series_root)) if os.path.isdir(series_root) else []:
        if not label.startswith("rod_"):
            continue
        for name in sorted(os.listdir(os.path.join(series_root, label))):
            comments, rows = read_series(os.path.join(series_root, label, name))
            p = parameters(comments["problem"])
            length, young = float(p["length"]), float(p["young"])
            density, area, load = float(p["density"]), float(p["area"]), float(p["load"])
            elements = int(p["elements"])
            speed, axial = math.sqrt(young / density), young * area
            peak = 2 * load * length / axial
            errors = [abs(float(r["tip"]) - dalembert_tip(float(r["t"]), length, speed, load, axial))
                      for r in rows]
            dt = float(comments["dt"])
            out_rows.append({
                "label": label, "problem": comments["problem"], "method": comments["method"],
                "dt": comments["dt"], "courant": f"{speed * dt * elements / length:.6g}",
                "tip_err_max": f"{max(errors) / abs(peak):.6g}",
                "tip_err_mean": f"{sum(errors) / len(errors) / abs(peak):.6g}",
                "tip_peak": f"{max(float(r['tip']) for r in rows) / peak:.6g}",
            })
    columns = ["label", "problem", "method", "dt", "courant", "tip_err_max", "tip_err_mean",
               "tip_peak"]
    with open(os.path.join(folder, "rod_front.csv"), "w", newline="") as handle:
        for line in provenance:
            handle.write(line + "\n")
        handle.write("# derived: scripts/mechanisms.py from series/rod_*/ (the tip against "
                     "d'Alembert's triangle wave)\n")
        writer = csv.DictWriter(handle, columns, lineterminator="\n")
        writer.writeheader()
        writer.writerows(out_rows)


if __name__ == "__main__":
    main()
