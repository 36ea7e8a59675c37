"""The cost of driving a Python integrator through the harness (docs/PERF.md "Python methods"):
Störmer–Verlet written in Python on Kepler (e = 0.6), 1e5 steps of 1e-3, run by geomint.run
(the metric pass: energy, momenta and the exact solution's error at every step point) against
the same Python loop calling the same step function by hand. Prints the median of the repeats of
each (interleaved, in one process), and the ratio; the target is a ratio <= 1.5.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [--repeats 7] [--steps 100000]
"""

import argparse
import os
import statistics
import time

import numpy as np

import geomint


def verlet(problem, q, p, t, h):
    p = p - 0.5 * h * problem.grad_potential(q)
    q = q + h * problem.inverse_mass() * p
    return q, p - 0.5 * h * problem.grad_potential(q)


def by_hand(problem, steps, dt):
    """The loop a user writes: the harness's grid t_k = k·dt, the same step function."""
    q, p = problem.initial_state()
    for k in range(1, steps + 1):
        t_next = k * dt
        t = (k - 1) * dt
        q, p = verlet(problem, q, p, t, t_next - t)
    return q, p


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--steps", type=int, default=100_000)
    args = parser.parse_args()
    dt = 1e-3
    problem = geomint.Problem("kepler:e=0.6")
    geomint.register_method("bench_py_verlet", verlet, order=2, symplectic=True, symmetric=True)

    harness_s, hand_s = [], []
    final_harness = final_hand = None
    for _ in range(args.repeats):
        start = time.perf_counter()
        run = geomint.run(problem, "bench_py_verlet", dt=dt, t_end=args.steps * dt)
        harness_s.append(time.perf_counter() - start)
        assert run.ok, run.row
        final_harness = (run.final_q, run.final_p)
        start = time.perf_counter()
        final_hand = by_hand(problem, args.steps, dt)
        hand_s.append(time.perf_counter() - start)
    # Both computed the same trajectory.
    assert np.array_equal(final_harness[0], final_hand[0])
    assert np.array_equal(final_harness[1], final_hand[1])
    harness, hand = statistics.median(harness_s), statistics.median(hand_s)
    load = os.getloadavg()[0]
    print(f"Kepler e=0.6, {args.steps} steps, median of {args.repeats} (load average {load:.1f})")
    print(f"harness (geomint.run, Python step): {harness:.3f} s  ({harness / args.steps * 1e6:.2f} us/step)")
    print(f"hand-written Python loop:           {hand:.3f} s  ({hand / args.steps * 1e6:.2f} us/step)")
    print(f"ratio: {harness / hand:.3f} (target <= 1.5)")


if __name__ == "__main__":
    main()
