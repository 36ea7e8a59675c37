// The compiled half of the Python package geomint (docs/PYTHON.md): the registries, the Problem
// interface on numpy arrays, and run_one / order_study returning the CLI's formatted row cells, so
// that python/geomint/__init__.py parses exactly the text `geomint run` would have written.
#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "harness/gate.hpp"
#include "harness/order.hpp"
#include "harness/paths.hpp"
#include "harness/record.hpp"
#include "harness/run.hpp"
#include "harness/run_spec.hpp"
#include "harness/scene.hpp"
#include "harness/score.hpp"
#include "harness/shard.hpp"
#include "harness/sweep.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"
#include "python/interrupt_scope.hpp"
#include "python/py_problem.hpp"
#include "python/python_method.hpp"

namespace geomint {
namespace {

py::list parameter_docs(const Params& params) {
  py::list parameters;
  for (const ParamDoc& doc : params.docs()) {
    py::dict parameter;
    parameter["key"] = doc.key;
    parameter["default"] = doc.default_value;
    parameter["help"] = doc.help;
    parameters.append(parameter);
  }
  return parameters;
}

// The data `geomint list methods` prints (harness/cli/list.cpp), read from the same sources: each
// entry's default configuration.
py::list method_entries() {
  py::list entries;
  for (const IntegratorEntry& entry : integrator_registry()) {
    Params params(Spec{entry.name, {}}, entry.name);
    const MethodInfo info = entry.factory(params)->info();
    py::dict item;
    item["name"] = entry.name;
    item["summary"] = python_method_summary(entry.name, entry.summary);
    item["order"] = info.order;
    item["flags"] = flag_names(info.flags);
    item["provider"] = entry.provider.label();
    item["family"] = method_family(info, entry.provider);
    item["parameters"] = parameter_docs(params);
    item["builtin"] = entry.builtin;
    entries.append(item);
  }
  return entries;
}

// The data `geomint list problems` prints: each entry's default instance.
py::list problem_entries() {
  py::list entries;
  for (const ProblemEntry& entry : problem_registry()) {
    Params params(Spec{entry.name, {}}, entry.name);
    const auto problem = entry.factory(params);
    py::dict item;
    item["name"] = entry.name;
    item["summary"] = entry.summary;
    item["dof"] = problem->dof();
    item["kind"] = std::string(kind_name(problem->kind()));
    item["capabilities"] = capability_names(problem->capabilities());
    item["parameters"] = parameter_docs(params);
    item["builtin"] = entry.builtin;
    entries.append(item);
  }
  return entries;
}

// A record's cells as `geomint run` writes them (to_row: the one formatter of every table).
py::dict cells(const RunRecord& record) {
  py::dict row;
  for (const auto& [column, cell] : to_row(record)) row[py::str(column)] = cell;
  return row;
}

py::dict run(const PyProblem& problem, const std::string& method_spec, const RunConfig& config) {
  RunSpec spec{problem.shared(), MethodFactory(method_spec), config};
  RunResult result;
  InterruptScope interrupt;
  {
    // A run may take minutes; other Python threads go on meanwhile.
    py::gil_scoped_release release;
    result = run_one(spec);
  }
  interrupt.raise_if_interrupted();
  py::dict out;
  out["row"] = cells(result.record);
  out["columns"] = record_columns({result.record});
  out["ok"] = result.ok;
  out["final_q"] = result.final_state.q;
  out["final_p"] = result.final_state.p;
  return out;
}

py::dict order(const PyProblem& problem, const std::string& method_spec, double dt0, int levels,
               double t_end, double diverge_factor) {
  const MethodFactory method(method_spec);
  OrderStudy study;
  InterruptScope interrupt;
  {
    py::gil_scoped_release release;
    study = order_study(problem.shared(), method, dt0, levels, t_end, diverge_factor);
  }
  interrupt.raise_if_interrupted();
  py::dict out;
  // The ladder as `geomint order --out` writes it, in memory (geomint.frame types its columns).
  out["table"] = ladder_table(study, {});
  py::dict summary;
  for (const auto& [column, cell] : to_row(study.record)) summary[py::str(column)] = cell;
  out["summary"] = summary;
  out["summary_columns"] = columns_of(order_schema(), std::vector<OrderRecord>{study.record});
  out["note"] = study.fit.note;
  return out;
}

// `geomint score --problem SPEC FILE`'s row for one trajectory file (read and validated by the
// program's reader: InputError naming the first bad row); `label` replaces the path in `method`
// when not empty (a temporary file written from arrays).
py::dict score(const PyProblem& problem, const std::string& path, double start_tol, bool velocities,
               const std::vector<std::string>& metrics, const std::string& label,
               const std::string& reference_dir) {
  std::vector<std::string> errors = score_metric_errors(metrics);
  if (!(start_tol >= 0 && std::isfinite(start_tol))) {
    errors.push_back(fmt::format("start_tol must be a finite number >= 0 (got {})", start_tol));
  }
  throw_input_errors(errors);
  const Trajectory trajectory = read_trajectory(path, problem.get(), start_tol, velocities);
  ScoreConfig config;
  config.reference_dir = reference_dir;
  config.extra_metrics = metrics;
  RunRecord record;
  {
    py::gil_scoped_release release;
    record = score_trajectory(problem.get(), trajectory, config);
  }
  if (!label.empty()) record.method = label;
  py::dict out;
  out["row"] = cells(record);
  out["columns"] = record_columns({record});
  out["ok"] = record.status == "ok";
  out["final_q"] = trajectory.states.back().q;
  out["final_p"] = trajectory.states.back().p;
  return out;
}

// A table's columns as numpy arrays by name, typed by the column (docs/PYTHON.md "sweep and
// gate"): real → float64 (NaN where a cell is empty or holds no number, order_multiplier's
// "n/a"), integer → int64 (float64 with NaN when a cell is empty, as pandas holds it), text → a
// list of str (None where empty).
py::dict table_arrays(const ResultTable& table) {
  py::dict arrays;
  const size_t rows = table.rows.size();
  for (const TableColumn& column : table.columns) {
    if (column.type == ColumnType::kText) {
      py::list cells;
      for (const Row& row : table.rows) {
        const auto cell = row.find(column.name);
        cells.append(cell == row.end() || cell->second.empty() ? py::object(py::none())
                                                               : py::object(py::str(cell->second)));
      }
      arrays[py::str(column.name)] = cells;
      continue;
    }
    std::vector<double> values(rows);
    bool complete = true;
    for (size_t r = 0; r < rows; ++r) {
      const auto value = table.number(r, column.name);
      complete = complete && value.has_value();
      values[r] = value.value_or(std::nan(""));
    }
    if (column.type == ColumnType::kInteger && complete) {
      py::array_t<long> integers(static_cast<py::ssize_t>(rows));
      for (size_t r = 0; r < rows; ++r) integers.mutable_at(r) = static_cast<long>(values[r]);
      arrays[py::str(column.name)] = integers;
    } else {
      arrays[py::str(column.name)] = py::array_t<double>(values.size(), values.data());
    }
  }
  return arrays;
}

// The in-memory tables of a sweep (harness/sweep.hpp SweepResult) and its failed runs.
py::dict sweep_result(SweepResult result) {
  py::dict out;
  out["failed"] = result.failed;
  out["tables"] = std::move(result.tables);
  return out;
}

// `geomint sweep SCENE [--quick] --out OUT [--no-timing]`, as harness/cli/sweep.cpp sets it up
// (the scene's name is the folder holding scene.toml, whatever the output folder): the failed
// runs and the tables in memory, also written into `out_dir` when it is not empty.
py::dict sweep_scene(const std::string& scene_path, bool quick, const std::string& out_dir,
                     int jobs, bool timing, bool progress, const std::string& command_line) {
  const Scene scene = load_scene(scene_path, quick);
  SweepOptions options;
  options.jobs = jobs;
  options.progress = progress;
  options.command_line = command_line;
  options.out_dir = out_dir;
  options.scene_name = std::filesystem::absolute(scene_path).parent_path().filename().string();
  options.variant = quick ? "quick" : "full";
  options.scene_hash = scene_content_hash(scene_path, quick);
  options.timing = timing;
  if (!out_dir.empty()) check_output_dir(options.out_dir, "out");
  SweepResult result;
  InterruptScope interrupt;
  {
    py::gil_scoped_release release;
    result = sweep(scene, options);
  }
  interrupt.raise_if_interrupted();
  return sweep_result(std::move(result));
}

py::list verdicts_of(const std::vector<Gate>& gates, const std::vector<ResultFile>& files) {
  py::list verdicts;
  for (const GateOutcome& outcome : check_gates(gates, files)) {
    py::dict verdict;
    verdict["gate"] = outcome.gate->name;
    verdict["scene"] = outcome.gate->scene;
    verdict["table"] = outcome.gate->table;
    verdict["column"] = outcome.gate->column;
    verdict["file"] = outcome.gate->file;
    verdict["applicable"] = outcome.applicable;
    verdict["passed"] = outcome.passed;
    verdict["rows_checked"] = outcome.rows_checked;
    verdict["lines"] = outcome.lines;
    verdicts.append(verdict);
  }
  return verdicts;
}

// `geomint gate GATES RESULTS...`'s verdicts, one dict per gate (applicable or not).
py::list gate(const std::string& gates_path, const std::vector<std::string>& results) {
  const std::vector<Gate> gates = load_gates(gates_path);
  return verdicts_of(gates, load_result_files(results));
}

// The same verdicts on a sweep's tables in memory, named as if read from `folder`.
py::list gate_tables(const std::string& gates_path, const std::vector<ResultTable>& tables,
                     const std::string& folder) {
  const std::vector<Gate> gates = load_gates(gates_path);
  return verdicts_of(gates, result_files(tables, folder));
}

}  // namespace
}  // namespace geomint

