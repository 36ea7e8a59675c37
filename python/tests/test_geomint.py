"""The Python package against the geomint program (ctest python_package, docs/PYTHON.md): every
registered method on two problems gives the row `geomint run` writes, cell for cell; the Problem
API agrees with the program's series; bad input is a ValueError with the program's message."""

import csv
import io
import math
import os
import subprocess
import tempfile

import numpy as np
import pytest

import geomint

HERE = os.path.dirname(os.path.abspath(__file__))
GEOMINT = os.environ.get("GEOMINT_EXE", os.path.join(HERE, "..", "..", "build", "geomint"))
# Short runs: the suite compares every method on both problems in well under a minute.
PROBLEMS = {"pendulum": (0.05, 1.0), "kepler": (0.01, 0.5)}
TIMING_COLUMNS = ("wall_s", "wall_s_min", "wall_s_iqr", "wall_s_repeats")


def cli(*args):
    return subprocess.run([GEOMINT, *args], capture_output=True, text=True, check=False)


def number_or_text(text):
    """The CLI's cell parsed here, independently of the package: float() of the text."""
    try:
        return float(text)
    except ValueError:
        return text


def cli_rows(text):
    lines = [line for line in text.splitlines(keepends=True) if not line.startswith("#")]
    return [
        {key: number_or_text(value) for key, value in row.items() if value != ""}
        for row in csv.DictReader(io.StringIO("".join(lines)))
    ]


def same_cells(a, b):
    """Equal cell for cell, NaN equal to NaN (both parsed from the same text 'nan')."""
    if a.keys() != b.keys():
        return False
    for key, value in a.items():
        other = b[key]
        if isinstance(value, float) and isinstance(other, float):
            if not (value == other or (math.isnan(value) and math.isnan(other))):
                return False
        elif value != other:
            return False
    return True


def without_timing(row):
    return {key: value for key, value in row.items() if key not in TIMING_COLUMNS}


@pytest.mark.parametrize("problem", sorted(PROBLEMS))
@pytest.mark.parametrize("method", [entry["name"] for entry in geomint.methods()])
def test_run_row_equals_cli_row(problem, method):
    dt, t_end = PROBLEMS[problem]
    done = cli("run", "--problem", problem, "--method", method, "--dt", str(dt), "--t-end",
               str(t_end), "--timing-repeats", "0")
    if done.returncode == 2:  # the program refuses the pair (e.g. the method does not apply)
        with pytest.raises(ValueError) as refused:
            geomint.run(problem, method, dt=dt, t_end=t_end)
        assert str(refused.value) in done.stderr
        return
    assert done.returncode in (0, 1), done.stderr
    [expected] = cli_rows(done.stdout)
    result = geomint.run(problem, method, dt=dt, t_end=t_end)
    assert same_cells(without_timing(result.row), without_timing(expected))
    assert result.status == cli_status(done.stdout)
    assert result.ok == (done.returncode == 0)
    assert [c for c in result.columns if c not in TIMING_COLUMNS] == [
        c for c in cli_columns(done.stdout) if c not in TIMING_COLUMNS
    ]


def cli_status(text):
    """The status cell as the program wrote it (text: "nan" stays "nan")."""
    lines = [line for line in text.splitlines(keepends=True) if not line.startswith("#")]
    return next(csv.DictReader(io.StringIO("".join(lines))))["status"]


def cli_columns(text):
    header = next(line for line in text.splitlines() if not line.startswith("#"))
    return header.split(",")


def listed_names(what, known):
    """The registry names `geomint list WHAT` prints first on its lines, in its order."""
    lines = cli("list", what).stdout.splitlines()
    return [line.split()[0] for line in lines if line.split() and line.split()[0] in known]


def test_registries_match_geomint_list():
    methods = [entry["name"] for entry in geomint.methods()]
    assert listed_names("methods", set(methods)) == methods
    problems = geomint.problems()
    names = [entry["name"] for entry in problems]
    assert listed_names("problems", set(names)) == names
    for entry in problems:
        problem = geomint.Problem(entry["name"])
        assert (problem.dof, problem.capabilities) == (entry["dof"], entry["capabilities"])
    verlet = next(entry for entry in geomint.methods() if entry["name"] == "stormer_verlet")
    assert verlet["order"] == 2 and "symplectic" in verlet["flags"]
    providers = {entry["name"]: entry["provider"] for entry in geomint.methods()}
    assert providers["stormer_verlet"] == "geomint"
    assert providers["cvode_bdf"] == "library:SUNDIALS"
    assert [parameter["key"] for parameter in verlet["parameters"]] == ["compensated"]


