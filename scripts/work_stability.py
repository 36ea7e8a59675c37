#!/usr/bin/env python3
"""Post-processing of results/work_stability (issue 29 item 4), run by scripts/reproduce.sh after the
sweep: joins each method's largest stable h (stability.csv) with its cost per step (the timing pass
of summary.csv) into work_stability.csv, fits log-log slopes against the stiffness and finds where
the best implicit method overtakes the best explicit one (work_stability_fit.csv), and writes one
curve file per problem and method under curves/ for scripts/work_stability.gp.

Each point lies on one stiffness axis: stiff_spring's ratio, fpu_stiff's omega^2, and the elastic
bar's Young's modulus (a fixed mesh) or its refinement (omega_max^2 of the mesh). The axis of a bar
point comes from its [[stability]] block's label ("bar_young_..." or "bar_mesh_..."), since the
canonical problem spec lists every parameter and cannot tell the two apart.

Usage: work_stability.py FOLDER   (results/work_stability or results/work_stability/quick)
"""
import csv
import math
import os
import sys

from geomint_tables import read_table

# Every method's step is capped per axis: about 30 steps per period of the slow mode. stiff_spring's
# slow frequency is ~0.71 and fpu_stiff's soft springs oscillate at O(1), hence 0.3; the bar's first
# bending mode has a period of ~3.1 s at E = 1e5 (beam theory: omega_1 = 1.875^2 sqrt(E I/(rho A
# L^4)) = 2.03 rad/s), hence 0.1. The implicit methods, stable for every h, are charged for
# resolving the slow motion the way an animator would. On the Young's-modulus axis the cap stays
# 0.1 at every E (a fixed frame step), although the bending period scales as E^(-1/2) there.
H_CAP = {"ratio": 0.3, "omega2": 0.3, "young": 0.1, "mesh": 0.1}


def axis_of(label, name):
    """The stiffness axis of a stability row: 'ratio' (stiff_spring), 'omega2' (fpu_stiff),
    'young' or 'mesh' (elastic_bar, from the block label); None for a problem not on any axis."""
    if name == "elastic_bar":
        return "young" if label.startswith("bar_young") else (
            "mesh" if label.startswith("bar_mesh") else None)
    return {"stiff_spring": "ratio", "fpu_stiff": "omega2"}.get(name)


# Stiffness on the x axis, from the problem's parameters and omega_max at its initial state: the
# spring-constant ratio k_stiff/k_soft of stiff_spring; omega^2 for fpu_stiff (its stiff springs
# have constant omega^2/2, the soft ones are O(1)); Young's modulus E for the bar on a fixed mesh;
# omega_max^2 for the bar under refinement (omega_max grows as 1/cell size). On every axis an
# explicit method's limit falls as stiffness^(-1/2).
STIFFNESS = {
    "ratio": lambda params, omega: float(params["ratio"]),
    "omega2": lambda params, omega: float(params["omega"]) ** 2,
    "young": lambda params, omega: float(params["young"]),
    "mesh": lambda params, omega: omega ** 2,
}


def panel_of(problem, axis):
    """Name of the figure panel and curve files: the problem, or elastic_bar_<axis>."""
    return f"{problem}_{axis}" if problem == "elastic_bar" else problem


def split_problem(spec):
    name, _, rest = spec.partition(":")
    params = dict(item.split("=", 1) for item in rest.split(",") if item)
    return name, params


def short_method(spec):
    """A curve name that scripts/common.gp's ms() knows: 'composition:base=...,scheme=yoshida4' ->
    composition_yoshida4, 'sprk:table=blanes_moan4' -> sprk_blanes_moan4, defaults dropped."""
    name, _, rest = spec.partition(":")
    params = dict(item.split("=", 1) for item in rest.split(",") if item)
    if name == "composition":
        return "composition_" + params.get("scheme", "yoshida4")
    if name == "sprk":
        return "sprk_" + params.get("table", "")
    return name


