// The black-box symplecticity defect of the computed one-step map (harness/map_defect.hpp).
#include "harness/map_defect.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "harness/metrics.hpp"
#include "harness/run_spec.hpp"
#include "integrators/constrained_step.hpp"
#include "problems/lagrangian.hpp"
#include "problems/mass_operator.hpp"
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

// The velocity q̇ at (q, p) by the problem's kind: M⁻¹p with a constant mass, ∂H/∂p = v(q, p) of
// the LagrangianSystem on the general kind (which has no constant mass).
Vec velocity_of(const Problem& problem, const Vec& q, const Vec& p) {
  if (const LagrangianSystem* general = problem.as_lagrangian()) return general->velocity(q, p);
  return MassOperator(problem).solve(q, p);
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

}  // namespace

std::string map_defect_not_applicable(const Integrator& method, const Problem& problem, double h) {
  if (problem.has(kFirstOrderOnly)) return "first-order problem: no canonical (q, p) pair";
  if (problem.has(kForce)) return "forced problem: the step is not a Hamiltonian map";
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

StepStatus computed_step_status(Integrator& method, const Problem& problem, State& state,
                                double h) {
  method.reset(problem, state, h);
  if (method.info().flags & kAdaptive) {
    const double t_stop = state.t + h;
    while (state.t < t_stop) {
      StepStatus status = method.adaptive_step(problem, state, t_stop);
      if (!status.ok) return status;
    }
  } else {
    StepStatus status = method.step(problem, state, h);
    if (!status.ok) return status;
  }
  if (!state.q.allFinite() || !state.p.allFinite()) {
    return StepStatus::failure("nan", "non-finite state after the step");
  }
  return StepStatus::success();
}

bool computed_step(Integrator& method, const Problem& problem, State& state, double h) {
  return computed_step_status(method, problem, state, h).ok;
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
  const double q_scale =
      block_scale(state.q, h * velocity_of(problem, state.q, state.p).cwiseAbs().maxCoeff());
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

namespace {

// G(q) at time t, dense (m × n); the time-free call on time-free problems.
Eigen::MatrixXd dense_constraint_jacobian(const Problem& problem, double t, const Vec& q) {
  const HolonomicConstraints& constraints = constraints_of(problem);
  SparseMatrix G;
  if (constraints.time_dependent()) {
    constraints.constraint_jacobian_at(t, q, G);
  } else {
    constraints.constraint_jacobian(q, G);
  }
  return Eigen::MatrixXd(G);
}

// A smooth projection P onto T*Q_c = {g(q) = 0, G(q)M⁻¹p (+ ∂g/∂t) = 0} at time t: q moves along
// M⁻¹G(q̃)ᵀν from the perturbed q̃ (Newton on ν until g is at round-off, then three more
// corrections so that the result does not depend on where the iteration stopped), p is then
// projected M⁻¹-orthogonally onto the tangent space at the new q. P is the identity on the
// manifold, so DP·u = u for every tangent vector u: it is only the chart's way back. False when
// the Newton iteration does not reach round-off.
bool project_onto_manifold(const Problem& problem, State& state) {
  const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
  const HolonomicConstraints& constraints = constraints_of(problem);
  const Eigen::MatrixXd direction =
      inverse_mass.asDiagonal() * dense_constraint_jacobian(problem, state.t, state.q).transpose();
  Vec residual;
  int polish = 0;
  for (int iteration = 0; iteration < 30 && polish < 3; ++iteration) {
    if (constraints.time_dependent()) {
      constraints.constraint_at(state.t, state.q, residual);
    } else {
      constraints.constraint(state.q, residual);
    }
    const Eigen::MatrixXd G = dense_constraint_jacobian(problem, state.t, state.q);
    if (!residual.allFinite() || !G.allFinite()) return false;
    const double round_off = 8 * std::numeric_limits<double>::epsilon() *
                             G.cwiseAbs().rowwise().sum().maxCoeff() *
                             state.q.lpNorm<Eigen::Infinity>();
    if (residual.size() == 0) {
      polish = 1;
      break;
    }
    if (residual.lpNorm<Eigen::Infinity>() <= round_off) ++polish;
    state.q -= direction * (G * direction).partialPivLu().solve(residual);
  }
  if (polish == 0 || !state.q.allFinite()) return false;
  project_momentum_to_tangent_space(problem, state.t, state.q, state.p);
  return state.p.allFinite();
}

// The chart directions v at a state of T*Q_c (2n × 2k, k = n − m): (T, 0) and (0, M T (TᵀMT)⁻¹),
// T an orthonormal basis of ker G(q). The p directions are tangent already (they lie in ker GM⁻¹);
// P adds to each q direction its hidden-constraint momentum correction, which lies in range Gᵀ ⟂ T.
// So UᵀΩU is the canonical form of R^{2k}: ω((Ta, c), (0, MT(TᵀMT)⁻¹b)) = aᵀb.
Eigen::MatrixXd chart_directions(const Problem& problem, const State& state) {
  const long n = state.q.size();
  const Eigen::MatrixXd G = dense_constraint_jacobian(problem, state.t, state.q);
  const long m = G.rows();
  const Eigen::MatrixXd basis = Eigen::HouseholderQR<Eigen::MatrixXd>(G.transpose()).householderQ();
  const Eigen::MatrixXd tangent = basis.rightCols(n - m);
  const Eigen::MatrixXd mass_tangent =
      MassOperator(problem).constant_inverse_diagonal().cwiseInverse().asDiagonal() * tangent;
  const Eigen::MatrixXd dual = mass_tangent * (tangent.transpose() * mass_tangent).inverse();
  Eigen::MatrixXd directions = Eigen::MatrixXd::Zero(2 * n, 2 * (n - m));
  directions.topLeftCorner(n, n - m) = tangent;
  directions.bottomRightCorner(n, n - m) = dual;
  return directions;
}

}  // namespace

ManifoldMap computed_manifold_map(Integrator& method, const Problem& problem, const State& state,
                                  double h) {
  const long n = state.q.size();
  Vec gradient;
  problem.gradient(state.q, gradient);
  const double q_scale =
      block_scale(state.q, h * velocity_of(problem, state.q, state.p).cwiseAbs().maxCoeff());
  const double p_scale = block_scale(state.p, h * gradient.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd directions = chart_directions(problem, state);
  const long k = directions.cols() / 2;
  // Each column stacks the difference of the projected starts (a tangent vector u) over the
  // difference of their images (J u): one Richardson pipeline for both.
  const int levels = static_cast<int>(std::log2(kMapDefectRelativeSteps.front() /
                                                kMapDefectRelativeSteps.back())) +
                     3;
  std::vector<Eigen::MatrixXd> differences(levels, Eigen::MatrixXd(4 * n, 2 * k));
  for (long j = 0; j < 2 * k; ++j) {
    const double step = kMapDefectRelativeSteps.front() * (j < k ? q_scale : p_scale);
    for (int level = 0; level < levels; ++level) {
      const double epsilon = std::ldexp(step, -level);
      State plus = state, minus = state;
      plus.q += epsilon * directions.col(j).head(n);
      plus.p += epsilon * directions.col(j).tail(n);
      minus.q -= epsilon * directions.col(j).head(n);
      minus.p -= epsilon * directions.col(j).tail(n);
      if (!project_onto_manifold(problem, plus) || !project_onto_manifold(problem, minus)) {
        ManifoldMap failed;
        failed.failure = "a perturbed start could not be projected onto the constraint manifold";
        return failed;
      }
      auto column = differences[level].col(j);
      column.segment(0, n) = (plus.q - minus.q) / (2 * epsilon);
      column.segment(n, n) = (plus.p - minus.p) / (2 * epsilon);
      for (State* start : {&plus, &minus}) {
        const StepStatus status = computed_step_status(method, problem, *start, h);
        if (!status.ok) {
          ManifoldMap failed;
          failed.failure = fmt::format("the step from a perturbed start failed: {} ({})",
                                       status.reason, status.message);
          return failed;
        }
      }
      column.segment(2 * n, n) = (plus.q - minus.q) / (2 * epsilon);
      column.segment(3 * n, n) = (plus.p - minus.p) / (2 * epsilon);
      if (!column.allFinite()) return {};
    }
  }
  ManifoldMap best;
  for (const double relative : kMapDefectRelativeSteps) {
    const int level =
        static_cast<int>(std::lround(std::log2(kMapDefectRelativeSteps.front() / relative)));
    const Eigen::MatrixXd coarse = (4 * differences[level + 1] - differences[level]) / 3;
    const Eigen::MatrixXd fine = (4 * differences[level + 2] - differences[level + 1]) / 3;
    const Eigen::MatrixXd error = fine - coarse;
    const double basis_error = error.topRows(2 * n).norm();
    const double image_error = error.bottomRows(2 * n).norm();
    // The δ whose errors move the defect least (first order: 2‖U‖‖E_U‖ + 2‖JU‖‖E_JU‖).
    const double weight =
        fine.topRows(2 * n).norm() * basis_error + fine.bottomRows(2 * n).norm() * image_error;
    if (best.tangent_basis.size() == 0 || weight < best.weight) {
      best.tangent_basis = fine.topRows(2 * n);
      best.image = fine.bottomRows(2 * n);
      best.basis_error = basis_error;
      best.image_error = image_error;
      best.relative_step = relative;
      best.weight = weight;
    }
  }
  return best;
}

MapDefect symplecticity_defect_map(const MethodFactory& factory, const Problem& problem,
                                   const State& state, double h) {
  const auto method = factory.make();
  return symplecticity_defect_map(*method, problem, state, h);
}

MapDefect symplecticity_defect_map(Integrator& method, const Problem& problem, const State& state,
                                   double h) {
  MapDefect out{kNaN, kNaN, kNaN, ""};
  if (!map_defect_not_applicable(method, problem, h).empty()) return out;
  if (problem.has(kConstraints)) {
    const ManifoldMap map = computed_manifold_map(method, problem, state, h);
    if (map.tangent_basis.size() == 0) {
      out.failure = map.failure;
      return out;
    }
    const long k = map.tangent_basis.cols() / 2;
    const Eigen::MatrixXd form = canonical_form(map.tangent_basis.rows() / 2);
    // The restricted form ω(u_i, u_j) on the chart's basis (canonical for an exact U).
    const Eigen::MatrixXd restricted = map.tangent_basis.transpose() * form * map.tangent_basis;
    const double restricted_norm = restricted.norm();
    const double basis_norm = map.tangent_basis.norm(), image_norm = map.image.norm();
    out.defect = (map.image.transpose() * form * map.image - restricted).norm() / restricted_norm;
    // The symplectic matrix of the chart, k = n − m: ‖J‖_F of the unconstrained case.
    out.jacobian_norm = image_norm * std::sqrt(2.0 * static_cast<double>(k)) / basis_norm;
    out.fd_error = (2 * basis_norm * map.basis_error + 2 * image_norm * map.image_error +
                    4 * std::numeric_limits<double>::epsilon() *
                        (basis_norm * basis_norm + image_norm * image_norm)) /
                   restricted_norm;
    return out;
  }
  const MapJacobian map = computed_map_jacobian(method, problem, state, h);
  if (map.jacobian.size() == 0) {
    out.failure = "the step from a perturbed start failed or was not finite";
    return out;
  }
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
        metrics[metric::symplecticity_defect_map.key()] = kNaN;
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
    metrics[metric::symplecticity_defect_map.key()] = defect;
    metrics[metric::symplecticity_defect_map_fd_err.key()] = error;
    // An adaptive solver's map over h is governed by its tolerance, not by h: no slope.
    if (!adaptive_ && defect > 10 * error && defect_half > 10 * error_half) {
      metrics[metric::symplecticity_defect_map_slope.key()] = std::log2(defect / defect_half);
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

std::unique_ptr<Observer> make_map_defect_observer(const MethodFactory& method,
                                                   const Problem& problem, double h,
                                                   const std::vector<std::string>& names) {
  if (!requested(names, metric::symplecticity_defect_map)) return nullptr;
  if (!map_defect_not_applicable(method.prototype(), problem, h).empty()) return nullptr;
  return std::make_unique<MapDefectObserver>(method, h, method.adaptive());
}

void add_map_defect_observer(const ObserverContext& context, ObserverList& observers) {
  if (context.method == nullptr) return;
  if (auto observer =
          make_map_defect_observer(*context.method, context.problem, context.dt, context.metrics)) {
    observers.push_back(std::move(observer));
  }
}

}  // namespace geomint
