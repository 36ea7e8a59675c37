// Step-point observers that turn a trajectory into the metrics of docs/DESIGN.md §3. Each observer
// applies only when the problem has what it needs (an invariant, an exact solution), so
// inapplicable metrics never appear in the output.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

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

// The metric observers that apply to `problem`. A `diverge_factor` that is > 0 and finite
// (RunConfig::diverge_factor) adds the divergence rule: the energy observer stops a conservative
// run whose |H − H₀|/|H₀| exceeds it (with the energy it evaluates for its metric, once per step
// point), a state-norm observer any other run whose max(|q|∞, |p|∞) exceeds kDivergedStateNorm.
std::vector<std::unique_ptr<Observer>> make_metric_observers(const Problem& problem,
                                                             double diverge_factor = 0);

// A forced or first-order run whose state passes this norm has blown up.
constexpr double kDivergedStateNorm = 1e100;

// Relative energy error reference: H0 for conservative problems, the exact solution's energy
// for forced problems that have one; false when neither applies.
bool has_energy_reference(const Problem& problem);

// Least-squares slope of y against x (energy drift over per-window maxima, phase shift against
// time, order of log error against log dt); 0 for fewer than 2 points or constant x.
double least_squares_slope(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace geomint
