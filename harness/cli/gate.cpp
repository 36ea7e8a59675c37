// `geomint gate GATES RESULTS...`: result tables checked against the thresholds of a gates file
// (harness/gate.hpp); exit 1 when a gate fails, 2 when none applies (docs/CLI.md "gate").
#include "harness/gate.hpp"

#include <fmt/format.h>

#include <memory>

#include "harness/cli/verbs.hpp"
#include "problems/spec.hpp"

namespace geomint::cli {
namespace {

struct GateCliOptions {
  std::string gates_path;
  std::vector<std::string> results;
  bool verbose = false;
};

int run_gate(const GateCliOptions& cli, const Context&) {
  const std::vector<Gate> gates = load_gates(cli.gates_path);
  const auto outcomes = check_gates(gates, load_result_files(cli.results));
  int failed = 0, applicable = 0;
  for (const auto& outcome : outcomes) {
    if (!outcome.applicable) continue;
    ++applicable;
    failed += outcome.passed ? 0 : 1;
    fmt::print("{} {} ({} row(s))\n", outcome.passed ? "PASS" : "FAIL", outcome.gate->name,
               outcome.rows_checked);
    if (!outcome.passed || cli.verbose) {
      for (const auto& line : outcome.lines) fmt::print("    {}\n", line);
    }
  }
  if (applicable == 0) {
    throw InputError(fmt::format(
        "gate: none of the {} gate(s) in '{}' applies to the results given (their scenes "
        "and variants differ); nothing was checked",
        outcomes.size(), cli.gates_path));
  }
  fmt::print("{} of {} gate(s) passed ({} not applicable to the scenes given)\n",
             applicable - failed, applicable, outcomes.size() - applicable);
  return failed == 0 ? kExitOk : kExitFailed;
}

}  // namespace

Verb add_gate(CLI::App& app) {
  auto options = std::make_shared<GateCliOptions>();
  auto* command = app.add_subcommand(
      "gate", "Check result CSVs against the thresholds of a gates file (exit 1 on failure)");
  command->add_option("gates", options->gates_path, "GATES.toml with [[gate]] blocks")->required();
  command->add_flag("--verbose", options->verbose,
                    "print every checked row, not only the failing ones");
  command
      ->add_option("results", options->results,
                   "result CSV files (summary.csv, order.csv, ...) or scene folders "
                   "(results/<scene>, results/<scene>/quick)")
      ->required();
  return {"gate", command,
          [options](const Context& context) { return run_gate(*options, context); }};
}

}  // namespace geomint::cli
