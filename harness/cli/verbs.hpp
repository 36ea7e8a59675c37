// The verbs of the geomint command line, one file each (harness/cli/<verb>.cpp, docs/CLI.md),
// listed in verbs.def: add_<verb> adds the subcommand with its options to `app` and returns how to
// run it. The order of verbs.def is the order of `geomint --help`.
#pragma once

#include <vector>

#include "harness/cli/common.hpp"

namespace geomint::cli {

// Adds the exit-code footer and every verb below to `app` in this order, each verb with --quiet
// bound to `quiet` (harness/cli/app.cpp).
std::vector<Verb> add_verbs(CLI::App& app, bool& quiet);

// Removes summary.json, order.json, ... of `out_dir` (harness/cli/sweep.cpp): called when a sweep
// or merge rewrote the CSVs without --format json, so no JSON table outlives its CSV.
void remove_stale_json_tables(const std::string& out_dir, const Context& context);

#define GEOMINT_VERB(verb) Verb add_##verb(CLI::App& app);
#include "harness/cli/verbs.def"
#undef GEOMINT_VERB

}  // namespace geomint::cli
