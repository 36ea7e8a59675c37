#!/usr/bin/env python3
"""Maps a reference trajectory computed in joint or angle coordinates to the constrained Cartesian
formulation of the same system (results/coordinates/README.md; ../shared/MECHANICS.md §5).

The constrained problems (rod_chain, spherical_pendulum) have no reference of their own: the
generator integrates unconstrained systems only. Their Cartesian runs are measured against the
other formulation's reference mapped through x = X(theta), p_cart = m dX/dt, so a Cartesian error
that falls at the order of its method is the two formulations agreeing.

usage: coordinates_reference.py rod_chain|spherical_pendulum SOURCE.csv TARGET_SPEC OUT.csv
  rod_chain: SOURCE is a rod_chain:coordinates=joint reference, TARGET_SPEC the Cartesian spec
  (the same masses, lengths and gravity); spherical_pendulum: SOURCE a coordinates=angles one.
"""
import math
import sys


def parse_spec(spec):
    """'name:a=1,b=2' -> {'a': '1', 'b': '2'}."""
    _, _, options = spec.partition(":")
    values = {}
    for item in filter(None, options.split(",")):
        key, _, value = item.partition("=")
        values[key] = value
    return values


def solve(matrix, rhs):
    """Gaussian elimination with partial pivoting (M(theta) is SPD and small)."""
    n = len(rhs)
    a = [row[:] + [rhs[i]] for i, row in enumerate(matrix)]
    for col in range(n):
        pivot = max(range(col, n), key=lambda r: abs(a[r][col]))
        a[col], a[pivot] = a[pivot], a[col]
        for r in range(col + 1, n):
            factor = a[r][col] / a[col][col]
            for c in range(col, n + 1):
                a[r][c] -= factor * a[col][c]
    x = [0.0] * n
    for r in reversed(range(n)):
        x[r] = (a[r][n] - sum(a[r][c] * x[c] for c in range(r + 1, n))) / a[r][r]
    return x


def rod_chain_row(values, theta, p_theta):
    n = len(theta)
    mass = float(values.get("mass", 1))
    mass_ratio = float(values.get("mass_ratio", 1))
    length = float(values.get("length", 1))
    length_ratio = float(values.get("length_ratio", 1))
    masses = [mass * mass_ratio**i for i in range(n)]
    lengths = [length * length_ratio**i for i in range(n)]
    # M(theta)_ij = sum_{k >= max(i, j)} m_k l_i l_j cos(theta_i - theta_j) (MECHANICS.md §5).
    tail_mass = [sum(masses[k:]) for k in range(n)]
    matrix = [[tail_mass[max(i, j)] * lengths[i] * lengths[j] * math.cos(theta[i] - theta[j])
               for j in range(n)] for i in range(n)]
    theta_dot = solve(matrix, p_theta)
    q, p = [], []
    x = y = vx = vy = 0.0
    for i in range(n):
        x += lengths[i] * math.sin(theta[i])
        y -= lengths[i] * math.cos(theta[i])
        vx += lengths[i] * math.cos(theta[i]) * theta_dot[i]
        vy += lengths[i] * math.sin(theta[i]) * theta_dot[i]
        q += [x, y]
        p += [masses[i] * vx, masses[i] * vy]
    return q, p


def spherical_pendulum_row(values, angles, p_angles):
    mass = float(values.get("mass", 1))
    length = float(values.get("length", 1))
    theta, phi = angles
    inertia = mass * length * length
    theta_dot = p_angles[0] / inertia
    phi_dot = p_angles[1] / (inertia * math.sin(theta) ** 2)
    st, ct, sp, cp = math.sin(theta), math.cos(theta), math.sin(phi), math.cos(phi)
    # theta from the downward vertical (-z), phi the azimuth.
    q = [length * st * cp, length * st * sp, -length * ct]
    v = [length * (ct * cp * theta_dot - st * sp * phi_dot),
         length * (ct * sp * theta_dot + st * cp * phi_dot),
         length * st * theta_dot]
    return q, [mass * component for component in v]


def main():
    if len(sys.argv) != 5 or sys.argv[1] not in ("rod_chain", "spherical_pendulum"):
        sys.stderr.write(__doc__)
        sys.exit(2)
    kind, source, target_spec, out = sys.argv[1:]
    mapper = rod_chain_row if kind == "rod_chain" else spherical_pendulum_row
    values = parse_spec(target_spec)
    header, rows = [], []
    with open(source) as file:
        for line in file:
            if line.startswith("#"):
                header.append(line.rstrip("\n"))
            elif line.startswith("t,"):
                dof = (len(line.strip().split(",")) - 1) // 2
            elif line.strip():
                numbers = [float(x) for x in line.split(",")]
                q, p = mapper(values, numbers[1:1 + dof], numbers[1 + dof:])
                rows.append([numbers[0]] + q + p)
    cartesian_dof = (len(rows[0]) - 1) // 2
    with open(out, "w") as file:
        for line in header:
            if line.startswith("# reference_problem: "):
                file.write(f"# mapped_from: {line[len('# reference_problem: '):]}\n")
                file.write(f"# reference_problem: {target_spec}\n")
            elif line.startswith("# command: "):
                file.write(line + "\n")
                file.write(f"# mapped_by: scripts/coordinates_reference.py {kind} "
                           f"{source.split('/')[-1]} {target_spec} (positions and m v of the "
                           "Cartesian formulation; the error estimate is the source's)\n")
            else:
                file.write(line + "\n")
        columns = ["t"] + [f"q_{i}" for i in range(cartesian_dof)] + \
                  [f"p_{i}" for i in range(cartesian_dof)]
        file.write(",".join(columns) + "\n")
        for row in rows:
            file.write(",".join(repr(x) for x in row) + "\n")


if __name__ == "__main__":
    main()
