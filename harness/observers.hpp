// Step-point observers that turn a trajectory into the metrics of docs/DESIGN.md §3. Each observer
// applies only when the problem has what it needs (an invariant, an exact solution), so
// inapplicable metrics never appear in the output.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "harness/metrics.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace geomint {

class Observer {
 public:
  virtual ~Observer() = default;
  // Called with the initial state; t_end is the horizon (for time windows).
  virtual void begin(const Problem& problem, const State& state, double t_end) = 0;
  // Called at each step point before observe(): a failed status (the divergence rule) ends the
  // run there, and no observer observes that point, so the metrics end with the last admitted one.
  virtual StepStatus admit(const Problem&, const State&) { return StepStatus::success(); }
  virtual void observe(const Problem& problem, const State& state) = 0;
  // Adds this observer's metrics (column name → value).
  virtual void finish(std::map<std::string, double>& metrics) const = 0;
};

struct ReferenceSolution;
class MethodFactory;

// What an observer factory (harness/metrics.def) may look at: the problem, the optional metrics
// asked for, the step, the divergence rule and, on a run, its method and reference.
struct ObserverContext {
  const Problem& problem;
  const std::vector<std::string>& metrics;  // RunConfig::extra_metrics
  double dt = 0;                            // the run's step (the first one of an adaptive run)
  // > 0 and finite (RunConfig::diverge_factor): the divergence rule. The energy observer stops a
  // conservative run whose |H − H₀|/|H₀| exceeds it (with the energy it evaluates for its metric,
  // once per step point), a state-norm rule any other run whose max(|q|∞, |p|∞) exceeds
  // kDivergedStateNorm.
  double diverge_factor = 0;
  // The run's parsed method: observers that step on their own make fresh integrators from it
  // (never re-parsing its spec); nullptr: no metric that reads the method applies. On a
  // non-separable problem it runs what the row's spec_on() names (integrators/general_step.hpp).
  const MethodFactory* method = nullptr;
  // A loaded reference whose rows reach t_end (error_max/error_final, valid_time), or nullptr.
  std::shared_ptr<const ReferenceSolution> reference = nullptr;
};

// The observers of every row of the metric table that applies in `context`, in table order.
ObserverList make_observers(const ObserverContext& context);

// The observers that need no method: the metrics computed whenever they apply to `problem`, with
// the divergence rule for `diverge_factor` (tests, and runs without optional metrics).
ObserverList make_metric_observers(const Problem& problem, double diverge_factor = 0);

// A forced or first-order run whose state passes this norm has blown up.
constexpr double kDivergedStateNorm = 1e100;

// Relative energy error reference: H0 for conservative problems, the exact solution's energy
// for forced problems that have one; false when neither applies.
bool has_energy_reference(const Problem& problem);

// Least-squares slope of y against x (energy drift over per-window maxima, phase shift against
// time, order of log error against log dt); 0 for fewer than 2 points or constant x.
double least_squares_slope(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace geomint
