// One run = (problem spec, method spec, dt, t_end): the step loop with observers at step points,
// the metrics of docs/DESIGN.md §3 that apply to the problem, failure rows, optional time series,
// and a separate timing pass without observers (a warm-up, then the median, minimum and
// interquartile range of repeats) for wall_s, wall_s_min, wall_s_iqr.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "harness/record.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

struct RunSpec;  // harness/run_spec.hpp

// A conservative run is stopped with status `diverged` when its relative energy error
// |H − H₀|/|H₀| exceeds this factor (forced problems: when max(|q|∞, |p|∞) exceeds 1e100);
// `--diverge-factor` / scene key `diverge_factor`. 0 or +inf turns the rule off (non-finite
// states still end the run with status `nan`).
constexpr double kDefaultDivergeFactor = 1e8;
// The failure reason of a run that exceeded RunConfig::wall_budget_s.
inline constexpr const char* kTimeoutStatus = "timeout";
// Cancellation (the Python package's Ctrl-C, docs/PYTHON.md): once request_interrupt() is called
// (async-signal-safe: a lock-free atomic store), a metric pass ends at its next step point with
// this status, a timing pass before its next repeat or adaptive step, until clear_interrupt().
inline constexpr const char* kInterruptedStatus = "interrupted";
void request_interrupt();
void clear_interrupt();
bool interrupt_requested();
// Caps on counts that would otherwise let one option request unbounded work.
constexpr int kMaxTimingRepeats = 100;
// Wall-clock budget of one timing pass (warm-up + repeats), scene key `timing_budget_s`: a pass
// starts no repeat it cannot finish inside the budget (judged from the runs so far), so a slow
// run gets fewer repeats — a point with its count in wall_s_repeats and a message, not a hole.
constexpr double kDefaultTimingBudgetSeconds = 600;
constexpr double kMaxTimingBudgetSeconds = 86400;
// Wall-clock budget of one run (`--wall-budget`, scene key `wall_budget_s`; 0 = none): a metric
// pass still running after it ends at the next step point as the row status `timeout` (t_reached,
// wall_s = the seconds spent), and a timing pass whose run takes longer marks the row `timeout`
// too, so that a work-precision diagram draws the run as a point at the budget, not as a hole.
constexpr double kMaxWallBudgetSeconds = 86400;
constexpr double kMaxFixedSteps = 1e10;  // t_end/dt of one fixed-step run
// The step budget of a fixed-step run (`--max-steps`, scene key `max_steps`), as the library
// wrappers have theirs: a run whose grid has more steps ends at once as the failure row
// `max_steps`, instead of computing for hours without output. 1e8 is ten times the largest
// committed run (long_run, 1e7 steps); the budget may be raised up to kMaxFixedSteps.
constexpr long kDefaultMaxSteps = 100'000'000;

struct RunConfig {
  double dt = 0.0;            // fixed step (> 0); adaptive methods ignore it
  double t_end = 0.0;         // horizon (> 0)
  std::string series_path;    // time series CSV, empty = none
  long series_every = 1;      // write every N-th step point (the last point always)
  bool series_state = false;  // force q, p columns for problems with > 64 dof
  // ≥ 0: a Poincaré section instead: only the points where q_i (i = series_section) crosses 0
  // upwards (q̇_i > 0), each interpolated between its two step points (cubic Hermite in time, with
  // q̇ = M⁻¹p and ṗ = −∇V; scene key `series_section`). -1: every series_every-th step point.
  long series_section = -1;
  int timing_repeats = 3;  // separate timed runs without observers (0..kMaxTimingRepeats)
  double timing_budget_s = kDefaultTimingBudgetSeconds;  // see kDefaultTimingBudgetSeconds
  double diverge_factor = kDefaultDivergeFactor;         // see kDefaultDivergeFactor; 0/inf = off
  double wall_budget_s = 0;                              // see kMaxWallBudgetSeconds; 0 = no budget
  long max_steps = kDefaultMaxSteps;  // fixed-step runs: grid steps allowed (1..kMaxFixedSteps)
  std::string command_line;           // for the series provenance
  // Problems without an exact solution: error_final/error_max against the reference file
  // <reference_dir>/<problem>.csv when it exists and has a row at t_end (harness/reference.hpp);
  // the row's column `reference` names the file.
  std::string reference_dir = "results/references";
  // Optional metrics to compute (harness/structure_metrics.hpp: optional_metric_names()), from
  // `run --metric` or a scene's table_columns.
  std::vector<std::string> extra_metrics;
};

