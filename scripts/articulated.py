#!/usr/bin/env python3
"""Post-processing of results/articulated, run by scripts/reproduce.sh after the sweep: the cost
blocks of summary.csv (labels cost_*) per step and per method against the number of links n
(cost.csv: wall time, recursive passes, force evaluations and Newton iterations per step), the
least-squares exponent of wall time per step against n over n = 64 ... 1024, and over 16 ... 64
where the dense and capped forms stop (cost_fit.csv, a row per range with two n or more; column
exponent), the same exponent of the work per step that no machine changes, n times the recursive
passes per step (each pass visits every link once; column work_exponent, only for the blocks
whose methods do nothing else: RECURSIVE_BLOCKS, engines aside), and one curve file per block and method under curves/ for
scripts/articulated.gp.

Usage: articulated.py FOLDER     (results/articulated or results/articulated/quick)
       articulated.py --selftest (the fit and the n parser on made-up rows)
"""
import csv
import math
import os
import re
import shutil
import sys

from geomint_tables import read_table

FIT_RANGES = [(64, 1024), (16, 64)]
# The blocks whose geomint methods do nothing per step but O(n) recursive passes (no dense or
# sparse factorisation: cost_dense's LU and cost_rattle's KKT solve are not passes), so that n ×
# the passes per step is their whole work; and the methods of provider `engine` (geomint list
# methods), whose counted passes are the adapter's (the momentum read back after each engine
# step), not the engine's own work.
RECURSIVE_BLOCKS = ("cost_recursive", "cost_articulated")
ENGINES = ("mujoco", "ode", "bullet", "dart")


def links_of(problem):
    """The number of links n of a chain problem spec (its n= parameter)."""
    found = re.search(r"(?:^|[:,])n=(\d+)(?:,|$)", problem)
    if not found:
        raise ValueError(f"problem '{problem}' has no n= parameter")
    return int(found.group(1))


def number(text):
    return float(text) if text not in (None, "") else None


def fit_exponent(points):
    """Least-squares slope of log(cost) against log(n); None below two distinct n."""
    points = [(n, c) for n, c in points if c is not None and c > 0]
    if len({n for n, _ in points}) < 2:
        return None
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(c) for _, c in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx


def fit_work_exponent(label, method, points, n_low, n_high):
    """The exponent of n × recursive passes per step over n_low ... n_high (each pass visits every
    link once); None outside RECURSIVE_BLOCKS, for an engine, and unless every point in the range
    counted its passes."""
    if label not in RECURSIVE_BLOCKS or method.partition(":")[0] in ENGINES:
        return None
    in_range = [p for p in points if n_low <= p["n"] <= n_high]
    if not in_range or not all(p["recursive_passes_per_step"] for p in in_range):
        return None
    return fit_exponent([(p["n"], p["n"] * p["recursive_passes_per_step"]) for p in in_range])


def fmt(value):
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value) if value != int(value) or abs(value) >= 1e15 else str(int(value))
    return str(value)


def curve_name(label, method):
    """A curve file's name: the block label, then the method's name and the option that tells its
    variants apart (integrator= or step=), as scripts/common.gp's style keys spell them
    ("cost_recursive__bullet_integrator_rk4")."""
    name, _, options = method.partition(":")
    variant = [option.replace("=", "_") for option in options.split(",")
               if option.startswith(("integrator=", "step="))]
    return f"{label}__" + "_".join([name] + variant)


