// Linear-stability search (docs/METHOD.md §7): the largest step h·ω for which a fixed-step method
// keeps the energy of an oscillator bounded, found by a geometric scan and bisection on h, next to
// the limit the linear theory predicts for the method (Hairer–Lubich–Wanner GNI §I.5 and §XIII;
// Hughes, The Finite Element Method, 2000, §9.1 for Newmark).
#pragma once

#include <string>
#include <vector>

#include "harness/table.hpp"
#include "problems/problem.hpp"

namespace geomint {

class MethodFactory;  // harness/run_spec.hpp

// What one `[[stability]]` scene block (or one test) asks for. The search range is given in
// h·ω (ω = the problem's omega_max at its initial state) or, for problems without omega_max, in
// h directly; the horizon in periods (2π/ω) or as a time.
struct StabilityOptions {
  double homega_min = 0.05, homega_max = 1000;  // search range in h·ω (when h_min == 0)
  double h_min = 0, h_max = 0;                  // search range in h (problems without omega_max)
  double periods = 100;                         // horizon in periods 2π/ω (when t_end == 0)
  double t_end = 0;                             // horizon in time
  long min_steps = 10000;  // at least this many steps, so that slow growth at large h shows
  // A run is unstable when |H(q_k, p_k)| exceeds growth·|H_0| at some step point (or a step fails
  // or turns non-finite). The factor is large because a stable but nearly degenerate invariant
  // ellipse (symplectic Euler close to hω = 2 reaches H/H_0 = 1/(1 − hω/2)) must not count as
  // unstable; exponential growth passes any factor within a few hundred steps.
  double growth = 1e4;
  int scan_points_per_decade = 8;  // geometric scan before the bisection
  double rel_tol = 1e-6;           // bisection stops when the bracket is this narrow (relative)
};

struct StabilityBlock {
  std::string label;
  std::vector<std::string> problems, methods;
  StabilityOptions options;
};

struct StabilityResult {
  Row row;  // label-free CSV row: problem, method, alpha, homega_max_measured, predicted, ...
  double homega_limit = 0;  // largest stable h·ω found (homega_max when stable up to the range)
  double predicted = 0;     // linear theory; +inf when unconditionally stable, NaN when unknown
  std::string status;       // "bracketed", "stable_to_max" or "unstable_at_min"
};

// Scans h·ω geometrically from the bottom of the range, bisects between the last stable and the
// first unstable point, and records whether a larger point of the scan is stable again
// (non-monotone stability). Throws InputError for adaptive methods, bad ranges or bad specs.
StabilityResult stability_search(const Problem& problem, const MethodFactory& method,
                                 const StabilityOptions& options);

// The linear-theory limit of h·ω on the harmonic oscillator for a method spec, as the method
// predicts it (Integrator::predicted_linear_stability): +inf for unconditionally stable methods,
// 0 for explicit Euler (never stable), NaN when the method has no prediction.
double predicted_homega_limit(const MethodFactory& method);

// Caps on the work of one search: steps per run (at the bottom of the range, the longest run)
// and points of the geometric scan.
constexpr long kMaxStabilityStepsPerRun = 100000000;
constexpr int kMaxStabilityScanPoints = 1000;

// Checks a block's options (InputError naming the key).
void validate_stability_options(const StabilityOptions& options, const std::string& where);

// Resolves the range and horizon for `problem_spec` (InputError when the problem has no
// omega_max and the block asks in h·ω or periods) and checks them against the caps above, so a
// search that would run for days is rejected when the scene is loaded.
// `problem_spec` is the spelling the messages name.
void check_stability_budget(const Problem& problem, const std::string& problem_spec,
                            const StabilityOptions& options, const std::string& where);

// Columns of stability.csv, in order.
const std::vector<std::string>& stability_columns();

// The type of a stability.csv column (the runs count an integer, the h*omega values and the
// method's alpha reals, the rest text).
ColumnType stability_column_type(const std::string& name);

}  // namespace geomint
