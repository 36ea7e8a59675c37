// `geomint score`: the metrics of trajectories other programs wrote (harness/score.hpp), one CSV
// row each in the columns of `geomint run`; with --order, the convergence order over them
// (docs/CLI.md "score").
#include "harness/score.hpp"

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <memory>

#include "harness/cli/verbs.hpp"
#include "harness/metrics.hpp"
#include "harness/paths.hpp"
#include "harness/run_spec.hpp"
#include "harness/table.hpp"

namespace geomint::cli {
namespace {

struct ScoreOptions {
  std::string problem_spec, out_path;
  std::vector<std::string> files;
  double start_tol = kDefaultStartTolerance;
  bool velocities = false;
  bool order = false;
  std::vector<std::string> extra_metrics;
};

int run_score(const ScoreOptions& options, const Context& context) {
  const auto problem = parse_problem(options.problem_spec);
  std::vector<std::string> errors = score_metric_errors(options.extra_metrics);
  if (!(options.start_tol >= 0 && std::isfinite(options.start_tol))) {
    errors.push_back(
        fmt::format("--start-tol must be a finite number >= 0 (got {})", options.start_tol));
  }
  if (!options.out_path.empty()) {
    try {
      check_output_file(options.out_path, "--out");
    } catch (const InputError& error) {
      errors.emplace_back(error.what());
    }
    for (const std::string& file : options.files) {
      if (same_file_path(file, options.out_path)) {
        errors.push_back(fmt::format("--out names the input file '{}'", file));
      }
    }
  }
  throw_input_errors(errors);
  // Every file is read and checked before anything is computed or written.
  std::vector<Trajectory> trajectories;
  for (const std::string& file : options.files) {
    try {
      trajectories.push_back(
          read_trajectory(file, *problem, options.start_tol, options.velocities));
    } catch (const InputError& error) {
      errors.emplace_back(error.what());
    }
  }
  throw_input_errors(errors);
  const ScoreConfig config{.extra_metrics = options.extra_metrics};
  std::vector<RunRecord> records;
  for (const Trajectory& trajectory : trajectories) {
    records.push_back(score_trajectory(*problem, trajectory, config));
  }
  std::optional<OrderFit> fit;
  if (options.order) {
    fit = score_order(*problem, trajectories, records);  // InputError before anything is written
    for (size_t k = 0; k < records.size(); ++k) records[k].order_level = static_cast<long>(k);
  }
  const std::string csv = records_to_csv(records, provenance(context.command_line));
  if (!options.out_path.empty()) {
    write_file_atomic(options.out_path, csv);
  } else if (!fit) {
    std::cout << csv;
  }
  if (!fit) return kExitOk;
  for (const RunRecord& record : records) {
    const Row row = to_row(record);
    const auto cell = [&](const std::string& key) {
      return row.count(key) ? row.at(key) : std::string("-");
    };
    inform(context, fmt::format("{}: dt={} error_final={}", record.method, cell("dt"),
                                cell(metric::error_final.key())));
  }
  if (!std::isfinite(fit->order)) {
    fmt::print(stderr, "{}: no order fit: {}\n", context.program, fit->note);
    return kExitFailed;
  }
  fmt::print("{:.3f}\n", fit->order);
  if (!fit->note.empty()) inform(context, fmt::format("order {:.3f}; {}", fit->order, fit->note));
  return kExitOk;
}

}  // namespace

Verb add_score(CLI::App& app) {
  auto options = std::make_shared<ScoreOptions>();
  auto* command = app.add_subcommand(
      "score", "Compute the metrics of trajectories written by any program (CSV or .npy)");
  command->add_option("--problem", options->problem_spec, "problem spec the trajectories solve")
      ->required();
  command
      ->add_option("files", options->files,
                   "trajectory files: CSV with header t,q0..,p0.. (or v0..), a geomint "
                   "series, or .npy (2-D float64, columns t, q, p)")
      ->required();
  command->add_option("--out", options->out_path, "write the rows here instead of stdout");
  command->add_option("--start-tol", options->start_tol,
                      fmt::format("the first row must be the problem's initial state within "
                                  "this tolerance times max(1, |value|) (default {:g})",
                                  kDefaultStartTolerance));
  command->add_flag("--velocity", options->velocities,
                    ".npy files: the last dof columns are velocities v, not momenta p");
  command->add_flag("--order", options->order,
                    "files at successively smaller steps: fit the convergence order (printed "
                    "on stdout; rows only with --out)");
  command->add_option("--metric", options->extra_metrics,
                      "also compute an optional metric (repeatable): period_measured (with "
                      "period_err_rel), energy_growth_exponent, valid_time (with "
                      "valid_time_reached)");
  return {"score", command,
          [options](const Context& context) { return run_score(*options, context); }};
}

}  // namespace geomint::cli
