"""geomint from Python: the problem and method registries, problems on numpy arrays, and runs
whose rows equal `geomint run`'s CSV row cell for cell (docs/PYTHON.md)."""

import math
import os
import tempfile

import numpy as np

from . import _geomint
from ._geomint import InputError  # a subclass of ValueError

__all__ = [
    "problems", "methods", "Problem", "Run", "Series", "run", "order", "InputError",
    "register_method", "check_names", "check", "verify", "sweep", "gate", "read_table", "Tables", "frame", "score",
]


def methods():
    """The method registry as `geomint list methods` shows it: one dict per method with name,
    summary, order, flags, family, parameters (key, default, help) and builtin."""
    return _geomint.methods()


def problems():
    """The problem registry as `geomint list problems` shows it: one dict per problem with
    name, summary, dof, kind, capabilities (of the default instance), parameters and builtin."""
    return _geomint.problems()


class Problem(_geomint.Problem):
    """A problem from its spec (`pendulum:theta0=1.5`): ValueError naming the bad name, key or
    value. Arrays in and out are numpy float64 vectors of length dof."""

    def __repr__(self):
        return f"geomint.Problem({self.spec!r})"


def _cell(text):
    """A CSV cell as the row dict holds it: a number when the text is one, else the text."""
    try:
        return float(text)
    except ValueError:
        return text


def parse_row(cells):
    """{column: cell text} -> {column: float or str}, the parsing every row of this package uses
    (and the tests apply to the CLI's CSV)."""
    return {column: _cell(text) for column, text in cells.items()}


class Series:
    """A run's time series: t, energy (None for first-order problems), q and p (rows = points,
    columns = dof; None when the series leaves the state out) and `columns`, every column of the
    series CSV by name (momenta, problem extras, constraint residuals, ...)."""

    def __init__(self, columns):
        self.columns = columns
        self.t = columns["t"]
        self.energy = columns.get("energy")
        self.q = self._stack(columns, "q") if "q_0" in columns else self._stack(columns, "y")
        self.p = self._stack(columns, "p")
        state = ("q_", "p_", "y_")
        # Conserved or monitored quantities: momenta, problem extras, constraint residuals.
        self.invariants = {
            name: values
            for name, values in columns.items()
            if name not in ("t", "energy")
            and not (name.startswith(state) and name.split("_", 1)[1].isdigit())
        }

    @staticmethod
    def _stack(columns, prefix):
        names = []
        while f"{prefix}_{len(names)}" in columns:
            names.append(f"{prefix}_{len(names)}")
        if not names:
            return None
        return np.column_stack([columns[name] for name in names])

    @classmethod
    def read_csv(cls, path):
        """Reads a series CSV written by `geomint run --series` (provenance lines skipped)."""
        with open(path, encoding="utf-8") as handle:
            lines = [line for line in handle if not line.startswith("#")]
        header = lines[0].strip().split(",")
        data = np.array(
            [[float(cell) for cell in line.strip().split(",")] for line in lines[1:]],
            dtype=np.float64,
        ).reshape(len(lines) - 1, len(header))
        return cls({name: data[:, i].copy() for i, name in enumerate(header)})


class Run:
    """One run's result: `row` ({column: float or str}, the cells of `geomint run`'s CSV row),
    `columns` (their CSV order), `status`, `ok`, `final_q`, `final_p`, and `series` (a Series,
    or None when series_every was not given)."""

    def __init__(self, result, series=None):
        self.columns = list(result["columns"])
        # In the CSV's column order, as the program writes the row.
        self.cells = {column: result["row"][column] for column in self.columns}
        self.row = parse_row(self.cells)
        self.ok = bool(result["ok"])
        # The text: a row dict parses the status "nan" (a non-finite state) as a float.
        self.status = self.cells["status"]
        self.final_q = result["final_q"]
        self.final_p = result["final_p"]
        self.series = series

    def __repr__(self):
        return f"<geomint.Run {self.row['problem']} {self.row['method']} status={self.status}>"


def _problem(problem):
    return problem if isinstance(problem, _geomint.Problem) else Problem(problem)


def read_table(path):
    """A table CSV the harness wrote, as pandas reads it with comment="#" and
    float_precision="round_trip" (the exact doubles: pandas' default parser can round the last
    of 17 digits; docs/PYTHON.md), but only whole lines starting with # are provenance: they go
    to df.attrs["provenance"]."""
    import io

    import pandas as pd

    with open(path, encoding="utf-8") as handle:
        lines = handle.readlines()
    provenance = {}
    for line in lines:
        if line.startswith("# ") and ":" in line:
            key, value = line[2:].split(":", 1)
            provenance[key.strip()] = value.strip()
    table = pd.read_csv(io.StringIO("".join(line for line in lines if not line.startswith("#"))),
                        float_precision="round_trip")
    table.attrs["provenance"] = provenance
    return table


