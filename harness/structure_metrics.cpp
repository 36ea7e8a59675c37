// Optional structure metrics (harness/structure_metrics.hpp; README "Metrics").
#include "harness/structure_metrics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "problems/problem.hpp"

namespace geomint {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// period_measured: mean interval between the upward zero crossings of the problem's
// period_observable(q, p) (default q[0]; problems/problem.hpp) at step points (each
// crossing time linearly interpolated between the two step points around it, an O(h²) error
// that is nearly the same at every crossing and so mostly cancels in the differences);
// period_err_rel = (period_measured − T)/T when the problem knows its period T. Needs two
// crossings.
class ZeroCrossingPeriodObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double) override {
    period_ = problem.has(kPeriod) ? problem.period() : kNaN;
    last_t_ = state.t;
    last_x_ = problem.period_observable(state.q, state.p);
  }
  void observe(const Problem& problem, const State& state) override {
    const double x = problem.period_observable(state.q, state.p);
    if (!std::isfinite(x)) return;
    if (last_x_ < 0 && x >= 0) {
      const double crossing = last_t_ + (-last_x_) / (x - last_x_) * (state.t - last_t_);
      if (crossings_ == 0) first_ = crossing;
      last_crossing_ = crossing;
      ++crossings_;
    }
    last_t_ = state.t;
    last_x_ = x;
  }
  void finish(std::map<std::string, double>& metrics) const override {
    if (crossings_ < 2) return;
    const double measured = (last_crossing_ - first_) / (crossings_ - 1);
    metrics["period_measured"] = measured;
    if (!std::isnan(period_)) metrics["period_err_rel"] = (measured - period_) / period_;
  }

 private:
  double period_ = kNaN;
  double last_t_ = 0, last_x_ = 0, first_ = 0, last_crossing_ = 0;
  long crossings_ = 0;
};

// energy_growth_exponent: least-squares slope of log M(t) against log t, M(t) the running
// maximum of |H − H₀|/|H₀| up to time t (t from the run's start), at kGrowthCheckpoints
// log-spaced times over the last kGrowthDecades decades of the run (or from the first step when
// the run is shorter); the first checkpoint is skipped since M there reflects the start-up. A
// bounded error gives 0, a random walk of round-off ½, a linear drift 1. Reported only when the
// run spans at least a decade and M > 0 at the checkpoints used.
class EnergyGrowthObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double t_end) override {
    energy0_ = problem.energy(state.q, state.p);
    scale_ = std::abs(energy0_) > 0 ? std::abs(energy0_) : 1.0;
    t0_ = state.t;
    span_ = t_end;
  }
  void observe(const Problem& problem, const State& state) override {
    const double elapsed = state.t - t0_;
    if (checkpoints_.empty()) {  // the first step fixes the smallest time that can be resolved
      const double first = std::max(elapsed, span_ * std::pow(10.0, -kGrowthDecades));
      if (!(first > 0) || span_ < 10 * first) return;
      for (int i = 0; i < kGrowthCheckpoints; ++i) {
        checkpoints_.push_back(
            first * std::pow(span_ / first, static_cast<double>(i) / (kGrowthCheckpoints - 1)));
      }
    }
    running_max_ =
        std::max(running_max_, std::abs(problem.energy(state.q, state.p) - energy0_) / scale_);
    // Step points land on or after a checkpoint: M up to the step point is recorded for it.
    while (next_ < checkpoints_.size() && elapsed >= checkpoints_[next_] * (1 - 1e-12)) {
      times_.push_back(elapsed);
      maxima_.push_back(running_max_);
      ++next_;
    }
  }
  void finish(std::map<std::string, double>& metrics) const override {
    std::vector<double> log_t, log_max;
    for (size_t i = 1; i < times_.size(); ++i) {
      if (!(maxima_[i] > 0) || !std::isfinite(maxima_[i])) return;
      log_t.push_back(std::log(times_[i]));
      log_max.push_back(std::log(maxima_[i]));
    }
    if (log_t.size() < 2) return;
    metrics["energy_growth_exponent"] = least_squares_slope(log_t, log_max);
  }

 private:
  static constexpr int kGrowthCheckpoints = 25;
  static constexpr double kGrowthDecades = 3;
  double energy0_ = 0, scale_ = 1, t0_ = 0, span_ = 0, running_max_ = 0;
  std::vector<double> checkpoints_, times_, maxima_;
  size_t next_ = 0;
};

