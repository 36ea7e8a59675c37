// One run = (problem spec, method spec, dt, t_end): the step loop with observers at step points,
// the metrics of DESIGN.md §3 that apply to the problem, failure rows, optional time series,
// and a separate timing pass without observers (median of repeats) for wall_s.
#pragma once

#include <optional>
#include <string>

#include "harness/table.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

struct RunConfig {
  double dt = 0.0;            // fixed step (> 0); adaptive methods ignore it
  double t_end = 0.0;         // horizon (> 0)
  std::string series_path;    // time series CSV, empty = none
  long series_every = 1;      // write every N-th step point (the last point always)
  bool series_state = false;  // force q, p columns for problems with > 64 dof
  int timing_repeats = 3;     // separate timed runs without observers; 0 = no wall_s
  std::string command_line;   // for the series provenance
  // Problems without an exact solution: error_final/error_max against the reference file
  // <reference_dir>/<problem>.csv when it exists and has a row at t_end (harness/reference.hpp);
  // the row's column `reference` names the file.
  std::string reference_dir = "results/references";
};

struct RunResult {
  Row row;  // CSV row: identifiers, status, metrics, counters, wall_s
  bool ok = true;
  State final_state;
  std::map<std::string, double> metrics;  // numeric metrics by column name
};

// Validates specs and config (InputError on bad input), then runs. Numerical failures are
// reported in the result (status != ok), never thrown.
RunResult run_one(const std::string& problem_spec, const std::string& method_spec,
                  const RunConfig& config);

// Timing pass alone: median wall time of `repeats` runs without observers or per-step checks.
double time_run(const std::string& problem_spec, const std::string& method_spec,
                const RunConfig& config, int repeats);

// Checks dt and t_end (InputError naming the offending option).
void validate_run_config(const RunConfig& config, bool adaptive);

}  // namespace geomint