def frame(table):
    """A result table in memory (a sweep's) as a pandas DataFrame, its columns typed by the
    harness's column types: real -> float64 (NaN where empty or no number, as "n/a"), integer ->
    int64 (float64 with NaN when a cell is empty), text -> object (NaN where empty); the provenance
    lines in df.attrs["provenance"]."""
    import pandas as pd

    arrays = table.arrays()
    columns = {}
    for name, kind in zip(table.columns, table.types):
        values = arrays[name]
        if kind == "text":
            # Empty cells are NaN, as pandas reads an empty CSV cell.
            values = np.array([math.nan if cell is None else cell for cell in values],
                              dtype=object)
        columns[name] = values
    result = pd.DataFrame(columns, columns=table.columns, index=pd.RangeIndex(table.rows))
    provenance = {}
    for key, value in table.provenance:
        provenance[key.strip()] = value.strip()  # as read_table reads a file's lines
    result.attrs["provenance"] = provenance
    return result


class Tables(dict):
    """A sweep's tables by name (summary, order, order_points, stability: those the scene has),
    each a pandas DataFrame built from the tables the harness returns in memory; `failed` is the
    number of failed runs (rows, not errors), `folder` where the CSVs were written (None when
    out was not given: nothing was written). csv(name) is the text of that table's CSV, and
    geomint.gate(gates, tables) gates the tables without reading a file."""

    def __init__(self, tables, failed, folder, raw=()):
        super().__init__(tables)
        self.failed = failed
        self.folder = folder
        self._raw = list(raw)

    def csv(self, name):
        """The CSV text of table `name`, byte for byte the file `geomint sweep` writes."""
        for table in self._raw:
            if table.name == name:
                return table.to_csv()
        raise KeyError(name)

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


SWEEP_TABLES = ("summary", "order", "order_points", "stability")


def sweep(scene, quick=False, out=None, jobs=1, timing=True, progress=False):
    """Runs a scene (its scene.toml, or the folder holding it) as `geomint sweep SCENE` does,
    with --quick, --jobs and --no-timing (timing=False), and returns its tables as a Tables dict
    of DataFrames, built from the tables in memory (no CSV is read back). `out` is the output
    folder (as --out): the CSVs, table.md and series are written there from the same tables.
    Without it nothing is written (no series files either)."""
    scene = os.fspath(scene)
    if os.path.isdir(scene):
        scene = os.path.join(scene, "scene.toml")
    command = f"python: geomint.sweep({scene!r}, quick={bool(quick)!r}, timing={bool(timing)!r})"
    folder = "" if out is None else os.fspath(out)
    result = _geomint.sweep(scene, bool(quick), folder, int(jobs), bool(timing), bool(progress),
                            command)
    tables = {table.name: frame(table) for table in result["tables"]}
    return Tables(tables, result["failed"], folder or None, result["tables"])


def gate(gates, results=None):
    """The verdicts of `geomint gate GATES RESULTS...` (or of the gates on the Tables a sweep
    returned, in memory): a DataFrame with one row per gate that
    applies to the results (gate, scene, table, column, file, passed, rows_checked, lines: the
    checked rows' verdicts), and df.attrs["passed"] (every gate passed: the program's exit 0)
    and df.attrs["not_applicable"] (the other gates' names). `gates` is a gates file or a scene
    folder (its gates.toml, and by default its results); `results` a folder, a CSV or a list.
    ValueError, as the program's exit 2, when no gate applies or a file is malformed."""
    import pandas as pd

    gates = os.fspath(gates)
    if os.path.isdir(gates):
        results = [gates] if results is None else results
        gates = os.path.join(gates, "gates.toml")
    if results is None:
        raise ValueError(f"gate: give the results to check after the gates file '{gates}'")
    if isinstance(results, Tables):
        # A sweep's tables in memory, named as the files of its folder would be.
        verdicts = _geomint.gate_tables(gates, results._raw, results.folder or "(in memory)")
    else:
        if isinstance(results, (str, os.PathLike)):
            results = [results]
        verdicts = _geomint.gate(gates, [os.fspath(path) for path in results])
    applied = [verdict for verdict in verdicts if verdict["applicable"]]
    if not applied:
        raise InputError(f"gate: none of the {len(verdicts)} gate(s) in '{gates}' applies to the "
                         "results given (their scenes and variants differ); nothing was checked")
    frame = pd.DataFrame(
        [{key: value for key, value in verdict.items() if key != "applicable"}
         for verdict in applied],
        columns=["gate", "scene", "table", "column", "file", "passed", "rows_checked", "lines"])
    frame.attrs["passed"] = bool(frame["passed"].all())
    frame.attrs["not_applicable"] = [v["gate"] for v in verdicts if not v["applicable"]]
    return frame


