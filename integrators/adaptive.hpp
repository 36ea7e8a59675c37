// Base of the adaptive library wrappers (SUNDIALS, GSL odeiv2, Boost.Odeint controlled steppers;
// docs/DESIGN.md §2): the rtol/atol/max_steps options and the checks every adaptive_step makes
// before it asks its library for a step.
#pragma once

#include <string>

#include "integrators/integrator.hpp"

namespace geomint {

// The options every adaptive wrapper reads.
struct AdaptiveSettings {
  double rtol = 1e-8;
  double atol = 1e-10;
  long max_steps = 1000000;  // steps over the whole run
};

// rtol in (0, 1), atol >= 0, max_steps in 1..1e12; `max_steps_help` says what the library counts
// as a step and how the run fails when the budget is used up.
AdaptiveSettings read_adaptive_settings(Params& params, const std::string& max_steps_help);

// Starting step from the size of y and y' in the error norm (Hairer, Nørsett & Wanner I, §II.4,
// first two stages of the starting-step algorithm), for libraries that need a guess (GSL has no
// estimate of its own, odeint's try_step needs one); a poor guess only costs rejected steps.
double starting_step(const Vec& y, const Vec& ydot, double rtol, double atol);

// The library's own state (y, t, step size) is the state of record: reset() loads it from State
// and each adaptive_step copies it back, so edits to State between steps are ignored. Setup
// problems found in reset() (which has no status to return) are kept in setup_status_ and
// reported by the first adaptive_step.
class AdaptiveIntegrator : public Integrator {
 public:
  StepStatus step(const Problem&, State&, double) override;

 protected:
  // `family` names the wrappers in messages ("SUNDIALS wrappers").
  AdaptiveIntegrator(const AdaptiveSettings& settings, std::string family)
      : settings_(settings), family_(std::move(family)) {}

  // Base reset, problem, setup status, callback error and t_ = state.t.
  void begin_adaptive_reset(const Problem& problem, const State& state, double h);

  // Guards shared by every adaptive_step before it asks the library for a step. Returns false
  // with `status` set when no library step should be taken: not reset, a setup failure, another
  // problem, t_stop reached (status success) or behind, or the run-total step budget used up.
  bool ready_to_step(const Problem& problem, const State& state, double t_stop,
                     StepStatus& status) const;

  // The failure when counters_.steps reached settings_.max_steps before t_stop.
  virtual StepStatus step_budget_exhausted(double t_stop) const;

  // Tolerances below round-off (roundoff_tolerance_ratio of y above 1): an error-controlled
  // solver would crawl at the smallest representable step until the budget runs out; this names
  // the cause at once. Success otherwise.
  StepStatus check_tolerances_above_roundoff(const double* y, long n, const std::string& reason,
                                             const std::string& method) const;

  AdaptiveSettings settings_;
  std::string family_;
  const Problem* problem_ = nullptr;
  StepStatus setup_status_;
  std::string callback_error_;  // text of an exception thrown inside a library callback
  double t_ = 0.0;              // time of the library's current y
};

}  // namespace geomint