def test_problem_api_agrees_with_the_cli_series():
    problem = geomint.Problem("kepler")
    assert problem.spec.startswith("kepler:") and problem.dof == 2 and problem.kind == "separable"
    q, p = problem.initial_state()
    assert q.dtype == np.float64 and q.shape == (2,) and p.shape == (2,)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "series.csv")
        done = cli("run", "--problem", problem.spec, "--method", "stormer_verlet", "--dt", "0.01",
                   "--t-end", "0.5", "--timing-repeats", "0", "--series", path)
        assert done.returncode == 0, done.stderr
        expected = geomint.Series.read_csv(path)
    # The energy of the initial state is the series' first energy, to the bit.
    assert problem.energy(q, p) == expected.energy[0]
    result = geomint.run(problem, "stormer_verlet", dt=0.01, t_end=0.5, series_every=1)
    series = result.series
    for name, values in expected.columns.items():
        assert np.array_equal(series.columns[name], values), name
    assert np.array_equal(series.q[-1], result.final_q)
    assert np.array_equal(series.p[-1], result.final_p)
    assert [problem.energy(series.q[i], series.p[i]) for i in range(len(series.t))] == list(
        series.energy)
    invariants = problem.invariants(q, p)
    assert invariants["energy"] == problem.energy(q, p)
    assert "angular_momentum" in invariants
    # kepler has an exact solution: at t = 0 it is the initial state.
    q0, p0 = problem.exact(0.0)
    np.testing.assert_allclose(q0, q, rtol=0, atol=1e-15)
    # ∇V of Kepler's V = −1/|q| is q/|q|³.
    np.testing.assert_allclose(problem.grad_potential(q), q / np.linalg.norm(q) ** 3, rtol=1e-15)


def test_series_every_thins_the_points():
    result = geomint.run("pendulum", "stormer_verlet", dt=0.1, t_end=1.0, series_every=3)
    assert list(result.series.t) == pytest.approx([0.0, 0.3, 0.6, 0.9, 1.0])
    assert result.series.q.shape == (5, 1) and result.series.invariants == {}


def test_bad_input_is_a_value_error_naming_the_parameter():
    with pytest.raises(ValueError, match="theta0"):
        geomint.Problem("pendulum:theta0=oops")
    with pytest.raises(ValueError, match="no_such_method"):
        geomint.run("pendulum", "no_such_method", dt=0.1, t_end=1.0)
    with pytest.raises(ValueError, match="--dt"):
        geomint.run("pendulum", "stormer_verlet", dt=-1.0, t_end=1.0)
    with pytest.raises(ValueError, match="q has 3 entries"):
        geomint.Problem("pendulum").energy(np.zeros(3), np.zeros(1))
    without_exact = geomint.Problem("henon_heiles")
    assert "exact" not in without_exact.capabilities
    with pytest.raises(ValueError, match="exact solution"):
        without_exact.exact(1.0)


def test_numerical_failure_is_a_row():
    # Explicit Euler's energy grows every step: past 1.5·|H₀| the run stops as `diverged`.
    result = geomint.run("pendulum", "explicit_euler", dt=0.5, t_end=100.0, diverge_factor=1.5)
    assert not result.ok and result.status == "diverged"
    assert "relative energy error above 1.5" in result.row["message"]
    assert result.row["t_reached"] < 100.0


def test_order_equals_the_cli_ladder():
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "ladder.csv")
        done = cli("order", "--problem", "pendulum", "--method", "stormer_verlet", "--dt", "0.1",
                   "--t-end", "1", "--levels", "4", "--out", path)
        assert done.returncode == 0, done.stderr
        with open(path, encoding="utf-8") as handle:
            text = handle.read()
    expected = cli_rows(text)
    frame = geomint.order("pendulum", "stormer_verlet", dt=0.1, t_end=1.0, levels=4)
    assert list(frame.columns) == cli_columns(text)
    for (_, row), want in zip(frame.iterrows(), expected):
        got = {key: value for key, value in row.items()
               if not (isinstance(value, float) and math.isnan(value) and key not in want)}
        assert same_cells(got, want)
    assert f"{frame.attrs['fit']['order']:.3f}" == done.stdout.strip()
    # Typed by the harness's column types, not guessed from the text.
    assert str(frame["steps"].dtype) == "int64" and str(frame["dt"].dtype) == "float64"
    assert frame["status"].dtype == object
