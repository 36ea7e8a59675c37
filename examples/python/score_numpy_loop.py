"""Scores a trajectory computed by a plain numpy loop, outside the harness (docs/PYTHON.md
"score"): the same Störmer–Verlet as geomint's built-in, written as a loop over numpy arrays, is
handed to geomint.score as arrays (t, q, p), which computes every metric `geomint run` would;
stepping the harness's grid (h = t_k+1 − t_k), the loop does the built-in's arithmetic, and the
row agrees with the harness's own run of stormer_verlet to the bit.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/score_numpy_loop.py
"""

import sys

import numpy as np

import geomint

kepler = geomint.Problem("kepler:e=0.6")
dt, steps = 0.01, 1000

# The loop any numpy user would write: kick, drift, kick, storing every point.
q, p = kepler.initial_state()
t = np.arange(steps + 1) * dt
qs, ps = np.empty((steps + 1, 2)), np.empty((steps + 1, 2))
qs[0], ps[0] = q, p
for k in range(steps):
    h = t[k + 1] - t[k]  # dt to rounding, as the harness steps its grid t_k = k·dt
    p = p - 0.5 * h * kepler.grad_potential(q)
    q = q + h * p  # unit mass
    p = p - 0.5 * h * kepler.grad_potential(q)
    qs[k + 1], ps[k + 1] = q, p

scored = geomint.score(kepler, t, qs, ps)
print(f"scored {scored.row['steps']:.0f} steps: energy_err_max = {scored.row['energy_err_max']:.3e}, "
      f"error_final = {scored.row['error_final']:.3e}, "
      f"angular_momentum_err_max = {scored.row['angular_momentum_err_max']:.1e}")

# The harness's own run of the built-in method over the same grid.
run = geomint.run(kepler, "stormer_verlet", dt=dt, t_end=steps * dt)
agree = True
for column in ("energy_err_max", "energy_err_final", "energy_drift", "error_final", "phase_err"):
    ours, builtin = scored.row[column], run.row[column]
    close = ours == builtin
    agree = agree and close
    print(f"{column}: numpy loop {ours!r}, geomint run stormer_verlet {builtin!r}"
          f"{'' if close else '  DIFFERENT'}")
sys.exit(0 if agree and scored.ok else 1)
