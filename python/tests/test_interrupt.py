"""Ctrl-C during a long harness call from Python (ctest python_interrupt, docs/PYTHON.md "Ctrl-C"):
SIGINT to a process inside geomint.run / order / a Python method's run ends the call promptly with
KeyboardInterrupt, the interpreter survives, and the next run is unaffected."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

SCRIPT = textwrap.dedent("""
    import sys, time
    import geomint

    def verlet(problem, q, p, t, h):
        p = p - 0.5 * h * problem.grad_potential(q)
        q = q + h * problem.inverse_mass() * p
        return q, p - 0.5 * h * problem.grad_potential(q)

    geomint.register_method("py_verlet", verlet, order=2, symplectic=True)
    # Minutes of work each (1e8 steps; 2e7 for the Python method).
    calls = {
        "run": lambda: geomint.run("kepler", "stormer_verlet", dt=1e-5, t_end=1e3),
        "timing": lambda: geomint.run("kepler", "stormer_verlet", dt=1e-4, t_end=1e3,
                                      timing_repeats=100),
        "order": lambda: geomint.order("kepler", "stormer_verlet", dt=1e-4, t_end=1e3, levels=3),
        "python_method": lambda: geomint.run("kepler", "py_verlet", dt=1e-4, t_end=2e3),
    }
    print("started", flush=True)
    start = time.monotonic()
    try:
        calls[sys.argv[1]]()
        print("finished without interruption", flush=True)
    except KeyboardInterrupt:
        print(f"KeyboardInterrupt after {time.monotonic() - start:.1f} s", flush=True)
    # The flag is cleared: the next run goes through.
    print("next run:", geomint.run("pendulum", "stormer_verlet", dt=0.1, t_end=1.0).status,
          flush=True)
""")


@pytest.mark.parametrize("call", ["run", "timing", "order", "python_method"])
def test_sigint_raises_keyboard_interrupt(call):
    process = subprocess.Popen([sys.executable, "-c", SCRIPT, call], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=os.environ.copy())
    try:
        assert process.stdout.readline().strip() == "started"
        time.sleep(1.0)  # inside the call, with the GIL released
        process.send_signal(signal.SIGINT)
        sent = time.monotonic()
        out, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 0, err
    assert "KeyboardInterrupt after" in out, out + err
    assert time.monotonic() - sent < 30
    assert "next run: ok" in out, out + err
