// Explicit (forward) and implicit (backward) Euler on M q̈ = −∇V(q) + F(q, q̇, t): the
// first-order, non-symplectic references of docs/METHOD.md §7 (Hairer, Nørsett & Wanner, "Solving
// ODEs I", §I.7; Hairer & Wanner, "Solving ODEs II", §IV.3).
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "integrators/forcing.hpp"
#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "integrators/tangent.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

class ExplicitEuler final : public Integrator {
 public:
  MethodInfo info() const override {
    return {"explicit_euler", 1, kExplicit,
            "forward Euler, Hairer-Norsett-Wanner Solving ODEs I §I.7; docs/METHOD.md §7"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(0.0);  // |1 + ihω| > 1 for every h > 0
  }

  // δq⁺ = δq + h M⁻¹δp, δp⁺ = δp − h∇²V(q)δq: both from the incoming tangent.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    TangentBlock block(problem.dof());
    const Eigen::MatrixXd start_q = block.q;
    block.drift(MassOperator(problem).constant_inverse_diagonal(), h);
    block.p -= h * (dense_hessian(problem, state.q) * start_q);
    tangent = block.stacked();
    return step(problem, state, h);
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    const Vec velocity = MassOperator(problem).solve(state.q, state.p);
    eval_total_force(problem, state.q, velocity, state.t, force_);
    state.q += h * velocity;
    state.p += h * force_;
    state.t += h;
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  Vec force_;
};

// Backward Euler for the unknown end velocity v⁺:
//   R(v⁺) = M v⁺ − p − h F_total(q + h v⁺, v⁺, t + h) = 0,  q⁺ = q + h v⁺,  p⁺ = M v⁺,
// solved by Newton with ∂R/∂v⁺ = M + h²∇²V(q⁺) − h d/dv⁺[F(q + h v⁺, v⁺, t + h)].
// The non-conservative part of that Jacobian:
//  - kForceJacobian: + h C(q⁺, v⁺) with C = −∂F/∂v; the h²∂F/∂q term is left out because
//    problems do not provide it. Only the Newton matrix is approximate (convergence may become
//    linear for position-dependent forces); the residual, hence the solution, is exact.
//  - kForce without kForceJacobian: the whole v⁺-derivative of F(q + h v⁺, v⁺, t + h) by central
//    differences, one column per unknown (2·dof force evaluations per Jacobian, dense): meant
//    for the small forced test problems; large forced problems should provide force_jacobian_v.
class ImplicitEuler final : public Integrator {
 public:
  explicit ImplicitEuler(const NewtonOptions& newton) : newton_(newton) {}

