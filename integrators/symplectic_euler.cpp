// Symplectic Euler, kick first (L_d = h L(q_k, v)) and drift first (L_d = h L(q_{k+1}, v)):
// docs/METHOD.md §1 table; Hairer, Lubich & Wanner, GNI §VI.3, Theorem 3.3 and its adjoint. Forces
// enter as discrete Lagrange–d'Alembert impulses h·F (docs/METHOD.md §2).
#include "integrators/fixed_step_loop.hpp"
#include "integrators/integrator.hpp"
#include "integrators/tangent.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// Kick then drift: p⁺ = p + h[−∇V(q) + F(q, v, t)], q⁺ = q + h M⁻¹p⁺. The force takes the
// velocity at the start of the step, v = M⁻¹p: the step velocity M⁻¹p⁺ would make a
// velocity-dependent force implicit, and the method is first order either way.
class SymplecticEulerA final : public ExplicitStepper<SymplecticEulerA> {
 public:
  MethodInfo info() const override {
    return {"symplectic_euler_a", 1, kExplicit | kSymplectic | kVariational,
            "symplectic Euler (kick first), GNI §VI.3 Thm 3.3; docs/METHOD.md §1"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(2.0);  // trace of the step matrix 2 − (hω)² (GNI §I.5)
  }

  // Kick with ∇²V(q), drift.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    TangentBlock block(problem.dof());
    block.kick(dense_hessian(problem, state.q), h);
    block.drift(MassOperator(problem).constant_inverse_diagonal(), h);
    tangent = block.stacked();
    return step(problem, state, h);
  }

  // Kick then drift (ExplicitStepper runs it for step() and advance()).
  void advance_by(const Problem& problem, State& state, double h) {
    const MassOperator mass(problem);
    mass.solve(state.q, state.p, velocity_);  // into the member: no allocation per step
    eval_total_force(problem, state.q, velocity_, state.t, force_);
    state.p += h * force_;
    mass.solve(state.q, state.p, velocity_);
    state.q += h * velocity_;
    state.t += h;
    ++counters_.steps;
  }

 private:
  Vec velocity_, force_;
};

// Drift then kick: q⁺ = q + h M⁻¹p, p⁺ = p + h[−∇V(q⁺) + F(q⁺, v, t + h)]. The force takes the
// drift velocity v = M⁻¹p = (q⁺ − q)/h, the discrete velocity of the step, so the impulse is
// the Lagrange–d'Alembert F_d⁺ = h F(q_{k+1}, v_{k,k+1}) and the scheme stays explicit.
class SymplecticEulerB final : public ExplicitStepper<SymplecticEulerB> {
 public:
  MethodInfo info() const override {
    return {"symplectic_euler_b", 1, kExplicit | kSymplectic | kVariational,
            "symplectic Euler (drift first), adjoint of GNI §VI.3 Thm 3.3; docs/METHOD.md §1"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(2.0);  // trace of the step matrix 2 − (hω)² (GNI §I.5)
  }

  // Drift, kick with ∇²V(q⁺).
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    TangentBlock block(problem.dof());
    block.drift(MassOperator(problem).constant_inverse_diagonal(), h);
    const StepStatus status = step(problem, state, h);
    block.kick(dense_hessian(problem, state.q), h);
    tangent = block.stacked();
    return status;
  }

  // Drift then kick (ExplicitStepper runs it for step() and advance()).
  void advance_by(const Problem& problem, State& state, double h) {
    MassOperator(problem).solve(state.q, state.p, velocity_);  // into the member: no allocation
    state.q += h * velocity_;
    state.t += h;
    eval_total_force(problem, state.q, velocity_, state.t, force_);
    state.p += h * force_;
    ++counters_.steps;
  }

 private:
  Vec velocity_, force_;
};

}  // namespace

std::unique_ptr<Integrator> make_symplectic_euler_a(Params&) {
  return std::make_unique<SymplecticEulerA>();
}

std::unique_ptr<Integrator> make_symplectic_euler_b(Params&) {
  return std::make_unique<SymplecticEulerB>();
}

}  // namespace geomint
