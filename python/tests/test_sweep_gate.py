"""geomint.sweep and geomint.gate against the geomint program (ctest python_sweep, docs/PYTHON.md):
a quick sweep's DataFrames equal the CSVs `geomint sweep` writes read with pandas, a scene runs a
Python method beside the built-ins, and the gate verdicts are the program's."""

import csv
import io
import json
import os
import shutil
import subprocess
import tempfile

import pandas as pd
import pytest

import geomint

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
GEOMINT = os.environ.get("GEOMINT_EXE", os.path.join(ROOT, "build", "geomint"))
SCENE = os.path.join(ROOT, "results", "order_basic")


def cli(*args):
    return subprocess.run([GEOMINT, *args], capture_output=True, text=True, check=False)


@pytest.fixture(scope="module")
def cli_folder():
    with tempfile.TemporaryDirectory(prefix="geomint-cli-sweep-") as folder:
        done = cli("sweep", os.path.join(SCENE, "scene.toml"), "--quick", "--no-timing",
                   "--quiet", "--out", folder)
        assert done.returncode == 0, done.stderr
        yield folder


# The dtype of each column type of the harness (geomint.frame): integer columns with an empty
# cell are float64, as pandas holds them.
DTYPES = {"real": ("float64",), "integer": ("int64", "float64"), "text": ("object",)}


def test_quick_sweep_frames_equal_the_cli_csvs(cli_folder):
    tables = geomint.sweep(SCENE, quick=True, timing=False)
    written = sorted(name[:-4] for name in os.listdir(cli_folder) if name.endswith(".csv"))
    assert sorted(tables) == written == ["order", "order_points", "summary"]
    assert tables.failed == 0 and tables.folder is None
    for name, frame in tables.items():
        # round_trip: pandas' default float parser can round the last of 17 digits, where the
        # frame holds the harness's doubles.
        expected = pd.read_csv(os.path.join(cli_folder, name + ".csv"), comment="#",
                               float_precision="round_trip")
        # The values are the CSV's exactly; the dtypes are the column types', where pandas guesses
        # from the text (a real column whose cells all look like integers reads as int64).
        pd.testing.assert_frame_equal(frame, expected, check_exact=True, check_dtype=False,
                                      obj=name)
        raw = next(table for table in tables._raw if table.name == name)
        for column, kind in zip(raw.columns, raw.types):
            assert str(frame[column].dtype) in DTYPES[kind], (name, column, kind)
    provenance = tables.summary.attrs["provenance"]
    assert provenance["scene"] == "order_basic" and provenance["variant"] == "quick"
    # Typed columns: the counters are integers, the errors reals, the status text.
    assert str(tables.summary["steps"].dtype) == "int64"
    assert str(tables.summary["energy_err_max"].dtype) == "float64"
    assert str(tables.summary["t_end"].dtype) == "float64"
    assert tables.summary["status"].tolist() == ["ok"] * len(tables.summary)