  MethodInfo info() const override {
    return {"implicit_euler", 1, kImplicit | kNeedsHessian | kFirstOrderCapable,
            "backward Euler, Hairer-Wanner Solving ODEs II §IV.3; docs/METHOD.md §7"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::unconditional();  // |1/(1 − ihω)| < 1 (A-stable)
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    newton_.forget_pattern();
    end_force_norm_ = std::numeric_limits<double>::quiet_NaN();
    damping_symmetric_.reset();
  }

  // At the converged v = M⁻¹p⁺, R = M v − p + h∇V(q + h v) gives (H = ∇²V(q⁺))
  //   (M + h²H) δv = δp − hH δq,   δq⁺ = δq + h δv,   δp⁺ = M δv.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    const StepStatus status = step(problem, state, h);
    if (!status.ok) return status;
    const int n = problem.dof();
    const Eigen::MatrixXd hessian = dense_hessian(problem, state.q);
    Eigen::MatrixXd matrix;
    MassOperator(problem).dense(state.q, matrix);
    matrix += h * h * hessian;
    Eigen::MatrixXd rhs(n, 2 * n);
    rhs << -h * hessian, Eigen::MatrixXd::Identity(n, n);
    const Eigen::MatrixXd dv = matrix.partialPivLu().solve(rhs);
    TangentBlock block(n);
    block.q += h * dv;
    block.p = MassOperator(problem).constant_diagonal().asDiagonal() * dv;
    tangent = block.stacked();
    return status;
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    if (problem.has(kFirstOrderOnly)) return step_first_order(problem, state, h);
    const Vec& mass = MassOperator(problem).constant_diagonal();
    const double t_next = state.t + h;
    update_sparse_mass_matrix(problem, mass_diagonal_, mass_matrix_);

    // Scale of the balanced terms for the relative residual test: ‖p‖ + h‖F‖ at the start of
    // the step. ‖F‖ at the end of the previous step is reused when the state was not changed
    // in between, which saves one force evaluation per step.
    if (!(std::isfinite(end_force_norm_) && end_q_.size() == state.q.size() && end_q_ == state.q)) {
      eval_total_force(problem, state.q, MassOperator(problem).solve(state.q, state.p), state.t,
                       force_);
      end_force_norm_ = robust_norm(force_);
    }
    const double residual_scale = robust_norm(state.p) + std::abs(h) * end_force_norm_;

    double latest_force_norm = 0.0, inner_scale = 0.0;
    NewtonSystem system;
    system.inner_term_scale = [&] { return inner_scale; };
    system.residual = [&](const Vec& v, Vec& residual) {
      q_next_ = state.q + h * v;
      eval_total_force(problem, q_next_, v, t_next, force_);
      latest_force_norm = robust_norm(force_);
      residual = mass.cwiseProduct(v) - state.p - h * force_;
    };
    system.jacobian = [&](const Vec& v, SparseMatrix& jacobian) {
      q_next_ = state.q + h * v;
      eval_hessian(problem, q_next_, hessian_);
      inner_scale = std::abs(h) * gradient_term_scale(hessian_, q_next_);
      jacobian = (h * h) * hessian_ + mass_matrix_;
      if (problem.has(kForce)) add_force_jacobian(problem, state.q, v, t_next, h, jacobian);
    };
    decide_damping_symmetry(problem, state.q, MassOperator(problem).solve(state.q, state.p),
                            state.t, damping_, damping_symmetric_);
    system.symmetric = !problem.has(kForce) || (problem.has(kForceJacobian) && *damping_symmetric_);

    Vec velocity = MassOperator(problem).solve(state.q, state.p);
    const NewtonResult result = newton_.solve(system, velocity, residual_scale);
    counters_.newton_iters += result.iterations;
    counters_.linear_solves += result.linear_solves;
    counters_.factorizations += result.factorizations;
    if (!result.converged) {
      end_force_norm_ = std::numeric_limits<double>::quiet_NaN();
      return StepStatus::failure(result.reason, describe(result));
    }

    // The last residual evaluation was at the accepted velocity, so its force is F at the new
    // state: reuse it for the next step's residual scale.
    state.q = state.q + h * velocity;
    state.p = mass.cwiseProduct(velocity);
    state.t = t_next;
    end_q_ = state.q;
    end_force_norm_ = latest_force_norm;
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  // Backward Euler on y' = f(t, y) (a first-order-only problem, y = state.q): Newton on
  // R(y⁺) = y⁺ − y − h f(t + h, y⁺) with ∂R/∂y⁺ = I − h ∂f/∂y (sparse LU), from y⁺ = y, the
  // residual relative to ‖y‖ + h‖f(t, y)‖.
  StepStatus step_first_order(const Problem& problem, State& state, double h) {
    const double t_next = state.t + h;
    const Vec& y = state.q;
    ++counters_.force_evals;
    problem.first_order_rhs(state.t, y, force_);
    const double residual_scale = robust_norm(y) + std::abs(h) * robust_norm(force_);
    NewtonSystem system;
    system.residual = [&](const Vec& x, Vec& residual) {
      ++counters_.force_evals;
      problem.first_order_rhs(t_next, x, force_);
      residual = x - y - h * force_;
    };
    system.jacobian = [&](const Vec& x, SparseMatrix& jacobian) {
      ++counters_.hessian_evals;
      problem.first_order_jacobian(t_next, x, hessian_);
      jacobian.resize(x.size(), x.size());
      jacobian.setIdentity();
      jacobian -= h * hessian_;
      jacobian.makeCompressed();
    };
    system.symmetric = false;
    Vec y_next = y;
    const NewtonResult result = newton_.solve(system, y_next, residual_scale);
    counters_.newton_iters += result.iterations;
    counters_.linear_solves += result.linear_solves;
    counters_.factorizations += result.factorizations;
    if (!result.converged) return StepStatus::failure(result.reason, describe(result));
    state.q = y_next;
    state.t = t_next;
    ++counters_.steps;
    return StepStatus::success();
  }

  void add_force_jacobian(const Problem& problem, const Vec& q_start, const Vec& v, double t_next,
                          double h, SparseMatrix& jacobian) {
    if (problem.has(kForceJacobian)) {
      force_of(problem).force_jacobian_v(q_next_, v, t_next, damping_);
      jacobian += h * damping_;
      return;
    }
    const int n = problem.dof();
    // Central differences with the step that balances truncation (δ²) and round-off (ε/δ).
    std::vector<Eigen::Triplet<double>> triplets;
    Vec v_shift = v, force_plus, force_minus;
    for (int j = 0; j < n; ++j) {
      const double delta = central_difference_step(v, j);
      v_shift[j] = v[j] + delta;
      q_shift_ = q_start + h * v_shift;
      eval_force(problem, q_shift_, v_shift, t_next, force_plus);
      v_shift[j] = v[j] - delta;
      q_shift_ = q_start + h * v_shift;
      eval_force(problem, q_shift_, v_shift, t_next, force_minus);
      v_shift[j] = v[j];
      for (int i = 0; i < n; ++i) {
        const double derivative = (force_plus[i] - force_minus[i]) / (2 * delta);
        if (derivative != 0.0) triplets.emplace_back(i, j, -h * derivative);
      }
    }
    // eval_force does not count; these are real force evaluations, so count them here.
    counters_.force_evals += 2L * n;
    SparseMatrix force_part(n, n);
    force_part.setFromTriplets(triplets.begin(), triplets.end());
    jacobian += force_part;
  }

  NewtonSolver newton_;
  Vec mass_diagonal_;
  SparseMatrix mass_matrix_, hessian_, damping_;
  std::optional<bool> damping_symmetric_;  // C = Cᵀ, decided on the first step of a run
  Vec force_, q_next_, q_shift_;
  Vec end_q_;
  double end_force_norm_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace

std::unique_ptr<Integrator> make_explicit_euler(Params&) {
  return std::make_unique<ExplicitEuler>();
}

std::unique_ptr<Integrator> make_implicit_euler(Params& params) {
  const NewtonOptions newton = read_newton_options(params, "‖p‖ + h‖F‖");
  return std::make_unique<ImplicitEuler>(newton);
}

}  // namespace geomint