def fit_slope(points):
    """Least-squares slope of log10(y) against log10(x); NaN with fewer than 2 points."""
    if len(points) < 2:
        return math.nan
    xs = [math.log10(x) for x, _ in points]
    ys = [math.log10(y) for _, y in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx


def crossover(best_explicit, best_implicit):
    """Stiffness where log(best implicit / best explicit) first turns from negative to >= 0,
    interpolated linearly in log-log between neighbouring stiffness values; NaN when it never does
    (or when the implicit method already wins at the smallest stiffness: no crossover in range)."""
    ks = sorted(k for k in best_explicit if k in best_implicit)
    logs = [math.log10(best_implicit[k] / best_explicit[k]) for k in ks]
    if not ks or logs[0] >= 0:
        return math.nan
    for (k0, r0), (k1, r1) in zip(zip(ks, logs), zip(ks[1:], logs[1:])):
        if r0 < 0 <= r1:
            x0, x1 = math.log10(k0), math.log10(k1)
            return 10 ** (x0 + (x1 - x0) * (-r0) / (r1 - r0))
    return math.nan


def fmt(x):
    return "nan" if isinstance(x, float) and math.isnan(x) else f"{x:.6g}"


def main(folder):
    summary, provenance = read_table(os.path.join(folder, "summary.csv"))
    stability, _ = read_table(os.path.join(folder, "stability.csv"))
    # Provenance of the derived tables: the sweep's (build, scene, variant), then how they were made.
    header = [line for line in provenance if not line.startswith("# command:")]
    header.append("# derived: scripts/work_stability.py from summary.csv and stability.csv")

    # Cost per step from the timing pass: one row per (problem, method). The fastest of the
    # repeats (wall_s_min), not the median: on a loaded machine the other processes only ever
    # add time, so the minimum is the least disturbed estimate; the IQR gives the error bars.
    cost = {}
    for row in summary:
        if row["status"] != "ok" or not row.get("wall_s"):
            continue
        steps = float(row["steps"])
        evaluations = float(row["force_evals"]) + float(row["hessian_evals"] or 0)
        cost[(row["problem"], row["method"])] = (
            float(row["wall_s_min"]) / steps,
            float(row["wall_s_iqr"] or 0) / steps,
            evaluations / steps,
            float(row["newton_iters"] or 0) / steps,
            row["family"],
        )

    records = []
    for row in stability:
        name, params = split_problem(row["problem"])
        axis = axis_of(row["label"], name)
        if axis is None or (row["problem"], row["method"]) not in cost:
            continue
        omega = float(row["omega"])
        if row["status"] == "unstable_at_min":
            continue  # no stable step in the searched range: no point on the diagram
        h_stable = float(row["homega_max_measured"]) / omega
        h_cap = H_CAP[axis]
        limited = row["status"] == "bracketed" and h_stable < h_cap
        h_used = min(h_stable, h_cap)
        wall, wall_iqr, evals, newton, family = cost[(row["problem"], row["method"])]
        records.append({
            "problem": name,
            "axis": axis,
            "stiffness": STIFFNESS[axis](params, omega),
            "method": short_method(row["method"]),
            "kind": "implicit" if "implicit" in row["label"] else "explicit",
            "family": family,
            "stability_status": row["status"],
            "h_stable": h_stable if row["status"] == "bracketed" else math.inf,
            "h_used": h_used,
            "limited_by": "stability" if limited else "cap",
            "wall_per_step": wall,
            "wall_per_step_iqr": wall_iqr,
            "evals_per_step": evals,
            "newton_per_step": newton,
            "sim_per_cpu_s": h_used / wall,
            "sim_per_eval": h_used / evals,
        })
    records.sort(key=lambda r: (r["problem"], r["axis"], r["kind"], r["method"], r["stiffness"]))

    columns = ["problem", "axis", "stiffness", "method", "kind", "family", "stability_status",
               "h_stable", "h_used", "limited_by", "wall_per_step", "wall_per_step_iqr",
               "evals_per_step", "newton_per_step", "sim_per_cpu_s", "sim_per_eval"]
    with open(os.path.join(folder, "work_stability.csv"), "w", newline="") as handle:
        handle.write("\n".join(header) + "\n")
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(columns)
        for r in records:
            writer.writerow([fmt(r[c]) if isinstance(r[c], float) else r[c] for c in columns])

    # Slopes: the explicit methods over their stability-limited points only (at the smallest
    # stiffness a method may reach the cap), the implicit ones over all points.
    fit_rows = []
    groups = {}
    for r in records:
        groups.setdefault((r["problem"], r["axis"], r["method"], r["kind"]), []).append(r)
    for (problem, axis, method, kind), rows in sorted(groups.items()):
        used = [r for r in rows if kind == "implicit" or r["limited_by"] == "stability"]
        fit_rows.append([problem, axis, method, kind, len(used),
                         fmt(fit_slope([(r["stiffness"], r["sim_per_cpu_s"]) for r in used])),
                         fmt(fit_slope([(r["stiffness"], r["sim_per_eval"]) for r in used])), "",
                         "", "", ""])
    for problem, axis in sorted({(r["problem"], r["axis"]) for r in records}):
        best = {}
        for measure in ("sim_per_cpu_s", "sim_per_eval"):
            for kind in ("explicit", "implicit"):
                table, winner = {}, {}
                for r in records:
                    if r["problem"] == problem and r["axis"] == axis and r["kind"] == kind:
                        if r[measure] > table.get(r["stiffness"], 0):
                            table[r["stiffness"]], winner[r["stiffness"]] = r[measure], r["method"]
                best[(measure, kind)] = (table, winner)
        cross_wall = crossover(best[("sim_per_cpu_s", "explicit")][0],
                               best[("sim_per_cpu_s", "implicit")][0])
        cross_work = crossover(best[("sim_per_eval", "explicit")][0],
                               best[("sim_per_eval", "implicit")][0])
        top = max(best[("sim_per_eval", "explicit")][0])
        fit_rows.append([problem, axis, "best_implicit_vs_best_explicit", "crossover",
                         len(best[("sim_per_eval", "explicit")][0]), "", "", fmt(cross_wall),
                         fmt(cross_work), best[("sim_per_eval", "explicit")][1][top],
                         best[("sim_per_eval", "implicit")][1][top]])
    with open(os.path.join(folder, "work_stability_fit.csv"), "w", newline="") as handle:
        handle.write("\n".join(header) + "\n")
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(["problem", "axis", "method", "kind", "points", "slope_sim_per_cpu_s",
                         "slope_sim_per_eval", "crossover_stiffness_wall",
                         "crossover_stiffness_work", "best_explicit_at_max",
                         "best_implicit_at_max"])
        writer.writerows(fit_rows)

    # One curve per problem and method for the figure (stiffness, sim_per_cpu_s, its spread from
    # the timing IQR, sim_per_eval).
    curves = os.path.join(folder, "curves")
    os.makedirs(curves, exist_ok=True)
    for old in os.listdir(curves):
        os.remove(os.path.join(curves, old))
    for (problem, axis, method, kind), rows in groups.items():
        with open(os.path.join(curves, f"{panel_of(problem, axis)}__{method}.dat"), "w") as handle:
            handle.write("# stiffness sim_per_cpu_s sim_per_cpu_s_lo sim_per_cpu_s_hi sim_per_eval\n")
            for r in rows:
                # Bars from the fastest repeat down to fastest + IQR: the spread of the timing.
                lo = r["h_used"] / (r["wall_per_step"] + r["wall_per_step_iqr"])
                hi = r["sim_per_cpu_s"]
                handle.write(f"{r['stiffness']:.6g} {r['sim_per_cpu_s']:.6g} {lo:.6g} {hi:.6g} "
                             f"{r['sim_per_eval']:.6g}\n")


def selftest():
    """Runs main() on a made-up folder whose answers are known in closed form: explicit limits
    h = 2/omega at one evaluation a step, implicit ones stable to the cap at 3 evaluations a step.
    stiff_spring (omega = sqrt(k), cap 0.3): slopes -1/2 and 0, a capped explicit point left out of
    the fit, no point for an explicit search stuck at its minimum, crossover 2/sqrt(k) = 0.3/3 at
    k = 400. The bar (cap 0.1): on the Young axis (omega = sqrt(E)/10, stiffness E) the crossover
    20/sqrt(E) = 0.1/3 is at E = 3.6e5; on the mesh axis (stiffness omega^2) 2/omega = 0.1/3 at
    omega^2 = 3600. Exit 1 naming the first wrong number (ctest WorkStability.selftest)."""
    import tempfile
    folder = tempfile.mkdtemp(prefix="work_stability_selftest_")
    provenance = "# geomint: selftest\n# scene: work_stability\n# variant: quick\n"
    # (labels' prefix, problem spec, omega) per point. At k = 10 the explicit limit 0.63 is above
    # the cap 0.3; at E = 1e4 (h = 0.2) and omega^2 = 100 (h = 0.2) above the bar's cap 0.1.
    points = [("", f'"stiff_spring:ratio={k:g}"', math.sqrt(k)) for k in (10.0, 1e2, 1e4, 1e6)]
    points += [("bar_young_", f'"elastic_bar:nx=2,young={e:g}"', math.sqrt(e) / 10)
               for e in (1e4, 1e5, 1e6, 1e7)]
    points += [("bar_mesh_", f'"elastic_bar:nx={n},young=1000"', math.sqrt(k))
               for n, k in ((2, 1e2), (3, 1e3), (4, 1e4), (5, 1e5))]
    with open(os.path.join(folder, "summary.csv"), "w") as summary, \
         open(os.path.join(folder, "stability.csv"), "w") as stability:
        summary.write(provenance + "label,problem,method,family,status,steps,force_evals,"
                      "hessian_evals,newton_iters,wall_s,wall_s_min,wall_s_iqr\n")
        stability.write(provenance + "label,problem,method,omega,homega_max_measured,status\n")
        for prefix, problem, omega in points:
            cap = 0.3 if prefix == "" else 0.1
            for label, method, evals, status, homega in (
                    ("explicit_limit", "stormer_verlet", 1, "bracketed", 2.0),
                    ("explicit_limit", "rk4", 4, "unstable_at_min", 0.5),
                    ("implicit_limit", "implicit_euler", 3, "stable_to_max", cap * omega)):
                summary.write(f"t,{problem},{method},f,ok,100,{100 * evals},0,0,{2e-6 * evals},{1e-6 * evals},0\n")
                stability.write(f"{prefix}{label},{problem},{method},{omega!r},{homega!r},{status}\n")
    main(folder)
    fits = {(r["axis"], r["method"], r["kind"]): r for r in read_table(
        os.path.join(folder, "work_stability_fit.csv"))[0]}
    rows = read_table(os.path.join(folder, "work_stability.csv"))[0]
    cross = "best_implicit_vs_best_explicit", "crossover"
    checks = [
        ("explicit slope per evaluation", fits[("ratio", "stormer_verlet", "explicit")]["slope_sim_per_eval"], -0.5),
        ("explicit slope per CPU-second", fits[("ratio", "stormer_verlet", "explicit")]["slope_sim_per_cpu_s"], -0.5),
        ("explicit points fitted (the capped one left out)", fits[("ratio", "stormer_verlet", "explicit")]["points"], 3),
        ("implicit slope per evaluation", fits[("ratio", "implicit_euler", "implicit")]["slope_sim_per_eval"], 0.0),
        ("crossover per evaluation", fits[("ratio",) + cross]["crossover_stiffness_work"], 400.0),
        ("crossover per CPU-second", fits[("ratio",) + cross]["crossover_stiffness_wall"], 400.0),
        ("bar, Young axis: explicit slope per evaluation", fits[("young", "stormer_verlet", "explicit")]["slope_sim_per_eval"], -0.5),
        ("bar, Young axis: explicit points fitted (cap 0.1)", fits[("young", "stormer_verlet", "explicit")]["points"], 3),
        ("bar, Young axis: crossover per evaluation", fits[("young",) + cross]["crossover_stiffness_work"], 3.6e5),
        ("bar, mesh axis: explicit slope per evaluation", fits[("mesh", "stormer_verlet", "explicit")]["slope_sim_per_eval"], -0.5),
        ("bar, mesh axis: implicit slope per evaluation", fits[("mesh", "implicit_euler", "implicit")]["slope_sim_per_eval"], 0.0),
        ("bar, mesh axis: crossover per evaluation", fits[("mesh",) + cross]["crossover_stiffness_work"], 3600.0),
        ("bar, mesh axis: implicit h_used (the cap)", [r for r in rows if r["axis"] == "mesh" and r["kind"] == "implicit"][0]["h_used"], 0.1),
        ("points (none for a search stuck at its minimum)", len(rows), 24),
    ]
    for what, got, expected in checks:
        if not math.isclose(float(got), expected, rel_tol=1e-9, abs_tol=1e-12):
            sys.exit(f"work_stability selftest: {what} = {got}, expected {expected} ({folder})")
    import shutil
    shutil.rmtree(folder)
    print(f"work_stability selftest: {len(checks)} checks passed")


if __name__ == "__main__":
    if len(sys.argv) == 2 and sys.argv[1] == "--selftest":
        selftest()
    elif len(sys.argv) != 2:
        sys.exit("usage: work_stability.py FOLDER (results/work_stability[/quick]) | --selftest")
    else:
        main(sys.argv[1])
