"""Checks Störmer–Verlet on Kepler from Python without plotting (docs/PYTHON.md): a run's row,
its time series, the Problem API on the final state, and the fitted order.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/verlet_check.py
"""

import sys

import numpy as np

import geomint

kepler = geomint.Problem("kepler:e=0.6")
q0, p0 = kepler.initial_state()
energy0 = kepler.energy(q0, p0)

# One orbit (the problem's default horizon is ten), every 10th step point kept in the series.
run = geomint.run(kepler, "stormer_verlet", dt=0.01, t_end=2 * np.pi, series_every=10)
assert run.status == "ok", run.row
print(f"{run.row['method']}: {run.row['steps']:.0f} steps, "
      f"energy_err_max = {run.row['energy_err_max']:.2e}, error_final = {run.row['error_final']:.2e}")

# A symplectic method keeps the energy error bounded: no drift over the orbit.
relative = np.abs(run.series.energy - energy0) / abs(energy0)
assert relative.max() < 1e-2, relative.max()
# The row's energy_err_final is the same quantity at the last step point, from the final state.
final = abs(kepler.energy(run.final_q, run.final_p) - energy0) / abs(energy0)
assert np.isclose(final, run.row["energy_err_final"], rtol=1e-12), (final, run.row)
# Angular momentum q × p is conserved to round-off by Störmer–Verlet.
angular = run.series.invariants["angular_momentum_0"]
assert np.ptp(angular) < 1e-12, np.ptp(angular)

# Second order, as declared: the slope of log error over dt = 0.01·2^-k.
ladder = geomint.order(kepler, "stormer_verlet", dt=0.01, t_end=2 * np.pi, levels=4)
fit = ladder.attrs["fit"]
print(f"fitted order {fit['order']:.3f} (declared {fit['declared_order']:.0f})")
print(ladder[["dt", "status", "error_final"]].to_string(index=False))
sys.exit(0 if abs(fit["order"] - 2) < 0.1 else 1)
