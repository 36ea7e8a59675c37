// Classical fourth-order Runge–Kutta on Hamilton's equations of the Lagrangian view,
// (q, p)' = (v(q, p), L_q(q, v) + F(q, v, t)) — on the separable kind v = M⁻¹p and
// L_q = −∇V(q) (Kutta 1901; Hairer, Nørsett & Wanner, "Solving ODEs I", §II.1, Table 1.2).
// Not symplectic: the negative control of docs/METHOD.md §7. On a first-order-only problem it is
// the same tableau on y' = f(t, y).
#include "integrators/fixed_step_loop.hpp"
#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"
#include "integrators/step_implementation.hpp"
#include "integrators/tangent.hpp"
#include "problems/mass_operator.hpp"
#include "problems/structures/time_dependent.hpp"

namespace geomint {
namespace {

class Rk4 final : public ExplicitStepper<Rk4> {
 public:
  MethodInfo info() const override {
    return {"rk4", 4, kExplicit | kFirstOrderCapable | kGeneralLagrangian,
            "classical Runge-Kutta, Hairer-Norsett-Wanner I §II.1"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(2.0 * std::sqrt(2.0));  // |R(iy)| ≤ 1 iff y ≤ 2√2 (GNI §VI.4)
  }

  // The same stages on the tangent: δK_i = (M⁻¹δP_i, −∇²V(Q_i)δQ_i) at the stage points Y_i.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    const TangentBlock start(problem.dof());
    TangentBlock stage = start, sum = start;
    Vec stage_q = state.q, stage_p = state.p, gradient;
    const double offsets[] = {h / 2, h / 2, h};  // Y_{i+1} = y + offsets[i]·K_i
    const double weights[] = {h / 6, h / 3, h / 3, h / 6};
    for (int i = 0; i < 4; ++i) {
      // K_i and δK_i at the stage point (stage_q, stage_p) with tangent `stage`.
      const Vec dq = inverse_mass.cwiseProduct(stage_p);
      problem.gradient(stage_q, gradient);
      const Eigen::MatrixXd dq_tangent = inverse_mass.asDiagonal() * stage.p;
      const Eigen::MatrixXd dp_tangent = -(dense_hessian(problem, stage_q) * stage.q);
      sum.q += weights[i] * dq_tangent;
      sum.p += weights[i] * dp_tangent;
      if (i == 3) break;
      stage_q = state.q + offsets[i] * dq;
      stage_p = state.p - offsets[i] * gradient;
      stage.q = start.q + offsets[i] * dq_tangent;
      stage.p = start.p + offsets[i] * dp_tangent;
    }
    tangent = sum.stacked();
    return step(problem, state, h);
  }

  // One step (ExplicitStepper runs it for step() and advance()): the one implementation for the
  // separable and the general Lagrangian kinds, which differ only in rhs().
  void advance_by(const Problem& problem, State& state, double h) {
    if (problem.has(kFirstOrderOnly)) {
      advance_first_order(problem, state, h);
      return;
    }
    mark_step_implementation();
    const double t = state.t;
    const Vec& q = state.q;
    const Vec& p = state.p;
    // Stage derivatives: dq_i = v(q_i, p_i), dp_i = total force at stage i. The stage points go
    // into stage_q_/stage_p_ so that no step allocates.
    rhs(problem, t, q, p, dq_[0], dp_[0]);
    stage_q_ = q + (h / 2) * dq_[0], stage_p_ = p + (h / 2) * dp_[0];
    rhs(problem, t + h / 2, stage_q_, stage_p_, dq_[1], dp_[1]);
    stage_q_ = q + (h / 2) * dq_[1], stage_p_ = p + (h / 2) * dp_[1];
    rhs(problem, t + h / 2, stage_q_, stage_p_, dq_[2], dp_[2]);
    stage_q_ = q + h * dq_[2], stage_p_ = p + h * dp_[2];
    rhs(problem, t + h, stage_q_, stage_p_, dq_[3], dp_[3]);
    state.q += (h / 6) * (dq_[0] + 2 * dq_[1] + 2 * dq_[2] + dq_[3]);
    state.p += (h / 6) * (dp_[0] + 2 * dp_[1] + 2 * dp_[2] + dp_[3]);
    state.t = t + h;
    ++counters_.steps;
  }

 private:
  // y = state.q (State::p is empty on these problems).
  void advance_first_order(const Problem& problem, State& state, double h) {
    const double t = state.t;
    const Vec& y = state.q;
    first_order(problem, t, y, dq_[0]);
    stage_q_ = y + (h / 2) * dq_[0];
    first_order(problem, t + h / 2, stage_q_, dq_[1]);
    stage_q_ = y + (h / 2) * dq_[1];
    first_order(problem, t + h / 2, stage_q_, dq_[2]);
    stage_q_ = y + h * dq_[2];
    first_order(problem, t + h, stage_q_, dq_[3]);
    state.q += (h / 6) * (dq_[0] + 2 * (dq_[1] + dq_[2]) + dq_[3]);
    state.t = t + h;
    ++counters_.steps;
  }

  void first_order(const Problem& problem, double t, const Vec& y, Vec& ydot) {
    ++counters_.force_evals;
    problem.first_order_rhs(t, y, ydot);
  }

  // Hamilton's equations of the Lagrangian view (docs/MECHANICS_GENERAL.md §1): dq = ∂H/∂p, the
  // velocity v(q, p) = M(q)⁻¹(p − a(q)) (M⁻¹p through the mass operator on the separable kind),
  // and dp = −∂H/∂q + F = L_q(q, v) + F(q, v, t) (−∇V(q) + F on the separable kind).
  void rhs(const Problem& problem, double t, const Vec& q, const Vec& p, Vec& dq, Vec& dp) {
    // A time-dependent H(q, p, t) has its own halves at t (q̇ = ∂T/∂p(p, t)), not M⁻¹p and −∇V.
    if (const auto* hamiltonian = problem.as<TimeDependentHamiltonian>()) {
      ++counters_.force_evals;
      hamiltonian->velocity(p, t, dq);
      hamiltonian->momentum_rate(q, p, t, dp);
      return;
    }
    if (const LagrangianSystem* general = problem.as_lagrangian()) {
      dq = general->velocity(q, p);
      ++counters_.force_evals;
      general->lagrangian_q(q, dq, dp);
      if (const NonConservativeForce* forced = problem.as_forced()) {
        forced->force(q, dq, t, force_);
        dp += force_;
      }
      return;
    }
    MassOperator(problem).solve(q, p, dq);
    eval_total_force(problem, q, dq, t, dp);
  }

  Vec dq_[4], dp_[4], stage_q_, stage_p_, force_;
};

}  // namespace

std::unique_ptr<Integrator> make_rk4(Params&) { return std::make_unique<Rk4>(); }

}  // namespace geomint
