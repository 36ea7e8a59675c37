"""Integrators written in Python in the harness (ctest python_methods, docs/PYTHON.md "Python
methods"): a hand-written Verlet gets the verify kit's verdicts of the built-in Störmer–Verlet,
wrong schemes are flagged, and every bad return of a step is a failure row naming what was wrong."""

import math
import threading

import numpy as np
import pytest

import geomint


def verlet(problem, q, p, t, h):
    """Störmer–Verlet, kick-drift-kick, written by hand."""
    p = p - 0.5 * h * problem.grad_potential(q)
    q = q + h * problem.inverse_mass() * p
    p = p - 0.5 * h * problem.grad_potential(q)
    return q, p


def symplectic_euler(problem, q, p, t, h):
    p = p - h * problem.grad_potential(q)
    return q + h * problem.inverse_mass() * p, p


def explicit_euler(problem, q, p, t, h):
    return q + h * problem.inverse_mass() * p, p - h * problem.grad_potential(q)


VERLET_FLAGS = dict(symplectic=True, symmetric=True, variational=True)
geomint.register_method("py_verlet", verlet, order=2, **VERLET_FLAGS)
# Wrong on purpose: first-order schemes declaring more than they have.
geomint.register_method("py_euler_as_order2", symplectic_euler, order=2, symplectic=True)
geomint.register_method("py_euler_as_symplectic", explicit_euler, order=1, symplectic=True)


def verdicts(method):
    frame = geomint.verify(method)
    return {row.check + ":" + row.problem: (row.applies, row.passed) for row in frame.itertuples()}


def test_registered_method_is_listed_with_provider_user():
    entry = next(m for m in geomint.methods() if m["name"] == "py_verlet")
    assert entry["provider"] == "user" and entry["builtin"] is False
    assert entry["order"] == 2 and entry["family"] == "explicit_symplectic"
    assert {"explicit", "symplectic", "symmetric", "variational"} <= set(entry["flags"])
    assert entry["summary"] == "Störmer–Verlet, kick-drift-kick, written by hand."


def test_hand_written_verlet_gets_the_builtin_verdicts():
    # Störmer–Verlet declares the same flags: every check applies and passes for both.
    ours, builtin = verdicts("py_verlet"), verdicts("stormer_verlet")
    assert ours == builtin
    applied = [passed for applies, passed in ours.values() if applies]
    assert len(applied) >= 6 and all(applied)


def test_run_row_equals_the_builtin_arithmetic():
    # The same kick-drift-kick in numpy gives the built-in's trajectory to the bit on Kepler.
    ours = geomint.run("kepler", "py_verlet", dt=0.01, t_end=1.0)
    builtin = geomint.run("kepler", "stormer_verlet", dt=0.01, t_end=1.0)
    assert ours.ok and ours.row["method"] == "py_verlet"
    for column in ("energy_err_max", "energy_drift", "error_final", "angular_momentum_err_max"):
        assert ours.row[column] == builtin.row[column], column
    assert ours.row["steps"] == 100 and ours.row["force_evals"] == 200  # two ∇V per step


def test_order_ladder_of_a_python_method():
    ladder = geomint.order("pendulum", "py_verlet", dt=0.1, t_end=1.0, levels=4)
    assert list(ladder["status"]) == ["ok"] * 4
    assert abs(ladder.attrs["fit"]["order"] - 2) < 0.1


def test_first_order_scheme_declared_second_order_is_flagged():
    result = geomint.check("py_euler_as_order2", "declared_order_pendulum")
    assert result["applies"] and not result["passed"], result["text"]
    assert abs(result["measured"] - 1) < 0.3


def test_explicit_euler_declared_symplectic_is_flagged():
    energy = geomint.check("py_euler_as_symplectic", "energy_without_drift")
    assert energy["applies"] and not energy["passed"], energy["text"]
    symplectic = geomint.check("py_euler_as_symplectic", "symplectic_map")
    assert symplectic["applies"] and not symplectic["passed"], symplectic["text"]


