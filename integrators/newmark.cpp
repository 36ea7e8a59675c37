// Newmark family (Kane, Marsden, Ortiz & West, IJNME 2000; docs/METHOD.md §1 and §7):
//   q₁ = q₀ + h v₀ + h²[(½−β)a₀ + βa₁],   v₁ = v₀ + h[(1−γ)a₀ + γa₁],   M a = −∇V(q) + F(q, v, t).
// β = 0, γ = ½ is Störmer–Verlet; β > 0 is symplectic only for a non-canonical form (not declared).
#include <fmt/format.h>

#include <cmath>
#include <optional>

#include "integrators/forcing.hpp"
#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"

namespace geomint {
namespace {

// Unknown a₁, residual in momentum units so the relative tolerance means what it means for the
// variational integrators:
//   R(a₁) = h[M a₁ + ∇V(q₁(a₁)) − F(q₁, v₁(a₁), t + h)],
//   ∂R/∂a₁ = h[M + βh²∇²V(q₁) + γh C(q₁, v₁)],   C = −∂F/∂v
// (the βh² ∂F/∂q part is left out, as in implicit_euler: only the Newton matrix is approximate;
// without force_jacobian_v the force's a₁-derivative is differenced). Start a₁ = a₀.
//
// Symmetry (γ = ½, forces depending on q only): the step with −h from (q₁, v₁) reproduces
// (q₀, v₀) — substituting q₁, v₁ into the −h formulas gives back q₀ and v₀ with a₀ = a(q₀) —
// so kSymmetric is declared for γ = ½ and verified by the registry's reversibility test.
//
// a₀ is cached between steps (first same as last: a₁ of one step is a₀ of the next). The cache is
// used only when the incoming (t, q, p) is bitwise the state it was computed for and the problem
// is the same object, so a caller that edits the state between steps gets a fresh a₀.
class Newmark final : public Integrator {
 public:
  Newmark(double beta, double gamma, const NewtonOptions& newton)
      : beta_(beta), gamma_(gamma), newton_(newton) {
    newton_.options().polish = true;  // invariants to round-off, not to the tolerance
  }

