// `geomint order`: the convergence order fitted over the ladder dt0·2^-k (harness/order.hpp);
// prints the order on stdout, the ladder on stderr; exit 1 when no order could be fitted
// (docs/CLI.md "order").
#include "harness/order.hpp"

#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "harness/cli/verbs.hpp"
#include "harness/metrics.hpp"
#include "harness/paths.hpp"
#include "harness/run.hpp"
#include "harness/table.hpp"

namespace geomint::cli {
namespace {

struct OrderOptions {
  std::string problem_spec, method_spec, out_path, initial_path;
  std::string format = "csv";
  double dt0 = 0, t_end = 0;
  long levels = 6;
  double diverge_factor = kDefaultDivergeFactor;
};

int run_order(OrderOptions options, const Context& context) {
  add_initial_state(options.problem_spec, options.initial_path);
  // Spec strings become objects here, once; then every input error is reported together.
  const auto problem = parse_problem(options.problem_spec);
  const MethodFactory method(options.method_spec);
  std::vector<std::string> errors =
      order_study_errors(*problem, method, options.dt0, options.levels, options.t_end);
  if (!options.out_path.empty()) {
    try {
      check_output_file(options.out_path, "--out");
    } catch (const InputError& error) {
      errors.emplace_back(error.what());
    }
  }
  TableFormat format = TableFormat::kCsv;
  try {
    format = parse_table_format(options.format, "--format");
    // stdout carries the fitted order alone (scripts read it); the table goes to --out only.
    if (format == TableFormat::kJson && options.out_path.empty()) {
      errors.emplace_back(
          "--format json applies to the --out table of the ladder runs; give --out FILE (stdout "
          "holds only the fitted order)");
    }
  } catch (const InputError& error) {
    errors.emplace_back(error.what());
  }
  throw_input_errors(errors);
  const OrderStudy study =
      order_study(problem, method, options.dt0, static_cast<int>(options.levels), options.t_end,
                  options.diverge_factor);
  for (const auto& run_result : study.runs) {
    const Row row = to_row(run_result.record);
    inform(context,
           fmt::format(
               "dt={:<12} status={:<8} error_final={}", row.at("dt"), row.at("status"),
               row.count(metric::error_final.key()) ? row.at(metric::error_final.key()) : "-"));
  }
  if (!options.out_path.empty()) {
    std::string table = to_csv(ladder_table(study, provenance(context.command_line)));
    // The JSON is the CSV read back, so both hold the same cells to the digit.
    if (format == TableFormat::kJson) table = to_json(parse_csv_table(table, "the ladder runs"));
    write_file_atomic(options.out_path, table);
  }
  if (!std::isfinite(study.fit.order)) {
    fmt::print(stderr, "{}: no order fit: {}\n", context.program, study.fit.note);
    return kExitFailed;
  }
  fmt::print("{:.3f}\n", study.fit.order);
  inform(context, fmt::format("order {:.3f} (declared {}) from dt = {}{}", study.fit.order,
                              study.record.declared_order, to_row(study.record).at("points_used"),
                              study.fit.note.empty() ? "" : "; " + study.fit.note));
  const Row orders = to_row(study.record);
  const auto shown = [](const std::string& cell) { return cell.empty() ? "no fit" : cell; };
  inform(context,
         fmt::format("order_q {}, order_p {}, order_multiplier {}{}", shown(orders.at("order_q")),
                     shown(orders.at("order_p")), shown(orders.at("order_multiplier")),
                     study.multiplier_from_state ? " (multiplier from (q, p))" : ""));
  return kExitOk;
}

}  // namespace

Verb add_order(CLI::App& app) {
  auto options = std::make_shared<OrderOptions>();
  auto* command = app.add_subcommand("order", "Fit the convergence order over a dt ladder");
  command->add_option("--problem", options->problem_spec, "problem spec")->required();
  command->add_option("--method", options->method_spec, "method spec")->required();
  command->add_option("--dt", options->dt0, "largest step dt0 (ladder dt0*2^-k)")->required();
  command->add_option(
      "--levels", options->levels,
      fmt::format("number of ladder levels ({}..{})", kMinOrderLevels, kMaxOrderLevels));
  command->add_option("--t-end", options->t_end, "horizon")->required();
  command->add_option("--out", options->out_path, "write the ladder runs as a table");
  command->add_option("--format", options->format,
                      "csv (default) or json (docs/schema/table.schema.json): the format of the "
                      "--out table");
  command->add_option("--diverge-factor", options->diverge_factor, diverge_factor_help());
  command->add_option("--initial", options->initial_path, kInitialStateHelp);
  return {"order", command,
          [options](const Context& context) { return run_order(*options, context); }};
}

}  // namespace geomint::cli