def main(folder):
    summary, provenance = read_table(os.path.join(folder, "summary.csv"))
    header = [line for line in provenance if not line.startswith("# command:")]
    cost = []
    for row in summary:
        if not row["label"].startswith("cost_") or row["status"] != "ok":
            continue
        steps = int(row["steps"])
        wall = number(row.get("wall_s"))
        per_step = lambda column: (number(row.get(column)) or 0.0) / steps
        cost.append({
            "label": row["label"],
            "method": row["method"],
            "problem": row["problem"].split(":")[0],
            "n": links_of(row["problem"]),
            "steps": steps,
            "wall_s_per_step": wall / steps if wall is not None else None,
            "recursive_passes_per_step": number(row.get("recursive_passes_per_step")),
            "force_evals_per_step": per_step("force_evals"),
            "newton_iters_per_step": per_step("newton_iters"),
        })
    series = {}
    for point in cost:
        series.setdefault((point["label"], point["method"], point["problem"]), []).append(point)
    fits = []
    for (label, method, problem), points in series.items():
        for n_low, n_high in FIT_RANGES:
            in_range = [(p["n"], p["wall_s_per_step"]) for p in points
                        if n_low <= p["n"] <= n_high]
            exponent = fit_exponent(in_range)
            if exponent is None:
                continue
            work_exponent = fit_work_exponent(label, method, points, n_low, n_high)
            fits.append({
                "label": label, "method": method, "problem": problem,
                "n_range": f"{n_low}-{n_high}",
                "n_min": min(n for n, _ in in_range), "n_max": max(n for n, _ in in_range),
                "points": len(in_range), "exponent": round(exponent, 3),
                "work_exponent": round(work_exponent, 3) if work_exponent is not None else None,
            })
    write(os.path.join(folder, "cost.csv"), header, cost,
          ["label", "method", "problem", "n", "steps", "wall_s_per_step",
           "recursive_passes_per_step", "force_evals_per_step", "newton_iters_per_step"])
    write(os.path.join(folder, "cost_fit.csv"), header, fits,
          ["label", "method", "problem", "n_range", "n_min", "n_max", "points", "exponent",
           "work_exponent"])
    curves = os.path.join(folder, "curves")
    shutil.rmtree(curves, ignore_errors=True)
    os.makedirs(curves)
    for (label, method, _), points in series.items():
        with open(os.path.join(curves, curve_name(label, method) + ".csv"), "w") as handle:
            handle.write("n,wall_s_per_step\n")
            for p in sorted(points, key=lambda p: p["n"]):
                if p["wall_s_per_step"] is not None:
                    handle.write(f"{p['n']},{p['wall_s_per_step']!r}\n")


def write(path, header, rows, columns):
    with open(path, "w", newline="") as handle:
        handle.write("\n".join(header) + "\n")
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(columns)
        for row in rows:
            writer.writerow([fmt(row[c]) for c in columns])


def selftest():
    assert links_of("rod_chain:coordinates=joint,gravity=1,n=256,omega=0") == 256
    assert links_of("articulated_chain:n=8") == 8
    assert links_of("rope:gravity=1,n=1024") == 1024
    # Cost c n^p is fitted as p, whatever c.
    assert abs(fit_exponent([(n, 3e-7 * n ** 1.0) for n in (64, 128, 256)]) - 1.0) < 1e-12
    assert abs(fit_exponent([(n, 2e-9 * n ** 3.0) for n in (64, 128)]) - 3.0) < 1e-12
    assert fit_exponent([(64, 1.0)]) is None
    # Passes per step constant in n: work exactly O(n); passes growing as n^0.25: n^1.25; a point
    # without a pass count (an engine) leaves the work exponent empty.
    flat = [{"n": n, "recursive_passes_per_step": 16.0} for n in (64, 256, 1024)]
    assert abs(fit_work_exponent("cost_recursive", "rk4", flat, 64, 1024) - 1.0) < 1e-12
    growing = [{"n": n, "recursive_passes_per_step": 3.0 * n ** 0.25} for n in (64, 128, 1024)]
    assert abs(fit_work_exponent("cost_recursive", "del:tol=1e-12", growing, 64, 1024) - 1.25) < 1e-12
    assert fit_work_exponent("cost_recursive", "rk4", flat + [{"n": 512, "recursive_passes_per_step": None}], 64, 1024) \
        is None
    assert fit_work_exponent("cost_recursive", "rk4", flat, 2, 32) is None
    assert fit_work_exponent("cost_recursive", "bullet:integrator=euler", flat, 64, 1024) is None
    assert fit_work_exponent("cost_dense", "del:solve=dense", flat, 64, 1024) is None
    assert curve_name("cost_mujoco", "mujoco:defaults=clean,integrator=rk4") == \
        "cost_mujoco__mujoco_integrator_rk4"
    assert curve_name("cost_dense", "del:force_at=midpoint,tol=1e-12") == "cost_dense__del"
    print("articulated.py selftest: ok")


if __name__ == "__main__":
    if len(sys.argv) == 2 and sys.argv[1] == "--selftest":
        selftest()
    elif len(sys.argv) == 2:
        main(sys.argv[1])
    else:
        sys.exit(__doc__)
