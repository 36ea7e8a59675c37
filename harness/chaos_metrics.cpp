// Chaos indicators: Lyapunov exponent, MEGNO and valid time (harness/chaos_metrics.hpp).
#include "harness/chaos_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "harness/map_defect.hpp"
#include "harness/metrics.hpp"
#include "harness/run_spec.hpp"
#include "harness/structure_metrics.hpp"
#include "integrators/newton.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A fixed, generic initial direction: a tangent vector along a symmetry (the flow, a conserved
// momentum) would not see the shear that makes MEGNO 2 on a torus, so no component is zero and
// none is favoured.
Vec initial_direction(long size) {
  Vec w(size);
  for (long i = 0; i < size; ++i) w[i] = 1.0 + 0.5 * std::sin(1.7 * static_cast<double>(i) + 0.3);
  return w / w.norm();
}

class ChaosObserver : public Observer {
 public:
  ChaosObserver(std::unique_ptr<Integrator> method, ChaosTangent kind)
      : method_(std::move(method)), kind_(kind) {}
  void begin(const Problem&, const State& state, double) override {
    previous_ = state;
    w_ = initial_direction(2 * state.q.size());
    sums_.start(state.t);
  }
  void observe(const Problem& problem, const State& state) override {
    if (failed_) return;
    const double h = state.t - previous_.t;
    if (!(h > 0)) return;
    Vec next;
    if (!propagate(problem, previous_, h, next)) {
      failed_ = true;
      return;
    }
    // |w| = 1 on entry, so the log of the new norm is this step's growth; renormalising keeps w
    // finite however fast it grows.
    const double growth = next.norm();
    if (!(growth > 0) || !std::isfinite(growth)) {
      failed_ = true;
      return;
    }
    sums_.add_step(previous_.t, state.t, std::log(growth));
    w_ = next / growth;
    previous_ = state;
  }
  void finish(std::map<std::string, double>& metrics) const override {
    const bool ok = !failed_ && sums_.steps() > 0;
    metrics[metric::lyapunov_max.key()] = ok ? sums_.lyapunov() : kNaN;
    metrics[metric::megno.key()] = ok ? sums_.megno_mean() : kNaN;
    metrics[metric::megno_final.key()] = ok ? sums_.megno_instant() : kNaN;
    metrics[metric::chaos_tangent_fd.key()] = kind_ == ChaosTangent::kFiniteDifference ? 1 : 0;
  }

 private:
  // next = DΦ_h(from) w_, exactly or by central differences of the computed map.
  bool propagate(const Problem& problem, const State& from, double h, Vec& next) {
    const long n = from.q.size();
    if (kind_ == ChaosTangent::kLinearisedStep) {
      State start = from;
      method_->reset(problem, start, h);
      if (!method_->step_tangent(problem, start, h, tangent_).ok) return false;
      next = tangent_ * w_;
      return next.allFinite();
    }
    const double size = robust_norm(from.q, from.p);
    const double epsilon =
        kChaosFiniteDifferenceStep * (size > 0 && std::isfinite(size) ? size : 1.0);
    State plus = from, minus = from;
    plus.q += epsilon * w_.head(n);
    plus.p += epsilon * w_.tail(n);
    minus.q -= epsilon * w_.head(n);
    minus.p -= epsilon * w_.tail(n);
    if (!computed_step(*method_, problem, plus, h) || !computed_step(*method_, problem, minus, h)) {
      return false;
    }
    next.resize(2 * n);
    next.head(n) = (plus.q - minus.q) / (2 * epsilon);
    next.tail(n) = (plus.p - minus.p) / (2 * epsilon);
    return next.allFinite();
  }

  std::unique_ptr<Integrator> method_;
  ChaosTangent kind_;
  State previous_;
  Vec w_;
  Eigen::MatrixXd tangent_;
  ChaosSums sums_;
  bool failed_ = false;
};