  MethodInfo info() const override {
    const bool second_order = gamma_ == 0.5;
    unsigned flags = 0;
    if (beta_ == 0.0) {
      flags = kExplicit;
      if (second_order) flags |= kSymplectic | kSymmetric | kVariational;  // Störmer–Verlet
    } else {
      flags = kImplicit | kNeedsHessian;
      if (second_order) flags |= kSymmetric;
    }
    return {"newmark", second_order ? 2 : 1, flags,
            "Newmark, Kane-Marsden-Ortiz-West IJNME 2000; docs/METHOD.md §1, §7"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    // Undamped Newmark on ẍ = −ω²x (Hughes 2000, §9.1.2): unconditionally stable for
    // 2β ≥ γ ≥ ½, otherwise for γ ≥ ½ stable iff hω < 1/√(γ/2 − β); γ < ½ amplifies every mode.
    if (gamma_ < 0.5) return StabilityPrediction::limit(0.0);
    if (2 * beta_ >= gamma_) return StabilityPrediction::unconditional();
    return StabilityPrediction::limit(1.0 / std::sqrt(gamma_ / 2 - beta_));
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    newton_.forget_pattern();
    damping_symmetric_.reset();
    acceleration(problem, state, a0_);
    remember(problem, state);
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    const Vec& mass = problem.mass();
    const Vec& inverse_mass = problem.inverse_mass();
    update_sparse_mass_matrix(problem, mass_diagonal_, mass_matrix_);
    const bool cache_hit = cached_problem_ == &problem && cached_t_ == state.t &&
                           cached_q_.size() == state.q.size() && cached_q_ == state.q &&
                           cached_p_ == state.p;
    if (!cache_hit) acceleration(problem, state, a0_);

    const bool forced = problem.has(kForce);
    const double t1 = state.t + h;
    const Vec v0 = inverse_mass.cwiseProduct(state.p);
    // The a₁-independent parts of q₁ and v₁.
    const Vec q_predict = state.q + h * v0 + (h * h * (0.5 - beta_)) * a0_;
    const Vec v_predict = v0 + (h * (1 - gamma_)) * a0_;

    Vec a1 = a0_;
    if (beta_ == 0.0 && !forced) {
      // Explicit: q₁ does not depend on a₁.
      eval_gradient(problem, q_predict, gradient_);
      a1 = -inverse_mass.cwiseProduct(gradient_);
    } else {
      if (forced)
        decide_damping_symmetry(problem, state.q, v0, state.t, damping_, damping_symmetric_);
      if (beta_ == 0.0) eval_gradient(problem, q_predict, gradient_);  // constant in a₁
      const auto total_force = [&](const Vec& a, Vec& f) {  // −∇V(q₁) + F(q₁, v₁, t₁)
        const Vec q1 = q_predict + (h * h * beta_) * a;
        if (beta_ != 0.0) eval_gradient(problem, q1, gradient_);
        f = -gradient_;
        if (forced) {
          ++counters_.force_evals;
          eval_force(problem, q1, v_predict + (h * gamma_) * a, t1, force_);
          f += force_;
        }
      };
      double inner_scale = 0.0;
      NewtonSystem system;
      system.inner_term_scale = [&] { return inner_scale; };
      system.residual = [&](const Vec& a, Vec& residual) {
        total_force(a, total_);
        residual = h * (mass.cwiseProduct(a) - total_);
      };
      system.jacobian = [&](const Vec& a, SparseMatrix& jacobian) {
        jacobian = mass_matrix_;
        const Vec q1 = q_predict + (h * h * beta_) * a;
        if (beta_ != 0.0) {
          eval_hessian(problem, q1, hessian_);
          inner_scale = std::abs(h) * gradient_term_scale(hessian_, q1);
          jacobian += (beta_ * h * h) * hessian_;
        }
        if (forced) {
          const Vec v1 = v_predict + (h * gamma_) * a;
          if (problem.has(kForceJacobian)) {
            problem.force_jacobian_v(q1, v1, t1, damping_);
            jacobian += (gamma_ * h) * damping_;
          } else {
            // −∂F(q₁(a), v₁(a))/∂a, differenced; divided by h since the jacobian is scaled below.
            jacobian -= central_difference_jacobian(
                [&](const Vec& x, Vec& f) {
                  eval_force(problem, q_predict + (h * h * beta_) * x, v_predict + (h * gamma_) * x,
                             t1, f);
                },
                a);
            counters_.force_evals += 2 * a.size();
          }
        }
        jacobian *= h;
      };
      system.symmetric = !forced || (problem.has(kForceJacobian) && *damping_symmetric_);
      // total_ holds the force at q₁(a₀) after the first residual: h‖M a‖ and h‖∇V‖ are the
      // terms R cancels, and for hω ≫ 1 the latter dominates ‖p‖ + h‖M a₀‖ by (hω)².
      system.scale_after_first_residual = [&] { return std::abs(h) * total_.norm(); };
      const double residual_scale = state.p.norm() + std::abs(h) * mass.cwiseProduct(a0_).norm();
      const NewtonResult result = newton_.solve(system, a1, residual_scale);
      counters_.newton_iters += result.iterations;
      counters_.linear_solves += result.linear_solves;
      counters_.factorizations += result.factorizations;
      if (!result.converged) {
        cached_problem_ = nullptr;
        return StepStatus::failure(result.reason, describe(result));
      }
    }

    state.q = q_predict + (h * h * beta_) * a1;
    state.p = mass.cwiseProduct(v_predict + (h * gamma_) * a1);
    state.t = t1;
    a0_ = a1;
    remember(problem, state);
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  // a = M⁻¹(−∇V(q) + F(q, M⁻¹p, t)).
  void acceleration(const Problem& problem, const State& state, Vec& a) {
    eval_total_force(problem, state.q, problem.inverse_mass().cwiseProduct(state.p), state.t, a);
    a = problem.inverse_mass().cwiseProduct(a);
  }

  void remember(const Problem& problem, const State& state) {
    cached_problem_ = &problem;
    cached_t_ = state.t;
    cached_q_ = state.q;
    cached_p_ = state.p;
  }

  double beta_;
  double gamma_;
  NewtonSolver newton_;
  Vec a0_;  // acceleration at the cached state
  const Problem* cached_problem_ = nullptr;
  double cached_t_ = 0.0;
  Vec cached_q_, cached_p_;
  Vec mass_diagonal_;
  SparseMatrix mass_matrix_, hessian_, damping_;
  std::optional<bool> damping_symmetric_;
  Vec gradient_, force_, total_;
};

}  // namespace

std::unique_ptr<Integrator> make_newmark(Params& params) {
  const double beta = params.real(
      "beta", 0.25, "position weight beta (0: explicit; 1/4: average acceleration)",
      [](double x) { return x >= 0.0 && x <= 0.5; }, "in [0, 0.5]");
  const double gamma = params.real(
      "gamma", 0.5, "velocity weight gamma (1/2: second order, no numerical damping)",
      [](double x) { return x >= 0.0 && x <= 1.0; }, "in [0, 1]");
  const NewtonOptions newton = read_newton_options(params, "|p| + h|M a0|");
  return std::make_unique<Newmark>(beta, gamma, newton);
}

}  // namespace geomint