def test_sweep_without_out_writes_nothing_and_with_out_writes_its_tables(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    geomint.sweep(SCENE, quick=True, timing=False)
    assert os.listdir(tmp_path) == []
    out = tmp_path / "out"
    tables = geomint.sweep(SCENE, quick=True, timing=False, out=out)
    assert tables.folder == str(out)
    for name, frame in tables.items():
        with open(out / (name + ".csv"), encoding="utf-8") as handle:
            assert tables.csv(name) == handle.read(), name
        # The frames built in memory equal the written files read back with pandas.
        pd.testing.assert_frame_equal(frame, geomint.read_table(out / (name + ".csv")),
                                      check_exact=True, check_dtype=False, obj=name)


def test_gate_on_the_tables_in_memory_equals_the_gate_on_their_files(tmp_path):
    tables = geomint.sweep(SCENE, quick=True, timing=False, out=tmp_path / "quick")
    in_memory = geomint.gate(SCENE, tables)
    from_files = geomint.gate(SCENE, tmp_path / "quick")
    pd.testing.assert_frame_equal(in_memory, from_files)
    assert in_memory.attrs == from_files.attrs
    unwritten = geomint.gate(SCENE, geomint.sweep(SCENE, quick=True, timing=False))
    assert list(unwritten["passed"]) == list(from_files["passed"])
    assert unwritten.attrs["passed"]


def test_gate_verdicts_are_the_programs(cli_folder):
    verdicts = geomint.gate(SCENE, cli_folder)
    done = cli("gate", SCENE, cli_folder, "--format", "json")
    expected = {row["gate"]: row["passed"] for row in json.loads(done.stdout)}
    assert dict(zip(verdicts["gate"], verdicts["passed"])) == expected
    assert verdicts.attrs["passed"] == (done.returncode == 0)


def test_gate_flags_a_table_that_leaves_its_band(cli_folder, tmp_path):
    # The gates of order_basic on a summary where Störmer–Verlet damps the chain's modes.
    with open(os.path.join(cli_folder, "summary.csv"), encoding="utf-8") as handle:
        lines = handle.read().splitlines(keepends=True)
    header_at = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    column = next(csv.reader([lines[header_at]])).index("mode_damping_max")
    for i in range(header_at + 1, len(lines)):
        cells = next(csv.reader([lines[i]]))
        if cells[2] == "stormer_verlet" and cells[1].startswith("spring_chain"):
            cells[column] = "0.5"
            text = io.StringIO()
            csv.writer(text, lineterminator="\n").writerow(cells)
            lines[i] = text.getvalue()
    damped = tmp_path / "quick"
    shutil.copytree(cli_folder, damped)
    (damped / "summary.csv").write_text("".join(lines), encoding="utf-8")
    verdicts = geomint.gate(os.path.join(SCENE, "gates.toml"), str(damped))
    done = cli("gate", os.path.join(SCENE, "gates.toml"), str(damped), "--format", "json")
    assert not verdicts.attrs["passed"] and done.returncode == 1, done.stderr
    expected = {row["gate"]: row["passed"] for row in json.loads(done.stdout)}
    assert dict(zip(verdicts["gate"], verdicts["passed"])) == expected
    failed = verdicts[~verdicts["passed"]]
    assert list(failed["gate"]) == [
        "order_basic modes: Störmer–Verlet keeps every mode's amplitude (|rho - 1| <= 1e-12) on "
        "the linear chain"]


def test_gate_input_errors_are_value_errors(tmp_path):
    with pytest.raises(ValueError, match="give the results"):
        geomint.gate(os.path.join(SCENE, "gates.toml"))
    with pytest.raises(ValueError):
        geomint.gate(tmp_path / "missing.toml", SCENE)


def verlet(problem, q, p, t, h):
    p = p - 0.5 * h * problem.grad_potential(q)
    q = q + h * problem.inverse_mass() * p
    return q, p - 0.5 * h * problem.grad_potential(q)


def test_a_scene_runs_a_python_method_on_worker_threads(tmp_path):
    geomint.register_method("py_sweep_verlet", verlet, order=2, symplectic=True, symmetric=True)
    scene = tmp_path / "py_scene" / "scene.toml"
    scene.parent.mkdir()
    scene.write_text('''title = "Python Verlet beside the built-in"
[[runs]]
label = "kepler"
problems = ["kepler:e=0.6", "pendulum:theta0=1.5"]
methods = ["stormer_verlet", "py_sweep_verlet"]
dt = 0.01
t_end = 2.0

[[orders]]
label = "ladder"
problems = ["pendulum:theta0=1.5"]
methods = ["stormer_verlet", "py_sweep_verlet"]
dt0 = 0.1
levels = 5
t_end = 2.0
''')
    tables = geomint.sweep(scene, jobs=2, timing=False, out=tmp_path / "out")
    assert tables.failed == 0 and tables.folder == str(tmp_path / "out")
    summary = tables.summary.set_index(["problem", "method"])
    for problem in summary.index.get_level_values(0).unique():
        ours, builtin = summary.loc[(problem, "py_sweep_verlet")], summary.loc[(problem,
                                                                              "stormer_verlet")]
        assert ours["energy_err_max"] == builtin["energy_err_max"], problem
    order = tables.order.set_index("method")
    assert order.loc["py_sweep_verlet", "order"] == order.loc["stormer_verlet", "order"]