def returning(value):
    def step(problem, q, p, t, h):
        if t >= 0.25:  # a few good steps first: the row's t_reached names the step that failed
            return value(q, p) if callable(value) else value
        return verlet(problem, q, p, t, h)

    return step


def raising(problem, q, p, t, h):
    if t >= 0.25:
        raise ZeroDivisionError("the scheme divided by zero")
    return verlet(problem, q, p, t, h)


BAD_RETURNS = {
    "exception": (raising, "python_exception",
                  "step() raised ZeroDivisionError: the scheme divided by zero"),
    "none": (returning(None), "python_bad_return", "it returned a NoneType"),
    "three_items": (returning(lambda q, p: (q, p, p)), "python_bad_return",
                    "it returned a tuple of length 3"),
    "wrong_length": (returning(lambda q, p: (np.zeros(3), p)), "python_bad_return",
                     "q has shape (3,)"),
    "matrix": (returning(lambda q, p: (q, np.zeros((2, 2)))), "python_bad_return",
               "p has shape (2, 2)"),
    "text": (returning(lambda q, p: ("abc", p)), "python_bad_return",
             "q is a str, not an array of numbers"),
    "nan": (returning(lambda q, p: (q, np.array([p[0], math.nan]))), "nan",
            "step() returned p[1] = nan"),
    "inf": (returning(lambda q, p: (np.array([math.inf, q[1]]), p)), "nan",
            "step() returned q[0] = inf"),
}


@pytest.mark.parametrize("case", sorted(BAD_RETURNS))
def test_bad_return_is_a_failure_row_naming_it(case):
    step, status, text = BAD_RETURNS[case]
    name = geomint.register_method(f"py_bad_{case}", step, order=2)
    result = geomint.run("kepler", name, dt=0.1, t_end=1.0)
    assert not result.ok and result.status == status, result.row
    assert text in result.row["message"], result.row["message"]
    assert "t=0.3" in result.row["message"] and result.row["t_reached"] == pytest.approx(0.3)
    assert result.row["steps"] == 3
    # The verify kit gets a failed check, not a crash.
    check = geomint.check(name, "declared_order_pendulum")
    assert check["applies"] and not check["passed"]


def test_exception_message_names_the_line():
    result = geomint.run("kepler", "py_bad_exception", dt=0.1, t_end=1.0)
    assert "test_python_methods.py:" in result.row["message"]


class StatefulVerlet:
    """Verlet that reuses the last force, counting its resets: one instance per run."""

    name = "py_class_verlet"
    order = 2
    flags = ["symplectic", "symmetric"]

    def __init__(self):
        self.resets = 0
        self.force = None

    def reset(self, problem, q, p, t, h):
        self.resets += 1
        self.force = problem.grad_potential(q)

    def step(self, problem, q, p, t, h):
        assert self.resets == 1
        p = p - 0.5 * h * self.force
        q = q + h * problem.inverse_mass() * p
        self.force = problem.grad_potential(q)
        return q, p - 0.5 * h * self.force


def test_a_class_is_instantiated_per_run():
    geomint.register_method(StatefulVerlet)
    first = geomint.run("pendulum", "py_class_verlet", dt=0.05, t_end=1.0)
    second = geomint.run("pendulum", "py_class_verlet", dt=0.05, t_end=1.0)
    builtin = geomint.run("pendulum", "stormer_verlet", dt=0.05, t_end=1.0)
    assert first.ok and second.ok, first.row
    assert first.row["energy_err_max"] == second.row["energy_err_max"]
    assert first.row["energy_err_max"] == builtin.row["energy_err_max"]
    assert first.row["force_evals"] == 21  # one per step plus the reset's


