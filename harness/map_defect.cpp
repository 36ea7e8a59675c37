// The black-box symplecticity defect of the computed one-step map (harness/map_defect.hpp).
#include "harness/map_defect.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "harness/run_spec.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Eigen::MatrixXd canonical_form(long n) {
  Eigen::MatrixXd form = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  form.topRightCorner(n, n) = Eigen::MatrixXd::Identity(n, n);
  form.bottomLeftCorner(n, n) = -Eigen::MatrixXd::Identity(n, n);
  return form;
}

// The scale a perturbation of a block is relative to: its own size, else the size the step gives
// it (h·M⁻¹p for q, h·∇V for p), else 1; so a state at rest or at the origin is still
// perturbed at the problem's own scale.
double block_scale(const Vec& block, double fallback) {
  const double own = block.size() ? block.cwiseAbs().maxCoeff() : 0.0;
  if (own > 0 && std::isfinite(own)) return own;
  if (fallback > 0 && std::isfinite(fallback)) return fallback;
  return 1.0;
}

// The central difference of the map at `state` in direction k with step δ; false on failure.
bool central_difference(Integrator& method, const Problem& problem, const State& state, double h,
                        long k, double step, Eigen::Ref<Eigen::VectorXd> column) {
  const long n = state.q.size();
  State plus = state, minus = state;
  if (k < n) {
    plus.q[k] += step;
    minus.q[k] -= step;
  } else {
    plus.p[k - n] += step;
    minus.p[k - n] -= step;
  }
  // The step actually represented in floating point, not the one asked for.
  const double actual = k < n ? plus.q[k] - minus.q[k] : plus.p[k - n] - minus.p[k - n];
  if (!computed_step(method, problem, plus, h) || !computed_step(method, problem, minus, h)) {
    return false;
  }
  column.head(n) = (plus.q - minus.q) / actual;
  column.tail(n) = (plus.p - minus.p) / actual;
  return column.allFinite();
}

