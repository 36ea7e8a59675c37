"""geomint from Python: the problem and method registries, problems on numpy arrays, and runs
whose rows equal `geomint run`'s CSV row cell for cell (docs/PYTHON.md)."""

import math
import os
import tempfile

import numpy as np

from . import _geomint
from ._geomint import InputError  # a subclass of ValueError

__all__ = ["problems", "methods", "Problem", "Run", "Series", "run", "order", "InputError"]


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
        self.status = self.row["status"]
        self.final_q = result["final_q"]
        self.final_p = result["final_p"]
        self.series = series

    def __repr__(self):
        return f"<geomint.Run {self.row['problem']} {self.row['method']} status={self.status}>"


def _problem(problem):
    return problem if isinstance(problem, _geomint.Problem) else Problem(problem)


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


def order(problem, method, dt, t_end, levels=6, diverge_factor=None):
    """The convergence order over the ladder dt·2^-k as `geomint order` fits it: a pandas
    DataFrame equal to the CSV `geomint order --out` writes (one row per level), with the fit
    (the order.csv row: order, order_q, order_p, points_used, status, ...) in df.attrs["fit"]."""
    import pandas as pd

    problem = _problem(problem)
    factor = _geomint.default_diverge_factor if diverge_factor is None else float(diverge_factor)
    result = _geomint.order(problem, method, float(dt), int(levels), float(t_end), factor)
    frame = pd.DataFrame(
        [[parse_row(row).get(column, math.nan) for column in result["columns"]]
         for row in result["rows"]],
        columns=result["columns"],
    )
    frame.attrs["fit"] = parse_row(result["summary"])
    frame.attrs["note"] = result["note"]
    return frame
