// The verbs of the geomint command line, one file each (harness/cli/<verb>.cpp, docs/CLI.md):
// add_<verb> adds the subcommand with its options to `app` and returns how to run it. Their
// order here is the order of `geomint --help`.
#pragma once

#include <vector>

#include "harness/cli/common.hpp"

namespace geomint::cli {

// Adds the exit-code footer and every verb below to `app` in this order, each verb with --quiet
// bound to `quiet` (harness/cli/app.cpp).
std::vector<Verb> add_verbs(CLI::App& app, bool& quiet);

Verb add_list(CLI::App& app);
Verb add_run(CLI::App& app);
Verb add_order(CLI::App& app);
Verb add_sweep(CLI::App& app);
Verb add_merge(CLI::App& app);
Verb add_slurm(CLI::App& app);
Verb add_reference(CLI::App& app);
Verb add_modes(CLI::App& app);
Verb add_gate(CLI::App& app);
Verb add_report(CLI::App& app);
Verb add_perf_compare(CLI::App& app);

}  // namespace geomint::cli