def run(
    problem,
    method,
    dt=None,
    t_end=None,
    metrics=(),
    series_every=None,
    series_state=False,
    series_section=None,
    timing_repeats=0,
    timing_budget_s=None,
    diverge_factor=None,
    max_steps=None,
    wall_budget_s=0.0,
    reference_dir="results/references",
):
    """Runs `method` on `problem` (a Problem or a spec string) as `geomint run` does; dt and
    t_end default to the problem's. Bad input raises ValueError (every message at once);
    a numerical failure is a Run whose status says why."""
    problem = _problem(problem)
    config = _geomint.RunConfig()
    config.dt = problem.default_dt if dt is None else float(dt)
    config.t_end = problem.default_t_end if t_end is None else float(t_end)
    config.extra_metrics = list(metrics)
    config.timing_repeats = int(timing_repeats)
    if timing_budget_s is not None:
        config.timing_budget_s = float(timing_budget_s)
    if diverge_factor is not None:
        config.diverge_factor = float(diverge_factor)
    if max_steps is not None:
        config.max_steps = int(max_steps)
    config.wall_budget_s = float(wall_budget_s)
    config.reference_dir = os.fspath(reference_dir)
    config.command_line = f"python: geomint.run({problem.spec!r}, {method!r})"
    want_series = series_every is not None or series_section is not None
    if not want_series:
        return Run(_geomint.run(problem, method, config))
    # First step: the series goes through the harness's file writer into a temporary folder.
    config.series_every = 1 if series_every is None else int(series_every)
    config.series_state = bool(series_state)
    if series_section is not None:
        config.series_section = int(series_section)
    with tempfile.TemporaryDirectory(prefix="geomint-series-") as folder:
        config.series_path = os.path.join(folder, "series.csv")
        result = _geomint.run(problem, method, config)
        series = Series.read_csv(config.series_path) if os.path.exists(config.series_path) else None
    return Run(result, series)


