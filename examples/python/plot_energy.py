"""Plots a run's time series with matplotlib (docs/PYTHON.md "Example"): the Kepler orbit of
Störmer–Verlet and explicit Euler, and their relative energy error over time, from the numpy
arrays of geomint.run(...).series. Writes the figure to the path given (default
kepler_energy.png). matplotlib is not a dependency of geomint: without it the script says how to
install it and exits 0 without plotting.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/plot_energy.py [figure.png]
"""

import sys

try:
    import matplotlib

    matplotlib.use("Agg")  # write a file; no display needed
    import matplotlib.pyplot as plt
except ImportError:
    print("plot_energy.py: skipped, matplotlib is not installed: install python3-matplotlib "
          "(sudo apt-get install python3-matplotlib) to draw the figure")
    sys.exit(0)

import numpy as np

import geomint

figure_path = sys.argv[1] if len(sys.argv) > 1 else "kepler_energy.png"
kepler = geomint.Problem("kepler:e=0.6")
q0, p0 = kepler.initial_state()
energy0 = kepler.energy(q0, p0)

fig, (orbit_axes, energy_axes) = plt.subplots(1, 2, figsize=(10, 4.5))
for method in ("stormer_verlet", "explicit_euler"):
    # Three orbits, every step point kept, the positions in the series (series_state).
    run = geomint.run(kepler, method, dt=0.005, t_end=6 * np.pi, series_every=1, series_state=True)
    series = run.series
    orbit_axes.plot(series.q[:, 0], series.q[:, 1], label=method, linewidth=0.8)
    relative = np.abs(series.energy - energy0) / abs(energy0)
    # The error is 0 at t = 0: plot from the first step on (log scale).
    energy_axes.semilogy(series.t[1:], relative[1:], label=method, linewidth=0.8)
    print(f"{method}: status {run.status}, energy_err_max = {run.row['energy_err_max']:.3e}")

orbit_axes.set(xlabel="q_0", ylabel="q_1", title="Kepler e = 0.6, dt = 0.005", aspect="equal")
energy_axes.set(xlabel="t", ylabel="|H - H(0)| / |H(0)|", title="Relative energy error")
for axes in (orbit_axes, energy_axes):
    axes.legend()
fig.tight_layout()
fig.savefig(figure_path, dpi=120)
print(f"wrote {figure_path}")