def test_registration_errors_name_what_is_wrong():
    with pytest.raises(ValueError, match="already registered"):
        geomint.register_method("stormer_verlet", verlet, order=2)
    with pytest.raises(ValueError, match="flag 'adaptive' cannot be declared.*allowed: explicit"):
        geomint.register_method("py_adaptive", verlet, order=2, flags=["adaptive"])
    with pytest.raises(ValueError, match="order = 0"):
        geomint.register_method("py_order0", verlet, order=0)
    with pytest.raises(ValueError, match="needs its order"):
        geomint.register_method("py_no_order", verlet)
    with pytest.raises(TypeError, match="neither a function"):
        geomint.register_method("py_not_callable", 42, order=2)
    assert "py_adaptive" not in [m["name"] for m in geomint.methods()]


def test_registering_a_name_again_replaces_the_python_method():
    geomint.register_method("py_replaced", explicit_euler, order=1)
    before = geomint.run("pendulum", "py_replaced", dt=0.1, t_end=1.0)
    geomint.register_method("py_replaced", verlet, order=2, symplectic=True)
    after = geomint.run("pendulum", "py_replaced", dt=0.1, t_end=1.0)
    assert after.row["energy_err_max"] < before.row["energy_err_max"]
    assert after.row["family"] == "explicit_symplectic"


def test_problem_kept_after_the_run_is_refused():
    kept = []

    def keeping(problem, q, p, t, h):
        kept.append(problem)
        return verlet(problem, q, p, t, h)

    geomint.register_method("py_keeping", keeping, order=2)
    assert geomint.run("pendulum", "py_keeping", dt=0.1, t_end=0.2).ok
    with pytest.raises(ValueError, match="valid during its run only"):
        kept[0].grad_potential(np.zeros(1))


def test_not_applicable_where_the_step_cannot_see_the_problem():
    # A damped oscillator has a force F(q, v, t) a Python step does not see: refused up front.
    with pytest.raises(ValueError, match="py_verlet"):
        geomint.run("damped_oscillator", "py_verlet", dt=0.1, t_end=1.0)


def test_python_methods_run_from_several_threads():
    # Each run releases the GIL and each step takes it again: concurrent runs neither deadlock
    # nor mix their states.
    rows = [None] * 4

    def work(i):
        rows[i] = geomint.run("kepler", "py_verlet", dt=0.01, t_end=2.0).row

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert all(row["status"] == "ok" for row in rows)
    assert len({row["energy_err_max"] for row in rows}) == 1


def test_score_of_a_numpy_loop_equals_the_python_method_run():
    # The loop of py_verlet's step on the harness's grid t_k = k·dt (each step h = t_k+1 − t_k,
    # as the harness computes it), written out: geomint.score gives the row of geomint.run.
    problem = geomint.Problem("kepler")
    dt, steps = 0.01, 300
    t = np.arange(steps + 1) * dt
    q, p = problem.initial_state()
    qs, ps = [q], [p]
    for k in range(steps):
        q, p = verlet(problem, q, p, t[k], t[k + 1] - t[k])
        qs.append(q)
        ps.append(p)
    scored = geomint.score(problem, t, np.array(qs), np.array(ps))
    run = geomint.run(problem, "py_verlet", dt=dt, t_end=steps * dt)
    assert scored.ok and scored.row["method"] == "arrays"
    for column in ("energy_err_max", "energy_err_final", "energy_drift", "error_final",
                   "angular_momentum_err_max", "phase_err"):
        assert scored.row[column] == run.row[column], column
    with pytest.raises(ValueError, match="row"):
        geomint.score(problem, [0.0, 0.0], np.array(qs[:2]), np.array(ps[:2]))


class FailingReset:
    name = "py_failing_reset"
    order = 2

    def reset(self, problem, q, p, t, h):
        raise RuntimeError("no history to start from")

    def step(self, problem, q, p, t, h):
        return q, p


def test_a_failing_reset_is_a_failure_row():
    geomint.register_method(FailingReset)
    result = geomint.run("pendulum", "py_failing_reset", dt=0.1, t_end=1.0)
    assert not result.ok and result.status == "python_exception", result.row
    assert "reset failed" in result.row["message"]
    assert "RuntimeError: no history to start from" in result.row["message"]
    assert result.row["steps"] == 0