PYBIND11_MODULE(_geomint, module) {
  using namespace geomint;
  module.doc() = "geomint's C++ core (use the package geomint, docs/PYTHON.md)";
  py::register_exception<InputError>(module, "InputError", PyExc_ValueError);

  module.def("methods", &method_entries);
  module.def("problems", &problem_entries);

  py::class_<PyProblem>(module, "Problem")
      .def(py::init<const std::string&>(), py::arg("spec"))
      .def_property_readonly("spec", [](const PyProblem& p) { return p.get().spec(); })
      .def_property_readonly("name", [](const PyProblem& p) { return p.get().name(); })
      .def_property_readonly("dof", [](const PyProblem& p) { return p.get().dof(); })
      .def_property_readonly(
          "kind", [](const PyProblem& p) { return std::string(kind_name(p.get().kind())); })
      .def_property_readonly(
          "capabilities",
          [](const PyProblem& p) { return capability_names(p.get().capabilities()); })
      .def_property_readonly("default_dt", [](const PyProblem& p) { return p.get().default_dt(); })
      .def_property_readonly("default_t_end",
                             [](const PyProblem& p) { return p.get().default_t_end(); })
      .def("initial_state", &PyProblem::initial_state)
      .def("exact", &PyProblem::exact, py::arg("t"))
      .def("energy", &PyProblem::energy, py::arg("q"), py::arg("p"))
      .def("grad_potential", &PyProblem::grad_potential, py::arg("q"))
      .def("potential", &PyProblem::potential, py::arg("q"))
      .def("mass", &PyProblem::mass)
      .def("inverse_mass", &PyProblem::inverse_mass)
      .def("invariants", &PyProblem::invariants, py::arg("q"), py::arg("p"))
      .def("period", &PyProblem::period);

  // A result table in memory (harness/table.hpp ResultTable): typed columns, cells as the CSV
  // writes them; geomint.sweep turns it into a DataFrame.
  py::class_<ResultTable>(module, "ResultTable")
      .def_readonly("name", &ResultTable::name)
      .def_readonly("provenance", &ResultTable::provenance)
      .def_property_readonly("columns", &ResultTable::column_names)
      .def_property_readonly("types",
                             [](const ResultTable& table) {
                               std::vector<std::string> types;
                               for (const auto& column : table.columns) {
                                 types.emplace_back(column_type_name(column.type));
                               }
                               return types;
                             })
      .def_property_readonly("rows", [](const ResultTable& table) { return table.rows.size(); })
      .def("arrays", &table_arrays)
      .def("to_csv", [](const ResultTable& table) { return to_csv(table); });

  py::class_<RunConfig>(module, "RunConfig")
      .def(py::init<>())
      .def_readwrite("dt", &RunConfig::dt)
      .def_readwrite("t_end", &RunConfig::t_end)
      .def_readwrite("series_path", &RunConfig::series_path)
      .def_readwrite("series_every", &RunConfig::series_every)
      .def_readwrite("series_state", &RunConfig::series_state)
      .def_readwrite("series_section", &RunConfig::series_section)
      .def_readwrite("timing_repeats", &RunConfig::timing_repeats)
      .def_readwrite("timing_budget_s", &RunConfig::timing_budget_s)
      .def_readwrite("diverge_factor", &RunConfig::diverge_factor)
      .def_readwrite("wall_budget_s", &RunConfig::wall_budget_s)
      .def_readwrite("max_steps", &RunConfig::max_steps)
      .def_readwrite("command_line", &RunConfig::command_line)
      .def_readwrite("reference_dir", &RunConfig::reference_dir)
      .def_readwrite("extra_metrics", &RunConfig::extra_metrics);

  module.def("run", &run, py::arg("problem"), py::arg("method"), py::arg("config"));
  module.def("order", &order, py::arg("problem"), py::arg("method"), py::arg("dt0"),
             py::arg("levels"), py::arg("t_end"), py::arg("diverge_factor"));
  module.attr("default_diverge_factor") = kDefaultDivergeFactor;
  module.attr("default_max_steps") = kDefaultMaxSteps;
  module.def("sweep", &sweep_scene, py::arg("scene"), py::arg("quick"), py::arg("out_dir"),
             py::arg("jobs"), py::arg("timing"), py::arg("progress"), py::arg("command_line"));
  module.def("gate", &gate, py::arg("gates"), py::arg("results"));
  module.def("gate_tables", &gate_tables, py::arg("gates"), py::arg("tables"), py::arg("folder"));
  module.def("score", &score, py::arg("problem"), py::arg("path"), py::arg("start_tol"),
             py::arg("velocities"), py::arg("metrics"), py::arg("label"), py::arg("reference_dir"));
  bind_python_methods(module);
}