class ValidTimeObserver : public Observer {
 public:
  explicit ValidTimeObserver(std::shared_ptr<const ReferenceSolution> reference)
      : reference_(std::move(reference)) {}
  void begin(const Problem&, const State& state, double) override {
    t0_ = state.t;
    t_last_ = state.t;
  }
  void observe(const Problem& problem, const State& state) override {
    if (found_) return;
    State truth;
    if (reference_) {
      const int row = reference_->row_at(state.t);
      if (row < 0) return;
      truth = State{state.t, reference_->q[row], reference_->p[row]};
    } else {
      truth = problem.exact(state.t);
    }
    const double scale = robust_norm(truth.q, truth.p);
    const double error =
        robust_norm(state.q - truth.q, state.p - truth.p) / (scale > 0 ? scale : 1);
    t_last_ = state.t;
    // NaN (a blown-up state) counts as reaching the threshold.
    if (!(error < kValidTimeErrorThreshold)) found_ = true;
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::valid_time.key()] = t_last_ - t0_;
    metrics[metric::valid_time_reached.key()] = found_ ? 1 : 0;
  }

 private:
  std::shared_ptr<const ReferenceSolution> reference_;
  double t0_ = 0, t_last_ = 0;
  bool found_ = false;
};

}  // namespace

void ChaosSums::start(double t0) {
  *this = ChaosSums{};
  t0_ = t0;
  t_ = t0;
}

void ChaosSums::add_step(double t_prev, double t, double log_growth) {
  const double elapsed = t - t0_;
  log_sum_ += log_growth;
  weighted_sum_ += (0.5 * (t_prev + t) - t0_) * log_growth;
  const double y = 2 * weighted_sum_ / elapsed;
  y_integral_ += 0.5 * (t - t_prev) * (y_ + y);
  y_ = y;
  t_ = t;
  ++steps_;
}

double ChaosSums::lyapunov() const { return log_sum_ / (t_ - t0_); }
double ChaosSums::megno_instant() const { return y_; }
double ChaosSums::megno_mean() const { return y_integral_ / (t_ - t0_); }

ChaosTangent chaos_tangent(const Integrator& method, const Problem& problem) {
  if (symplecticity_defect_not_applicable(method, problem).empty()) {
    return ChaosTangent::kLinearisedStep;
  }
  // The finite-difference tangent needs the computed map with a step; 1 stands for any h > 0.
  if (map_defect_not_applicable(method, problem, 1.0).empty()) {
    return ChaosTangent::kFiniteDifference;
  }
  return ChaosTangent::kNone;
}

std::string chaos_tangent_not_applicable(const Integrator& method, const Problem& problem) {
  if (chaos_tangent(method, problem) != ChaosTangent::kNone) return "";
  return map_defect_not_applicable(method, problem, 1.0);
}

std::unique_ptr<Observer> make_chaos_observer(const MethodFactory& method, const Problem& problem,
                                              const std::vector<std::string>& names) {
  if (!requested(names, metric::lyapunov_max) && !requested(names, metric::megno)) return nullptr;
  return make_chaos_observer(method, problem, names, chaos_tangent(method.prototype(), problem));
}

std::unique_ptr<Observer> make_chaos_observer(const MethodFactory& factory, const Problem& problem,
                                              const std::vector<std::string>& names,
                                              ChaosTangent kind) {
  if (!requested(names, metric::lyapunov_max) && !requested(names, metric::megno)) return nullptr;
  auto method = factory.make();
  const bool usable = (kind == ChaosTangent::kLinearisedStep &&
                       symplecticity_defect_not_applicable(*method, problem).empty()) ||
                      (kind == ChaosTangent::kFiniteDifference &&
                       map_defect_not_applicable(*method, problem, 1.0).empty());
  if (!usable) return nullptr;
  return std::make_unique<ChaosObserver>(std::move(method), kind);
}

std::unique_ptr<Observer> make_valid_time_observer(
    const Problem& problem, std::shared_ptr<const ReferenceSolution> reference,
    const std::vector<std::string>& names) {
  if (!requested(names, metric::valid_time)) return nullptr;
  if (problem.has(kExact)) reference = nullptr;
  if (!problem.has(kExact) && !reference) return nullptr;
  return std::make_unique<ValidTimeObserver>(std::move(reference));
}

void add_chaos_observer(const ObserverContext& context, ObserverList& observers) {
  if (context.method == nullptr) return;
  if (auto observer = make_chaos_observer(*context.method, context.problem, context.metrics)) {
    observers.push_back(std::move(observer));
  }
}

// Against the exact solution where there is one, else against a loaded reference.
void add_valid_time_observer(const ObserverContext& context, ObserverList& observers) {
  const Problem& problem = context.problem;
  std::shared_ptr<const ReferenceSolution> reference =
      problem.has(kExact) ? nullptr : context.reference;
  if (!problem.has(kExact) && !reference) return;
  if (auto observer = make_valid_time_observer(problem, reference, context.metrics)) {
    observers.push_back(std::move(observer));
  }
}

}  // namespace geomint
