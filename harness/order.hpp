// Convergence order (docs/DESIGN.md §3): least-squares slope of log(error) against log(dt) over a
// dt ladder dt0·2⁻ᵏ, after dropping failed points, the round-off plateau and pre-asymptotic
// points; at least 3 points, reported with the points used.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "harness/run_spec.hpp"

namespace geomint {

struct OrderFit {
  double order = 0.0;     // NaN when fewer than 3 usable points
  std::vector<int> used;  // indices into the ladder that entered the fit
  std::string note;       // why points were dropped, or why there is no fit
};

// `errors[i]` at step `dts[i]` (dts decreasing); failed points have a non-finite error.
// Points whose error is below `plateau_floor` are on the round-off plateau; points whose error
// exceeds `error_ceiling` are not small against the solution, so not in the asymptotic range
// (the slope of errors that have saturated at the size of the orbit says nothing about the
// method: Kepler at e = 0.999 with errors of 1e3 once fitted "order 0.999").
OrderFit fit_order(const std::vector<double>& dts, const std::vector<double>& errors,
                   double plateau_floor = 1e-13,
                   double error_ceiling = std::numeric_limits<double>::infinity());

// The error_ceiling order_study passes: a tenth of the solution's own scale.
constexpr double kAsymptoticErrorFraction = 0.1;

struct OrderStudy {
  OrderFit fit;  // of ‖(q, p) − exact‖ (error_final)
  // The same fit on the final ‖q − q_exact‖ and ‖p − p_exact‖ alone (or against the finest level).
  OrderFit fit_q, fit_p;
  // |λ̄ − λ(t_N − h/2)|∞ with λ̄ the method's discrete multiplier (docs/METHOD.md §3, "Discrete
  // multiplier"), or |λ(q_N, p_N) − λ(t_N)|∞ from the state for methods that expose none; only
  // when the problem has exact_multipliers() (multiplier_applies).
  OrderFit fit_multiplier;
  bool multiplier_applies = false;
  bool multiplier_from_state = false;  // the fallback above was used
  std::vector<RunResult> runs;         // one per ladder level
  OrderRecord record;                  // the order.csv row
};

// Ladder length: at least 3 points for a fit, at most kMaxOrderLevels (dt0·2⁻²⁹ is already far
// below any useful step).
constexpr int kMinOrderLevels = 3;
constexpr int kMaxOrderLevels = 30;

// Every error a study can be refused for before its first run, one message each naming the
// option: levels, dt0 and t_end, t_end/dt of the finest level against kMaxFixedSteps, and
// whether the method applies to the problem.
std::vector<std::string> order_study_errors(const Problem& problem, const MethodFactory& method,
                                            double dt0, long levels, double t_end);

// Runs the ladder dt0·2⁻ᵏ, k = 0..levels−1, without timing (one problem object, a fresh
// integrator from `method` per level), and fits error_final (or, for problems without an exact
// solution, the difference to the finest level — noted in the row), the q and p parts of it, and
// the multiplier error where the problem knows its exact value. Validates everything first
// (order_study_errors), so bad input throws before any run.
OrderStudy order_study(const std::shared_ptr<const Problem>& problem, const MethodFactory& method,
                       double dt0, int levels, double t_end,
                       double diverge_factor = kDefaultDivergeFactor);

// The study's ladder in memory, one row per level over the record columns its runs set: the
// table `geomint order --out` writes (to_csv) and geomint.order returns.
ResultTable ladder_table(const OrderStudy& study,
                         const std::vector<std::pair<std::string, std::string>>& lines);

}  // namespace geomint
