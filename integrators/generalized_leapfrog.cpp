// The generalized leapfrog, Störmer–Verlet for a non-separable H(q, p) (Hairer, Lubich & Wanner,
// GNI §VI.3, (VI.3.4)–(VI.3.6); ../shared/MECHANICS.md §4): symplectic, symmetric, order 2;
// implicit in p½ and q₁ unless H is separable, where it is Störmer–Verlet.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "integrators/dense_newton.hpp"
#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

double inf_norm(const Vec& x) { return dense_inf_norm(x); }

}  // namespace

// With H_q = −L_q(q, v(q, p)) and H_p = v(q, p) (the Hamiltonian view of LagrangianSystem):
//   1. p½ = p₀ + (h/2) L_q(q₀, v(q₀, p½))                    Newton, J = I − (h/2) ∂L_q/∂p
//   2. q₁ = q₀ + (h/2)[v(q₀, p½) + v(q₁, p½)]               Newton, J = I − (h/2) ∂v/∂q
//   3. p₁ = p½ + (h/2) L_q(q₁, v(q₁, p½))                    explicit
// Both Jacobians are blocks of hamiltonian_vector_field_jacobian and are not symmetric; each
// equation goes to dense_newton (integrators/dense_newton.hpp: partially pivoted LU, a polishing
// correction kept only if it lowers ‖R‖, since symplecticity holds for the exact solve). On
// a separable problem v = M⁻¹p and L_q = −∇V(q) do not couple, both solves are explicit, and the
// step is Störmer–Verlet's kick–drift–kick (the method computes it as such, no Hessian needed).
StepStatus general_leapfrog_step(const LagrangianSystem& system, State& state, double h,
                                 const GeneralNewtonSettings& newton, Counters& counters) {
  const long n = state.q.size();
  const Vec q0 = state.q;
  const Vec p0 = state.p;
  Vec L_q;
  DenseMatrix field_jacobian;
  // Both equations stop at ‖R‖∞ ≤ floor·(the size of R's terms), `scale` as of the last R.
  double scale = 0;
  const auto converged = [&](const Vec& residual, double floor) {
    return inf_norm(residual) <= floor * scale;
  };

  // 1. p½: R(P) = P − p₀ − (h/2) L_q(q₀, v(q₀, P)).
  Vec p_half = p0;
  const auto half_kick = [&](const Vec& q, const Vec& p) {
    system.lagrangian_q(q, system.velocity(q, p), L_q);
    ++counters.force_evals;
    return Vec((h / 2) * L_q);
  };
  DenseNewtonSystem kick_equation;
  kick_equation.residual = [&](const Vec& P, Vec& residual) {
    const Vec kick = half_kick(q0, P);
    scale = inf_norm(P) + inf_norm(p0) + inf_norm(kick);
    residual = P - p0 - kick;
  };
  kick_equation.converged = converged;
  kick_equation.jacobian = [&](const Vec& P, DenseMatrix& jacobian) {
    system.hamiltonian_vector_field_jacobian(q0, P, field_jacobian);
    jacobian = DenseMatrix::Identity(n, n) - (h / 2) * field_jacobian.bottomRightCorner(n, n);
  };
  kick_equation.method = "generalized_leapfrog";
  kick_equation.unknown = "p_half";
  StepStatus status = dense_newton(kick_equation, p_half, newton, counters);
  if (!status.ok) return status;

  // 2. q₁: R(Q) = Q − q₀ − (h/2)[v(q₀, p½) + v(Q, p½)].
  const Vec start_drift = (h / 2) * system.velocity(q0, p_half);
  Vec q1 = q0 + 2 * start_drift;
  DenseNewtonSystem drift_equation;
  drift_equation.residual = [&](const Vec& Q, Vec& residual) {
    const Vec end_drift = (h / 2) * system.velocity(Q, p_half);
    scale = inf_norm(Q) + inf_norm(q0) + inf_norm(start_drift) + inf_norm(end_drift);
    residual = Q - q0 - start_drift - end_drift;
  };
  drift_equation.converged = converged;
  drift_equation.jacobian = [&](const Vec& Q, DenseMatrix& jacobian) {
    system.hamiltonian_vector_field_jacobian(Q, p_half, field_jacobian);
    jacobian = DenseMatrix::Identity(n, n) - (h / 2) * field_jacobian.topLeftCorner(n, n);
  };
  drift_equation.method = "generalized_leapfrog";
  drift_equation.unknown = "q1";
  status = dense_newton(drift_equation, q1, newton, counters);
  if (!status.ok) return status;

  // 3. p₁ = p½ + (h/2) L_q(q₁, v(q₁, p½)).
  state.p = p_half + half_kick(q1, p_half);
  state.q = q1;
  state.t += h;
  ++counters.steps;
  if (!state.q.allFinite() || !state.p.allFinite()) {
    return StepStatus::failure("nan", "generalized_leapfrog: non-finite state");
  }
  return StepStatus::success();
}

namespace {

class GeneralizedLeapfrog final : public Integrator {
 public:
  explicit GeneralizedLeapfrog(const NewtonOptions& newton) : newton_(newton) {}

  MethodInfo info() const override {
    return {"generalized_leapfrog", 2,
            kImplicit | kSymplectic | kSymmetric | kConservativeOnly | kGeneralLagrangian,
            "generalized leapfrog (Störmer-Verlet for non-separable H), GNI §VI.3 (3.4)-(3.6)"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(2.0);  // Störmer–Verlet on the oscillator (GNI §I.5)
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    if (problem.kind() != ProblemKind::kLagrangian) return separable_step(problem, state, h);
    return general_leapfrog_step(*problem.as_lagrangian(), state, h,
                                 {newton_.tolerance, newton_.max_iterations}, counters_);
  }

 private:
  // Kick–drift–kick with ∇V and M⁻¹: the separable case of the three stages above.
  StepStatus separable_step(const Problem& problem, State& state, double h) {
    Vec gradient;
    problem.gradient(state.q, gradient);
    ++counters_.force_evals;
    state.p -= (h / 2) * gradient;
    state.q += h * MassOperator(problem).solve(state.q, state.p);
    problem.gradient(state.q, gradient);
    ++counters_.force_evals;
    state.p -= (h / 2) * gradient;
    state.t += h;
    ++counters_.steps;
    return StepStatus::success();
  }

  NewtonOptions newton_;
};

}  // namespace

std::unique_ptr<Integrator> make_generalized_leapfrog(Params& params) {
  const NewtonOptions newton = read_newton_options(params, "the terms of each stage's equation");
  return std::make_unique<GeneralizedLeapfrog>(newton);
}

}  // namespace geomint