bool requested(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

std::string map_defect_not_applicable(const Integrator& method, const Problem& problem, double h) {
  if (problem.has(kFirstOrderOnly)) return "first-order problem: no canonical (q, p) pair";
  if (problem.has(kForce)) return "forced problem: the step is not a Hamiltonian map";
  if (problem.has(kConstraints)) {
    return "constrained problem: the map acts on the constraint manifold (not measured yet)";
  }
  if (problem.dof() > kMaxMapDefectDof) {
    return fmt::format("{} degrees of freedom: more than the {} the 32n-step difference takes",
                       problem.dof(), kMaxMapDefectDof);
  }
  if (!(h > 0 && std::isfinite(h))) {
    return (method.info().flags & kAdaptive)
               ? "adaptive method: give --dt, the span of the map measured"
               : "no step h > 0";
  }
  return "";
}

bool computed_step(Integrator& method, const Problem& problem, State& state, double h) {
  method.reset(problem, state, h);
  if (method.info().flags & kAdaptive) {
    const double t_stop = state.t + h;
    while (state.t < t_stop) {
      if (!method.adaptive_step(problem, state, t_stop).ok) return false;
    }
  } else if (!method.step(problem, state, h).ok) {
    return false;
  }
  return state.q.allFinite() && state.p.allFinite();
}

double map_defect_of_jacobian(const Eigen::MatrixXd& jacobian) {
  if (!jacobian.allFinite()) return kNaN;
  const Eigen::MatrixXd form = canonical_form(jacobian.rows() / 2);
  return (jacobian.transpose() * form * jacobian - form).norm() / form.norm();
}

MapJacobian computed_map_jacobian(Integrator& method, const Problem& problem, const State& state,
                                  double h) {
  const long n = state.q.size();
  Vec gradient;
  problem.gradient(state.q, gradient);
  const double q_scale = block_scale(
      state.q, h * (problem.inverse_mass().cwiseProduct(state.p)).cwiseAbs().maxCoeff());
  const double p_scale = block_scale(state.p, h * gradient.cwiseAbs().maxCoeff());
  // D(δ/2^m) for m = 0 … levels−1, the coarsest δ the first of kMapDefectRelativeSteps, column
  // by column; every three consecutive levels give a J and its error estimate.
  const int levels = static_cast<int>(std::log2(kMapDefectRelativeSteps.front() /
                                                kMapDefectRelativeSteps.back())) +
                     3;
  std::vector<Eigen::MatrixXd> differences(levels, Eigen::MatrixXd(2 * n, 2 * n));
  for (long k = 0; k < 2 * n; ++k) {
    const double step = kMapDefectRelativeSteps.front() * (k < n ? q_scale : p_scale);
    for (int level = 0; level < levels; ++level) {
      if (!central_difference(method, problem, state, h, k, std::ldexp(step, -level),
                              differences[level].col(k))) {
        return {};
      }
    }
  }
  MapJacobian best;
  for (const double relative : kMapDefectRelativeSteps) {
    const int m =
        static_cast<int>(std::lround(std::log2(kMapDefectRelativeSteps.front() / relative)));
    const Eigen::MatrixXd coarse = (4 * differences[m + 1] - differences[m]) / 3;
    const Eigen::MatrixXd fine = (4 * differences[m + 2] - differences[m + 1]) / 3;
    const double error = (fine - coarse).norm();
    if (best.jacobian.size() == 0 || error < best.error) {
      best.jacobian = fine;
      best.error = error;
      best.relative_step = relative;
    }
  }
  return best;
}

MapDefect symplecticity_defect_map(const std::string& method_spec, const Problem& problem,
                                   const State& state, double h) {
  return symplecticity_defect_map(MethodFactory(method_spec), problem, state, h);
}

MapDefect symplecticity_defect_map(const MethodFactory& factory, const Problem& problem,
                                   const State& state, double h) {
  MapDefect out{kNaN, kNaN, kNaN};
  const auto method = factory.make();
  if (!map_defect_not_applicable(*method, problem, h).empty()) return out;
  const MapJacobian map = computed_map_jacobian(*method, problem, state, h);
  if (map.jacobian.size() == 0) return out;
  const double jacobian_norm = map.jacobian.norm();
  const double form_norm = std::sqrt(2.0 * static_cast<double>(state.q.size()));
  out.defect = map_defect_of_jacobian(map.jacobian);
  out.jacobian_norm = jacobian_norm;
  out.fd_error = (2 * jacobian_norm * map.error +
                  4 * std::numeric_limits<double>::epsilon() * jacobian_norm * jacobian_norm) /
                 form_norm;
  return out;
}

namespace {

// Samples the initial state, the first step point at or after half the horizon and the last one;
// the defects are computed in finish() from fresh integrators, so the run is not disturbed.
class MapDefectObserver : public Observer {
 public:
  MapDefectObserver(MethodFactory method, double h, bool adaptive)
      : method_(std::move(method)), h_(h), adaptive_(adaptive) {}
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
  void finish(std::map<std::string, double>& metrics) const override {
    std::vector<State> points = states_;
    if (has_last_ && last_.t > points.back().t) points.push_back(last_);
    double defect = 0, error = 0, defect_half = 0, error_half = 0;
    for (const State& state : points) {
      const MapDefect at_h = symplecticity_defect_map(method_, *problem_, state, h_);
      if (std::isnan(at_h.defect)) {
        metrics["symplecticity_defect_map"] = kNaN;
        return;
      }
      defect = std::max(defect, at_h.defect);
      error = std::max(error, at_h.fd_error);
      const MapDefect at_half = symplecticity_defect_map(method_, *problem_, state, h_ / 2);
      if (std::isnan(at_half.defect)) {
        defect_half = kNaN;
      } else if (!std::isnan(defect_half)) {
        defect_half = std::max(defect_half, at_half.defect);
        error_half = std::max(error_half, at_half.fd_error);
      }
    }
    metrics["symplecticity_defect_map"] = defect;
    metrics["symplecticity_defect_map_fd_err"] = error;
    // An adaptive solver's map over h is governed by its tolerance, not by h: no slope.
    if (!adaptive_ && defect > 10 * error && defect_half > 10 * error_half) {
      metrics["symplecticity_defect_map_slope"] = std::log2(defect / defect_half);
    }
  }

 private:
  MethodFactory method_;
  double h_;
  bool adaptive_;
  const Problem* problem_ = nullptr;
  std::vector<State> states_;
  State last_;
  bool has_last_ = false;
  double half_ = 0;
};

}  // namespace

std::unique_ptr<Observer> make_map_defect_observer(const std::string& method_spec,
                                                   const Problem& problem, double h,
                                                   const std::vector<std::string>& names) {
  if (!requested(names, "symplecticity_defect_map")) return nullptr;
  return make_map_defect_observer(MethodFactory(method_spec), problem, h, names);
}

std::unique_ptr<Observer> make_map_defect_observer(const MethodFactory& method,
                                                   const Problem& problem, double h,
                                                   const std::vector<std::string>& names) {
  if (!requested(names, "symplecticity_defect_map")) return nullptr;
  if (!map_defect_not_applicable(method.prototype(), problem, h).empty()) return nullptr;
  return std::make_unique<MapDefectObserver>(method, h, method.adaptive());
}

}  // namespace geomint
