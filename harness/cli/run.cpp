// `geomint run`: one problem with one method (harness/run.hpp), its summary as one CSV row and
// optionally a time series; exit 1 when the run failed (docs/CLI.md "run").
#include "harness/run.hpp"

#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "harness/cli/verbs.hpp"
#include "harness/paths.hpp"
#include "harness/run_spec.hpp"
#include "harness/structure_metrics.hpp"
#include "harness/table.hpp"

namespace geomint::cli {
namespace {

struct RunOptions {
  std::string problem_spec, method_spec, out_path, series_path, initial_path;
  std::string format = "csv";
  double dt = 0, t_end = 0;
  bool dt_given = false, t_end_given = false;
  long every = 1;
  long timing_repeats = 3;
  double diverge_factor = kDefaultDivergeFactor;
  bool series_state = false;
  long max_steps = kDefaultMaxSteps;
  double wall_budget_s = 0;
  std::vector<std::string> extra_metrics;
};

int run_run(RunOptions options, const Context& context) {
  add_initial_state(options.problem_spec, options.initial_path);
  // Spec strings become objects here, once; an unknown name, key or value stops at once.
  RunSpec spec{parse_problem(options.problem_spec), MethodFactory(options.method_spec), {}};
  std::vector<std::string> errors;
  // Counted in a long so that a huge value is reported, not wrapped into range.
  if (options.timing_repeats < 0 || options.timing_repeats > kMaxTimingRepeats) {
    errors.push_back(fmt::format("--timing-repeats must be in 0..{} (got {})", kMaxTimingRepeats,
                                 options.timing_repeats));
    options.timing_repeats = 0;
  }
  RunConfig& config = spec.config;
  config.dt = options.dt_given ? options.dt : spec.problem->default_dt();
  config.t_end = options.t_end_given ? options.t_end : spec.problem->default_t_end();
  config.series_path = options.series_path;
  config.series_every = options.every;
  config.series_state = options.series_state;
  config.timing_repeats = static_cast<int>(options.timing_repeats);
  config.diverge_factor = options.diverge_factor;
  config.max_steps = options.max_steps;
  config.wall_budget_s = options.wall_budget_s;
  config.extra_metrics = options.extra_metrics;
  config.command_line = context.command_line;
  // Outputs are checked before anything is computed.
  TableFormat format = TableFormat::kCsv;
  try {
    format = parse_table_format(options.format, "--format");
  } catch (const InputError& error) {
    errors.emplace_back(error.what());
  }
  const std::string& out_path = options.out_path;
  if (!out_path.empty()) {
    try {
      check_output_file(out_path, "--out");
    } catch (const InputError& error) {
      errors.emplace_back(error.what());
    }
  }
  if (!options.series_path.empty() && !out_path.empty() &&
      same_file_path(options.series_path, out_path)) {
    errors.push_back(
        fmt::format("--series and --out name the same file '{}' (the summary would overwrite "
                    "the series)",
                    out_path));
  }
  for (std::string& error : spec.validate()) errors.push_back(std::move(error));
  throw_input_errors(errors);
  const RunResult result = run_one(spec);
  std::string table = records_to_csv({result.record}, provenance(context.command_line));
  // The JSON is the CSV read back, so both hold the same cells to the digit.
  if (format == TableFormat::kJson) table = to_json(parse_csv_table(table, "the summary"));
  if (out_path.empty()) {
    std::cout << table;
  } else {
    write_file_atomic(out_path, table);
  }
  if (!result.ok) {
    fmt::print(stderr, "{}: run failed: {}: {}\n", context.program, result.record.status,
               result.record.message.value_or(""));
  }
  return result.ok ? kExitOk : kExitFailed;
}

}  // namespace

Verb add_run(CLI::App& app) {
  auto options = std::make_shared<RunOptions>();
  auto* command =
      app.add_subcommand("run", "Run one problem with one method and print a CSV row");
  command->add_option("--problem", options->problem_spec, "problem spec, e.g. pendulum:theta0=1.5")
      ->required();
  command->add_option("--method", options->method_spec, "method spec, e.g. stormer_verlet")
      ->required();
  command->add_option("--dt", options->dt, "step size (> 0); default: the problem's");
  command->add_option("--t-end", options->t_end, "horizon (> 0); default: the problem's");
  command->add_option("--out", options->out_path, "write the summary here instead of stdout");
  command->add_option("--format", options->format,
                      "csv (default) or json: the summary table as CSV with '# key: value' "
                      "provenance lines, or as JSON (docs/schema/table.schema.json); the "
                      "--series file stays CSV");
  command->add_option("--series", options->series_path, "write a time series CSV here");
  command->add_option("--every", options->every,
                      "series: every N-th step point (the last is always written)");
  command->add_flag("--state", options->series_state, "series: include q and p even for > 64 dof");
  command->add_option("--timing-repeats", options->timing_repeats,
                      fmt::format("timing pass repeats (0 = none, at most {})", kMaxTimingRepeats));
  command->add_option("--diverge-factor", options->diverge_factor, diverge_factor_help());
  command->add_option("--max-steps", options->max_steps,
                      fmt::format("step budget of a fixed-step run: more grid steps end the run "
                                  "as the failure row max_steps (default {:g}, at most {:g})",
                                  static_cast<double>(kDefaultMaxSteps), kMaxFixedSteps));
  command->add_option("--wall-budget", options->wall_budget_s,
                      fmt::format("wall-clock budget of the run in seconds: a longer run ends as "
                                  "the row status timeout (0 = none, the default; at most {:g})",
                                  kMaxWallBudgetSeconds));
  command->add_option("--metric", options->extra_metrics,
                      "also compute an optional metric (repeatable): symplecticity_defect, "
                      "period_measured (with period_err_rel), energy_growth_exponent, "
                      "mode_freq_err_max, mode_damping_max, symplecticity_defect_map (with "
                      "symplecticity_defect_map_fd_err and symplecticity_defect_map_slope), "
                      "lyapunov_max, megno (with megno_final and chaos_tangent_fd), valid_time "
                      "(with valid_time_reached), toda_invariants_err_max, lrl_err_max, "
                      "loop_action_err (with loop_action_points)");
  command->add_option("--initial", options->initial_path, kInitialStateHelp);
  return {"run", command, [options, command](const Context& context) {
            RunOptions given = *options;
            given.dt_given = command->count("--dt") > 0;
            given.t_end_given = command->count("--t-end") > 0;
            return run_run(given, context);
          }};
}

}  // namespace geomint::cli