bool requested(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// One step of a fresh integrator from `start`, as a vector (q, p); NaN entries when it fails.
Vec one_step(const std::string& method_spec, const Problem& problem, const State& start, double h) {
  const auto method = make_integrator(method_spec);
  State state = start;
  method->reset(problem, state, h);
  const long n = state.q.size();
  Vec out(2 * n);
  if (!method->step(problem, state, h).ok) return Vec::Constant(2 * n, kNaN);
  out << state.q, state.p;
  return out;
}

}  // namespace

const std::vector<std::string>& optional_metric_names() {
  static const std::vector<std::string> names = {"symplecticity_defect", "period_measured",
                                                 "energy_growth_exponent"};
  return names;
}

void check_optional_metrics(const std::vector<std::string>& names, const std::string& option) {
  for (const auto& name : names) {
    if (!requested(optional_metric_names(), name)) {
      throw InputError(fmt::format("{}: unknown metric '{}' (one of: {})", option, name,
                                   fmt::join(optional_metric_names(), ", ")));
    }
  }
}

bool symplecticity_defect_applies(const Integrator& method, const Problem& problem) {
  return !(method.info().flags & kAdaptive) && !problem.has(kForce) && !problem.has(kConstraints);
}

double symplecticity_defect(const std::string& method_spec, const Problem& problem,
                            const State& state, double h) {
  const long n = state.q.size();
  // ε^{1/3}: balances the O(δ²) truncation and O(ε/δ) rounding of a central difference.
  const double root = std::cbrt(std::numeric_limits<double>::epsilon());
  const double q_scale =
      state.q.lpNorm<Eigen::Infinity>() > 0 ? state.q.lpNorm<Eigen::Infinity>() : 1.0;
  const double p_scale =
      state.p.lpNorm<Eigen::Infinity>() > 0 ? state.p.lpNorm<Eigen::Infinity>() : 1.0;
  Eigen::MatrixXd jacobian(2 * n, 2 * n);
  for (long j = 0; j < 2 * n; ++j) {
    const double delta = root * (j < n ? q_scale : p_scale);
    State plus = state, minus = state;
    if (j < n) {
      plus.q[j] += delta, minus.q[j] -= delta;
    } else {
      plus.p[j - n] += delta, minus.p[j - n] -= delta;
    }
    // The actual perturbation after rounding, so the quotient divides by what was added.
    const double step = j < n ? plus.q[j] - minus.q[j] : plus.p[j - n] - minus.p[j - n];
    jacobian.col(j) =
        (one_step(method_spec, problem, plus, h) - one_step(method_spec, problem, minus, h)) / step;
  }
  if (!jacobian.allFinite()) return kNaN;
  Eigen::MatrixXd form = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  form.topRightCorner(n, n) = Eigen::MatrixXd::Identity(n, n);
  form.bottomLeftCorner(n, n) = -Eigen::MatrixXd::Identity(n, n);
  const double size = jacobian.cwiseAbs().maxCoeff();
  return (jacobian.transpose() * form * jacobian - form).cwiseAbs().maxCoeff() /
         std::max(1.0, size * size);
}

std::vector<std::unique_ptr<Observer>> make_optional_observers(
    const Problem& problem, const std::vector<std::string>& names) {
  std::vector<std::unique_ptr<Observer>> observers;
  if (requested(names, "period_measured") && !problem.has(kForce) && problem.dof() >= 1) {
    observers.push_back(std::make_unique<ZeroCrossingPeriodObserver>());
  }
  if (requested(names, "energy_growth_exponent") && !problem.has(kForce)) {
    observers.push_back(std::make_unique<EnergyGrowthObserver>());
  }
  return observers;
}

}  // namespace geomint
