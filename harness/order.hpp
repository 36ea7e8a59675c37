// Convergence order (DESIGN.md §3): least-squares slope of log(error) against log(dt) over a
// dt ladder dt0·2⁻ᵏ, after dropping failed points, the round-off plateau and pre-asymptotic
// points; at least 3 points, reported with the points used.
#pragma once

#include <string>
#include <vector>

#include "harness/run.hpp"

namespace geomint {

struct OrderFit {
  double order = 0.0;     // NaN when fewer than 3 usable points
  std::vector<int> used;  // indices into the ladder that entered the fit
  std::string note;       // why points were dropped, or why there is no fit
};

// `errors[i]` at step `dts[i]` (dts decreasing); failed points have a non-finite error.
// Points whose error is below `plateau_floor` are on the round-off plateau.
OrderFit fit_order(const std::vector<double>& dts, const std::vector<double>& errors,
                   double plateau_floor = 1e-13);

struct OrderStudy {
  OrderFit fit;
  std::vector<RunResult> runs;  // one per ladder level
  Row row;                      // problem, method, order, declared_order, points_used, ...
};

// Runs the ladder dt0·2⁻ᵏ, k = 0..levels−1, without timing, and fits error_final (or, for
// problems without an exact solution, the difference to the finest level — noted in the row).
OrderStudy order_study(const std::string& problem_spec, const std::string& method_spec, double dt0,
                       int levels, double t_end);

}  // namespace geomint
