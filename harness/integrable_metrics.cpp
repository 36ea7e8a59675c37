// Observers of Flaschka's Toda invariants, the Kepler eccentricity vector and the loop action
// ∮p·dq of the computed one-step map (harness/integrable_metrics.hpp).
#include "harness/integrable_metrics.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <vector>

#include "harness/map_defect.hpp"
#include "harness/metrics.hpp"
#include "harness/run_spec.hpp"
#include "problems/problem.hpp"
#include "problems/structures/kepler_orbit.hpp"
#include "problems/structures/toda.hpp"

namespace geomint {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

class TodaInvariantsObserver : public Observer {
 public:
  explicit TodaInvariantsObserver(const TodaStructure& toda) : toda_(toda) {}
  void begin(const Problem&, const State& state, double) override {
    const Eigen::MatrixXd lax = toda_.lax_matrix(state.q, state.p);
    initial_ = flaschka_invariants(lax);
    const Vec magnitudes =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(lax, Eigen::EigenvaluesOnly)
            .eigenvalues()
            .cwiseAbs();
    scales_.resize(initial_.size());
    for (int k = 0; k < initial_.size(); ++k) {
      scales_[k] =
          std::max(magnitudes.array().pow(k + 1).sum(), std::numeric_limits<double>::min());
    }
  }
  void observe(const Problem&, const State& state) override {
    const Vec traces = flaschka_invariants(toda_.lax_matrix(state.q, state.p));
    // A NaN state makes the metric NaN (std::max would drop it).
    const double err = ((traces - initial_).cwiseAbs().cwiseQuotient(scales_)).maxCoeff();
    if (std::isnan(err) || std::isnan(err_max_)) {
      err_max_ = kNaN;
    } else {
      err_max_ = std::max(err_max_, err);
    }
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::toda_invariants_err_max.key()] = err_max_;
  }

 private:
  const TodaStructure& toda_;
  Vec initial_, scales_;
  double err_max_ = 0;
};

class LrlObserver : public Observer {
 public:
  explicit LrlObserver(const KeplerOrbitStructure& orbit) : orbit_(orbit) {}
  void begin(const Problem&, const State& state, double) override {
    initial_ = orbit_.eccentricity_vector(state.q, state.p);
  }
  void observe(const Problem&, const State& state) override {
    const double err = (orbit_.eccentricity_vector(state.q, state.p) - initial_).norm();
    if (std::isnan(err) || std::isnan(err_max_)) {
      err_max_ = kNaN;
    } else {
      err_max_ = std::max(err_max_, err);
    }
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::lrl_err_max.key()] = err_max_;
  }

 private:
  const KeplerOrbitStructure& orbit_;
  Eigen::Vector3d initial_;
  double err_max_ = 0;
};

// ∫₀^{2π} p·q′ dθ of the loop sampled at M equally spaced θ: with the discrete Fourier
// coefficients P_k, Q_k (k = 1 … M/2 − 1; the mean drops out, the Nyquist term is left out),
// 2π Σ_k −2k Im(conj(P_k)·Q_k).
double spectral_action(const std::vector<Vec>& q, const std::vector<Vec>& p) {
  const int points = static_cast<int>(q.size());
  const long n = q.front().size();
  std::vector<std::complex<double>> roots(points);
  for (int j = 0; j < points; ++j) {
    roots[j] = std::polar(1.0, -2 * std::numbers::pi * j / points);
  }
  double sum = 0;
  for (int k = 1; k < points / 2; ++k) {
    Eigen::VectorXcd q_hat = Eigen::VectorXcd::Zero(n), p_hat = Eigen::VectorXcd::Zero(n);
    for (int j = 0; j < points; ++j) {
      const std::complex<double> root = roots[(static_cast<long>(j) * k) % points];
      q_hat += root * q[j].cast<std::complex<double>>();
      p_hat += root * p[j].cast<std::complex<double>>();
    }
    sum += -2.0 * k * (p_hat.conjugate().cwiseProduct(q_hat)).sum().imag();
  }
  return 2 * std::numbers::pi * sum / (static_cast<double>(points) * points);
}

// ξ_i ∝ (−1)^i (1 + ½ sin(1.7(i + 1))), unit length: every degree of freedom in the loop, with
// different weights, so that a translation-invariant problem does not see a rigid shift.
Vec loop_direction(long n) {
  Vec xi(n);
  for (long i = 0; i < n; ++i) {
    xi[i] = (i % 2 == 0 ? 1.0 : -1.0) * (1 + 0.5 * std::sin(1.7 * static_cast<double>(i + 1)));
  }
  return xi / xi.norm();
}

constexpr double kLoopRadius = 1.0 / 32;

// Per-coordinate radii of the loop: kLoopRadius times |x_i|, at least a tenth of the block's
// largest entry (1 for a block at 0), so that an angle of many turns (polar Kepler's φ) does not
// set the radius of the radius r, and a coordinate at 0 still moves.
Vec loop_radii(const Vec& block) {
  double size = block.size() ? block.cwiseAbs().maxCoeff() : 0.0;
  if (!(size > 0 && std::isfinite(size))) size = 1.0;
  return kLoopRadius * block.cwiseAbs().cwiseMax(0.1 * size);
}

constexpr int kFirstLoopPoints = 16;
constexpr int kMaxLoopPoints = 2048;

