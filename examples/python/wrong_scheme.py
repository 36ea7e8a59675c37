"""Verifies two integrators written in Python with geomint's checks (docs/PYTHON.md "Python
methods"): a hand-written Störmer–Verlet passes every check its flags call for, and a "Verlet"
that reuses the old force in its second kick — first order, not symplectic, though it claims
both — is flagged by the order, energy and symplectic-map checks. Exit 0 when both verdicts hold.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/wrong_scheme.py
"""

import sys

import geomint


def verlet(problem, q, p, t, h):
    """Störmer–Verlet (kick-drift-kick), hand-written."""
    p = p - 0.5 * h * problem.grad_potential(q)
    q = q + h * problem.inverse_mass() * p
    return q, p - 0.5 * h * problem.grad_potential(q)


def stale_verlet(problem, q, p, t, h):
    """Velocity Verlet with the old force in the second kick (wrong on purpose)."""
    force = problem.grad_potential(q)
    p = p - 0.5 * h * force
    q = q + h * problem.inverse_mass() * p
    return q, p - 0.5 * h * force  # should be ∇V at the new q


FLAGS = dict(order=2, symplectic=True, symmetric=True)
geomint.register_method("hand_verlet", verlet, **FLAGS)
geomint.register_method("stale_verlet", stale_verlet, **FLAGS)

verdicts = {}
for method in ("hand_verlet", "stale_verlet"):
    report = geomint.verify(method)
    applied = report[report["applies"]]
    print(f"{method}: {int(applied['passed'].sum())} of {len(applied)} checks passed")
    for text in applied["text"]:
        print("  " + text)
    verdicts[method] = dict(zip(applied["check"] + " " + applied["problem"], applied["passed"]))

correct_passes = all(verdicts["hand_verlet"].values())
failed = [check for check, passed in verdicts["stale_verlet"].items() if not passed]
flagged = any(check.startswith("declared_order") for check in failed) and any(
    check.startswith(("energy_without_drift", "symplectic_map")) for check in failed)
print(f"hand_verlet passes every check: {correct_passes}; stale_verlet flagged by: {failed}")
sys.exit(0 if correct_passes and flagged else 1)
