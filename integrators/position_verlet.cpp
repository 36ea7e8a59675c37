// Position Verlet, drift–kick–drift: the Strang splitting of the exact flows of T = ½pᵀM⁻¹p and V
// (Hairer, Lubich & Wanner, GNI §I.1.4 and §II.5, eq. (5.5) with the roles of T and V swapped);
// the adjoint-ordered sibling of stormer_verlet (docs/METHOD.md §1).
#include "integrators/fixed_step_loop.hpp"
#include "integrators/integrator.hpp"
#include "integrators/tangent.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

//   q½ = q + (h/2) M⁻¹p
//   p⁺ = p + h [−∇V(q½) + F(q½, M⁻¹(p + p⁺)/2, t + h/2)]
//   q⁺ = q½ + (h/2) M⁻¹p⁺
// Without F it is a composition of exact flows that are each symplectic and equivariant under the
// problem's symmetries, in symmetric order: symplectic, symmetric, second order, and the momentum
// maps of those symmetries are kept exactly (discrete Noether; the map has a type-1 generating
// function L_d(q, q⁺) for small h, GNI §VI.5). A velocity-dependent force is taken at the mean
// velocity of the step, solved by fixed-point iteration (Integrator::solve_force_kick), which
// keeps second order; at the incoming velocity M⁻¹p, as before, it was first order (1.04 on the
// driven damped oscillator).
// One gradient per step: the kick point q½ is never reused, so there is no cache. ExplicitStepper
// runs the same body for step() and for advance()'s allocation-free grid loop.
class PositionVerlet final : public ExplicitStepper<PositionVerlet> {
 public:
  MethodInfo info() const override {
    return {"position_verlet", 2, kExplicit | kSymplectic | kSymmetric | kVariational,
            "position Verlet (drift-kick-drift), GNI §I.1.4, §II.5; docs/METHOD.md §1"};
  }

  // On q̈ = −ω²q the step matrix has trace 2 − (hω)², as for kick–drift–kick (GNI §I.5).
  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(2.0);
  }

  // Drift, kick with ∇²V(q½), drift.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    TangentBlock block(problem.dof());
    block.drift(MassOperator(problem).constant_inverse_diagonal(), h / 2);
    const Vec half_q = state.q + (h / 2) * MassOperator(problem).solve(state.q, state.p);
    block.kick(dense_hessian(problem, half_q), h);
    block.drift(MassOperator(problem).constant_inverse_diagonal(), h / 2);
    tangent = block.stacked();
    return step(problem, state, h);
  }

  StepStatus advance_by(const Problem& problem, State& state, double h) {
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    const bool forced = problem.has(kForce);
    if (forced) velocity_ = inverse_mass.cwiseProduct(state.p);  // the guess for v½
    state.q += (h / 2) * inverse_mass.cwiseProduct(state.p);
    eval_gradient(problem, state.q, gradient_);
    if (forced) {
      // v½ = M⁻¹(p + p⁺)/2 = M⁻¹(p − (h/2)∇V + (h/2)F(q½, v½, t½)).
      base_p_ = state.p - (h / 2) * gradient_;
      StepStatus status =
          solve_force_kick(problem, state.q, state.t + h / 2, base_p_, h / 2, velocity_, force_);
      if (!status.ok) return status;
    }
    state.p -= h * gradient_;
    if (forced) state.p += h * force_;
    state.q += (h / 2) * inverse_mass.cwiseProduct(state.p);
    state.t += h;
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  Vec gradient_, force_, velocity_, base_p_;
};

}  // namespace

std::unique_ptr<Integrator> make_position_verlet(Params&) {
  return std::make_unique<PositionVerlet>();
}

}  // namespace geomint