class LoopActionObserver : public Observer {
 public:
  LoopActionObserver(MethodFactory method, double h) : method_(std::move(method)), h_(h) {}
  void begin(const Problem& problem, const State& state, double t_end) override {
    problem_ = &problem;
    states_ = {state};
    half_ = state.t + t_end / 2;
  }
  void observe(const Problem&, const State& state) override {
    if (!state.q.allFinite() || !state.p.allFinite()) return;
    if (states_.size() == 1 && state.t >= half_) states_.push_back(state);
    last_ = state;
    has_last_ = true;
  }
  // The largest error over the initial state, the first step point past t_end/2 and the last.
  void finish(std::map<std::string, double>& metrics) const override {
    std::vector<State> points = states_;
    if (has_last_ && last_.t > points.back().t) points.push_back(last_);
    double error = 0;
    int loop_points = 0;
    for (const State& state : points) {
      const LoopAction action = loop_action(method_, *problem_, state, h_);
      loop_points = std::max(loop_points, action.points);
      if (std::isnan(action.error)) {
        error = kNaN;
        break;
      }
      error = std::max(error, action.error);
    }
    metrics[metric::loop_action_err.key()] = error;
    metrics[metric::loop_action_points.key()] = loop_points;
  }

 private:
  MethodFactory method_;
  double h_;
  const Problem* problem_ = nullptr;
  std::vector<State> states_;
  double half_ = 0;
  State last_;
  bool has_last_ = false;
};

}  // namespace

LoopAction loop_action(const MethodFactory& method, const Problem& problem, const State& state,
                       double h) {
  LoopAction result;
  const long n = state.q.size();
  const Vec xi = loop_direction(n);
  const Vec radius_q = loop_radii(state.q).cwiseProduct(xi);
  const Vec radius_p = loop_radii(state.p).cwiseProduct(xi);
  auto integrator = method.make();
  std::vector<Vec> start_q, start_p, image_q, image_p;
  // Samples at θ_j = 2πj/M; doubling M keeps the old samples as the even ones.
  const auto sample = [&](int points, int j) -> bool {
    const double theta = 2 * std::numbers::pi * j / points;
    State point = state;
    point.q += std::cos(theta) * radius_q;
    point.p += std::sin(theta) * radius_p;
    start_q[j] = point.q;
    start_p[j] = point.p;
    const StepStatus status = computed_step_status(*integrator, problem, point, h);
    if (!status.ok) {
      result.failure = status.message;
      return false;
    }
    image_q[j] = point.q;
    image_p[j] = point.p;
    return true;
  };
  double previous = kNaN;
  double previous_refinement = std::numeric_limits<double>::infinity();
  for (int points = kFirstLoopPoints; points <= kMaxLoopPoints; points *= 2) {
    std::vector<Vec> old_q = image_q, old_p = image_p;
    start_q.assign(points, Vec());
    start_p.assign(points, Vec());
    image_q.assign(points, Vec());
    image_p.assign(points, Vec());
    for (int j = 0; j < points; ++j) {
      if (j % 2 == 0 && !old_q.empty()) {
        const double theta = 2 * std::numbers::pi * j / points;
        start_q[j] = state.q + std::cos(theta) * radius_q;
        start_p[j] = state.p + std::sin(theta) * radius_p;
        image_q[j] = old_q[j / 2];
        image_p[j] = old_p[j / 2];
      } else if (!sample(points, j)) {
        result.error = kNaN;
        result.points = points;
        return result;
      }
    }
    result.points = points;
    result.initial = spectral_action(start_q, start_p);
    result.image = spectral_action(image_q, image_p);
    const double change = std::abs(result.image - result.initial);
    result.error = change / std::abs(result.initial);
    if (!std::isfinite(result.error)) {
      result.error = kNaN;
      result.failure = "non-finite loop action";
      return result;
    }
    // Converged: the refinement changes I by less than 1e-14 of it or a thousandth of the
    // change measured, or no longer shrinks (the round-off of the sum is reached: a linear
    // problem's image is an ellipse, exact from the first M).
    const double refinement = std::abs(result.image - previous);
    if (!std::isnan(previous) &&
        (refinement <= std::max(1e-14 * std::abs(result.initial), 1e-3 * change) ||
         refinement >= 0.5 * previous_refinement)) {
      result.converged = true;
      return result;
    }
    if (!std::isnan(previous)) previous_refinement = refinement;
    previous = result.image;
  }
  return result;
}

LoopAction loop_action(const std::string& method_spec, const Problem& problem, const State& state,
                       double h) {
  return loop_action(MethodFactory(method_spec), problem, state, h);
}

std::string loop_action_not_applicable(const Integrator& method, const Problem& problem, double h) {
  std::string reason = map_defect_not_applicable(method, problem, h);
  if (reason.empty() && problem.has(kConstraints)) {
    reason = "constrained problem: the loop would leave the constraint manifold";
  }
  return reason;
}

void add_toda_invariants_observer(const ObserverContext& context, ObserverList& observers) {
  if (!requested(context.metrics, metric::toda_invariants_err_max)) return;
  const auto* toda = context.problem.as<TodaStructure>();
  if (toda == nullptr || context.problem.dof() > kMaxTodaInvariantParticles) return;
  observers.push_back(std::make_unique<TodaInvariantsObserver>(*toda));
}

void add_lrl_observer(const ObserverContext& context, ObserverList& observers) {
  if (!requested(context.metrics, metric::lrl_err_max)) return;
  if (const auto* orbit = context.problem.as<KeplerOrbitStructure>()) {
    observers.push_back(std::make_unique<LrlObserver>(*orbit));
  }
}

void add_loop_action_observer(const ObserverContext& context, ObserverList& observers) {
  if (!requested(context.metrics, metric::loop_action_err) || context.method == nullptr) return;
  const MethodFactory& method = *context.method;
  if (!loop_action_not_applicable(method.prototype(), context.problem, context.dt).empty()) return;
  observers.push_back(std::make_unique<LoopActionObserver>(method, context.dt));
}

}  // namespace geomint