def score(problem, t=None, q=None, p=None, *, v=None, path=None, metrics=(),
          start_tol=1e-9, reference_dir="results/references"):
    """The metrics of a trajectory another program computed, as `geomint score --problem SPEC
    FILE` gives them (docs/USAGE.md "Scoring a trajectory from another program"): a Run whose row
    has the columns of `geomint run`'s row (method = the file, or "arrays"). Either arrays t (n),
    q (n x dof) and p or v (n x dof; v = velocities, turned into momenta by the problem), or
    `path` (a CSV with a header or a .npy, as the program reads it). The first row must be the
    problem's initial state within start_tol; a bad input is a ValueError naming the first bad row."""
    problem = _problem(problem)
    metrics = list(metrics)
    if path is not None:
        if t is not None or q is not None or p is not None or v is not None:
            raise ValueError("score: give either path or the arrays t, q, p (or v), not both")
        result = _geomint.score(problem, os.fspath(path), float(start_tol), False, metrics, "",
                                os.fspath(reference_dir))
        return Run(result)
    if t is None or q is None or (p is None) == (v is None):
        raise ValueError("score: give t, q and one of p or v (or path)")
    t = np.asarray(t, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    second = np.asarray(p if p is not None else v, dtype=np.float64)
    if q.ndim == 1:
        q, second = q[:, None], second[:, None]
    if t.ndim != 1 or q.shape != second.shape or q.shape[0] != t.shape[0]:
        raise ValueError(f"score: t must have shape (n,) and q, {'p' if p is not None else 'v'} "
                         f"shape (n, dof); got {t.shape}, {q.shape}, {second.shape}")
    table = np.ascontiguousarray(np.column_stack([t, q, second]))
    with tempfile.TemporaryDirectory(prefix="geomint-score-") as folder:
        file = os.path.join(folder, "trajectory.npy")
        np.save(file, table)
        result = _geomint.score(problem, file, float(start_tol), v is not None, metrics,
                                "arrays", os.fspath(reference_dir))
    return Run(result)


def order(problem, method, dt, t_end, levels=6, diverge_factor=None):
    """The convergence order over the ladder dt·2^-k as `geomint order` fits it: a pandas
    DataFrame equal to the CSV `geomint order --out` writes (one row per level; its columns typed
    as geomint.frame types them), with the fit
    (the order.csv row: order, order_q, order_p, points_used, status, ...) in df.attrs["fit"]."""
    problem = _problem(problem)
    factor = _geomint.default_diverge_factor if diverge_factor is None else float(diverge_factor)
    result = _geomint.order(problem, method, float(dt), int(levels), float(t_end), factor)
    ladder = frame(result["table"])  # typed columns, from the table in memory
    ladder.attrs["fit"] = parse_row(result["summary"])
    ladder.attrs["note"] = result["note"]
    return ladder


def register_method(method, step=None, *, name=None, order=None, implicit=False,
                    symplectic=False, symmetric=False, variational=False,
                    energy_preserving=False, flags=None, summary=None, reference=""):
    """Registers an integrator written in Python; it then runs in run(), order(), sweep() and the
    verify kit (check(), verify()) like a built-in method, with provider "user".

    Either register_method(name, step, order=2, symplectic=True, ...) with a function
    step(problem, q, p, t, h) -> (q, p), or register_method(obj) with an object or a class that
    has a step method of that signature and `name`, `order` (and optionally `flags`, a list of
    flag names, and `summary`) as attributes; a class is instantiated once per run, and an
    optional reset(problem, q, p, t, h) is called before the first step. Keywords override the
    attributes. Declarable flags: explicit (the default) or implicit, symplectic, symmetric,
    variational, energy_preserving. The step sees problem.grad_potential(q), .potential(q),
    .mass(), .inverse_mass() and the rest of geomint.Problem, so Python methods run on
    conservative separable problems. Registering a name again replaces the Python method; a
    built-in's name is a ValueError. Returns the name."""
    if isinstance(method, str):
        if step is None:
            raise TypeError("register_method(name, step, ...): step is missing")
        name = method if name is None else name
        target = step
    elif step is not None:
        raise TypeError("register_method(obj) takes no step: obj.step is the step")
    else:
        target = method
    factory = function = None
    if isinstance(target, type):
        if not callable(getattr(target, "step", None)):
            raise TypeError(f"class {target.__name__} has no step method")
        factory = target
    elif callable(getattr(target, "step", None)):
        function = target.step
    elif callable(target):
        function = target
    else:
        raise TypeError(f"{target!r} is neither a function nor an object with a step method")
    name = name if name is not None else getattr(target, "name", None)
    order = order if order is not None else getattr(target, "order", None)
    if not isinstance(name, str):
        raise ValueError("register_method: a name is required (argument or attribute `name`)")
    if order is None:
        raise ValueError(f"register_method: method '{name}' needs its order (argument or "
                         "attribute `order`)")
    declared = flags if flags is not None else getattr(target, "flags", ())
    declared = [declared] if isinstance(declared, str) else list(declared)
    if "implicit" not in declared and "explicit" not in declared:
        declared.append("implicit" if implicit else "explicit")
    keywords = {"symplectic": symplectic, "symmetric": symmetric, "variational": variational,
                "energy_preserving": energy_preserving}
    declared += [flag for flag, given in keywords.items() if given and flag not in declared]
    if summary is None:
        summary = getattr(target, "summary", None) or (
            (target.__doc__ or "").strip().split("\n")[0] or f"Python method {name}")
    _geomint.register_method(name, function, factory, int(order), declared, summary, reference)
    return name


def check_names():
    """The verify kit's checks in the order verify() runs them (docs/VERIFY.md)."""
    return list(_geomint.check_names())


def check(method, name, constrained_problem="cartesian_pendulum"):
    """One check of the verify kit on `method` (a spec, a Python method included): a dict with
    check, method, problem, applies, passed, measured, bound, detail and text (one line, as the
    C++ kit's describe() prints it). applies is False (and passed True) when the method's flags
    do not call for the check."""
    return dict(_geomint.check(method, name, constrained_problem))


def verify(method, constrained_problem="cartesian_pendulum"):
    """Every check of check_names() on `method`: a pandas DataFrame, one row per check, the
    verdicts a built-in method gets from the C++ verify kit (GEOMINT_VERIFY_METHOD)."""
    import pandas as pd

    rows = [check(method, name, constrained_problem) for name in check_names()]
    return pd.DataFrame(rows, columns=["check", "method", "problem", "applies", "passed",
                                       "measured", "bound", "detail", "text"])
