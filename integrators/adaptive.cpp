// Shared options and step guards of the adaptive library wrappers (see adaptive.hpp).
#include "integrators/adaptive.hpp"

#include <fmt/format.h>

#include <cmath>

namespace geomint {

AdaptiveSettings read_adaptive_settings(Params& params, const std::string& max_steps_help) {
  AdaptiveSettings settings;
  settings.rtol = params.real("rtol", settings.rtol, "relative tolerance", Range::open(0, 1));
  settings.atol = params.real("atol", settings.atol, "absolute tolerance", Range::at_least(0));
  settings.max_steps =
      params.integer("max_steps", settings.max_steps, max_steps_help, 1, 1000000000000L);
  return settings;
}

double starting_step(const Vec& y, const Vec& ydot, double rtol, double atol) {
  const Vec scale = (atol + rtol * y.array().abs()).matrix();
  const double d0 = std::sqrt((y.array() / scale.array()).square().mean());
  const double d1 = std::sqrt((ydot.array() / scale.array()).square().mean());
  if (!(d0 >= 1e-5 && d1 >= 1e-5) || !std::isfinite(d0 / d1)) return 1e-6;
  return 0.01 * d0 / d1;
}

StepStatus AdaptiveIntegrator::step(const Problem&, State&, double) {
  return StepStatus::failure(
      "adaptive_only", fmt::format("{} are adaptive; the harness calls adaptive_step()", family_));
}

void AdaptiveIntegrator::begin_adaptive_reset(const Problem& problem, const State& state,
                                              double h) {
  Integrator::reset(problem, state, h);
  problem_ = &problem;
  setup_status_ = StepStatus::success();
  callback_error_.clear();
  t_ = state.t;
}

bool AdaptiveIntegrator::ready_to_step(const Problem& problem, const State& state, double t_stop,
                                       StepStatus& status) const {
  status = StepStatus::success();
  if (problem_ == nullptr) {
    status = StepStatus::failure("not_reset", "adaptive_step called before reset()");
    return false;
  }
  if (!setup_status_.ok) {
    status = setup_status_;
    return false;
  }
  if (&problem != problem_) {
    status = StepStatus::failure("problem_changed",
                                 "adaptive_step called with another problem than reset()");
    return false;
  }
  if (t_stop == state.t) return false;
  if (!(t_stop > t_)) {
    status = StepStatus::failure(
        "bad_t_stop", fmt::format("t_stop={} is not ahead of the solver time {}", t_stop, t_));
    return false;
  }
  if (counters_.steps >= settings_.max_steps) {
    status = step_budget_exhausted(t_stop);
    return false;
  }
  return true;
}

StepStatus AdaptiveIntegrator::step_budget_exhausted(double t_stop) const {
  // At a tolerance below round-off the controller keeps accepting steps near the smallest
  // representable size, and a huge horizon needs ever more steps: both end here.
  return StepStatus::failure(
      "max_steps", fmt::format("max_steps={} accepted steps taken before t={:.6g} (t_stop "
                               "{:.6g}); raise max_steps or loosen rtol/atol",
                               settings_.max_steps, t_, t_stop));
}

StepStatus AdaptiveIntegrator::check_tolerances_above_roundoff(const double* y, long n,
                                                               const std::string& reason,
                                                               const std::string& method) const {
  const double ratio = roundoff_tolerance_ratio(y, n, settings_.rtol, settings_.atol);
  if (ratio <= 1.0) return StepStatus::success();
  return too_much_accuracy(reason, method, t_, settings_.rtol, settings_.atol, ratio);
}

}  // namespace geomint