// t_reached (failure rows only) is, for every kind of method, the time of the last step point
// that passed the checks: the state the metrics end with. The run failed in the step after it
// (fixed-step methods: the step ending at t_reached + dt, named in the message; adaptive ones:
// the solver's next internal step).
// InputError unless the Poincaré section q_i = 0 (i = `section`; −1 = none) can be written for
// `problem` (RunConfig::series_section).
void check_series_section(const Problem& problem, long section);
// The same check as a message, empty when the section can be written.
std::string series_section_error(const Problem& problem, long section);

struct RunResult {
  RunRecord record;  // identifiers, status, metrics, counters, wall_s
  bool ok = true;
  State final_state;
  // The method's multiplier impulses in its last step (Integrator::last_constraint_impulses).
  std::optional<ConstraintImpulses> final_impulses;
};

// Validates the spec (RunSpec::validate(); one InputError listing every error), then runs.
// Numerical failures are reported in the result (status != ok), never thrown.
RunResult run_one(const RunSpec& spec);
// The same from spec strings (RunSpec::parse), for the command line, the scene reader and tests.
RunResult run_one(const std::string& problem_spec, const std::string& method_spec,
                  const RunConfig& config);

// Order statistics of the timed repeats of one run: the minimum (the least disturbed run), the
// median (wall_s; the mean of the two middle values for an even count) and the interquartile
// range Q3 − Q1, with quartiles interpolated linearly between order statistics (Hyndman–Fan
// type 7, R's and NumPy's default): Q(p) = x₍ⱼ₎ + f·(x₍ⱼ₊₁₎ − x₍ⱼ₎), j + f = p·(n − 1), 0-based.
struct TimingStats {
  double min = 0, median = 0, iqr = 0, max = 0;
  int count = 0;  // repeats the statistics are taken over
};
// Throws std::invalid_argument on an empty sample (a timing pass always times one run).
TimingStats timing_stats(std::vector<double> seconds);

// Timing pass alone: one untimed warm-up run (caches, page faults, lazy library setup), then
// `repeats` timed runs without observers or per-step checks, inside config.timing_budget_s; or
// the status of the first run that failed (a method whose runs differ; it gets no time).
struct [[nodiscard]] TimingOutcome {
  StepStatus status;
  TimingStats stats;
  double seconds = 0;  // stats.median
  // Why fewer than `repeats` runs were timed (the budget), empty otherwise.
  std::string budget_note;
  // A timed run took longer than config.wall_budget_s: the row becomes status `timeout` with
  // wall_s = that run's seconds (stats hold the runs timed up to and including it).
  bool timed_out = false;
  // The recursive passes per step of the warm-up run's steps (integrator reset excluded) on a
  // problem whose mechanics are O(n) tree recursions (problems/articulated.hpp): a
  // machine-independent cost; nullopt on every other problem.
  std::optional<double> recursive_passes_per_step = std::nullopt;
  // "timing pass failed: reason: message", the row's message when the status failed.
  std::string failure_message() const;
};
// Each run builds a fresh integrator from spec.method (no spec text is re-parsed).
TimingOutcome time_run(const RunSpec& spec, int repeats);
TimingOutcome time_run(const std::string& problem_spec, const std::string& method_spec,
                       const RunConfig& config, int repeats);
// Writes a successful outcome's statistics into the record (wall_s = median, wall_s_min,
// wall_s_iqr, wall_s_repeats, recursive_passes_per_step) and a budget note as its message; a failed
// one's message; a timed-out one also sets status `timeout`.
void record_timing(const TimingOutcome& timing, RunRecord& record);

// Checks dt, t_end (t_end/dt <= kMaxFixedSteps for fixed-step methods), --every,
// --timing-repeats, --diverge-factor, --max-steps and --wall-budget: one message per offending
// option, naming it and what is allowed. A grid longer than max_steps is no input error but a
// failure row.
std::vector<std::string> run_config_errors(const RunConfig& config, bool adaptive);
// The same as one InputError listing every message.
void validate_run_config(const RunConfig& config, bool adaptive);

// Checks the run's output paths before anything is computed (InputError naming the option):
// --series must be writable.
void check_run_outputs(const RunConfig& config);

}  // namespace geomint
