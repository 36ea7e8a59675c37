// Newmark family (Kane, Marsden, Ortiz & West, IJNME 2000; docs/METHOD.md §1 and §7) and its
// α-generalisations HHT (Hilber, Hughes & Taylor 1977) and generalized-α (Chung & Hulbert 1993):
//   q₁ = q₀ + h v₀ + h²[(½−β)a₀ + βa₁],   v₁ = v₀ + h[(1−γ)a₀ + γa₁],
//   M[(1−α_m)a₁ + α_m a₀] = (1−α_f) f(q₁, v₁, t₁) + α_f f(q₀, v₀, t₀),   f = −∇V(q) + F(q, v, t).
// α_m = α_f = 0 is Newmark (M a = f at every step point); β = 0, γ = ½ is Störmer–Verlet; β > 0 is
// symplectic only for a non-canonical form (not declared).
#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "integrators/forcing.hpp"
#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "integrators/tangent.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// Unknown a₁, residual in momentum units so the relative tolerance means what it means for the
// variational integrators:
//   R(a₁) = h[(1−α_m)M a₁ + α_m M a₀ − (1−α_f) f(q₁(a₁), v₁(a₁), t + h) − α_f f₀],
//   ∂R/∂a₁ = h[(1−α_m)M + (1−α_f)(βh²∇²V(q₁) + γh C(q₁, v₁))],   C = −∂F/∂v
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
//
// For HHT and generalized-α (α_m or α_f ≠ 0) a₁ is an algorithmic acceleration, not M⁻¹f(q₁):
// the method is a one-step map on (q, v, a), and State (t, q, p) does not carry a. The cache
// carries it between steps, as a multistep method carries its history; a start (reset, or an
// edited state) takes the consistent acceleration a₀ = M⁻¹f(q₀, v₀, t₀), the start Chung &
// Hulbert (1993, §2) and Hilber et al. analyse. Recomputing the consistent a₀ at every step
// instead would be a different two-term method whose high-frequency damping is not the
// requested ρ∞ (integrators/structural_alpha_test.cpp measures both, docs/METHODS.md
// "Structural-dynamics schemes"). At α_m = α_f (γ = ½: HHT α = 0, generalized-α ρ∞ = 1) a
// consistent start stays consistent, the scheme is Newmark's trapezoidal rule and kSymmetric is
// declared.
class Newmark final : public Integrator {
 public:
  // α-generalisation of Newmark (α_m = α_f = 0); `second_order` is the caller's γ = ½ − α_m + α_f,
  // decided where γ is computed so that no floating-point comparison decides the declared order.
  struct Alpha {
    std::string name = "newmark";
    double alpha_m = 0.0, alpha_f = 0.0;
    bool second_order = false;
    std::string reference = "Newmark, Kane-Marsden-Ortiz-West IJNME 2000; docs/METHOD.md §1, §7";
  };
  Newmark(double beta, double gamma, const NewtonOptions& newton, Alpha alpha)
      : beta_(beta), gamma_(gamma), newton_(newton), alpha_(std::move(alpha)) {
    newton_.options().polish = true;  // invariants to round-off, not to the tolerance
  }

  MethodInfo info() const override {
    const bool second_order = alpha_.second_order;
    unsigned flags = 0;
    if (beta_ == 0.0) {
      flags = kExplicit;
      if (second_order) flags |= kSymplectic | kSymmetric | kVariational;  // Störmer–Verlet
    } else {
      flags = kImplicit | kNeedsHessian;
      if (gamma_ == 0.5 && alpha_.alpha_m == alpha_.alpha_f) flags |= kSymmetric;
    }
    return {alpha_.name, second_order ? 2 : 1, flags, alpha_.reference};
  }

  StabilityPrediction predicted_linear_stability() const override {
    // Undamped Newmark on ẍ = −ω²x (Hughes 2000, §9.1.2): unconditionally stable for
    // 2β ≥ γ ≥ ½, otherwise for γ ≥ ½ stable iff hω < 1/√(γ/2 − β); γ < ½ amplifies every mode.
    // HHT (α ∈ [−⅓, 0]) and generalized-α (ρ∞ ∈ [0, 1]) are unconditionally stable (Hilber et al.
    // 1977; Chung & Hulbert 1993, §3): every parameter the factories accept is in that range.
    if (alpha_.alpha_m != 0.0 || alpha_.alpha_f != 0.0) return StabilityPrediction::unconditional();
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
    const Vec& mass = MassOperator(problem).constant_diagonal();
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    update_sparse_mass_matrix(problem, mass_diagonal_, mass_matrix_);
    const bool cache_hit = cached_problem_ == &problem && cached_t_ == state.t &&
                           cached_q_.size() == state.q.size() && cached_q_ == state.q &&
                           cached_p_ == state.p;
    if (!cache_hit) acceleration(problem, state, a0_);

    const bool forced = problem.has(kForce);
    const double t1 = state.t + h;
    const Vec v0 = inverse_mass.cwiseProduct(state.p);
    const double alpha_m = alpha_.alpha_m, alpha_f = alpha_.alpha_f;
    // The a₁-independent part of the balance: α_m M a₀ − α_f f₀.
    Vec old_balance = (alpha_m * mass).cwiseProduct(a0_);
    if (alpha_f != 0.0) {
      eval_total_force(problem, state.q, v0, state.t, total_);
      old_balance -= alpha_f * total_;
    }
    // The a₁-independent parts of q₁ and v₁.
    const Vec q_predict = state.q + h * v0 + (h * h * (0.5 - beta_)) * a0_;
    const Vec v_predict = v0 + (h * (1 - gamma_)) * a0_;

    Vec a1 = a0_;
    if (beta_ == 0.0 && !forced && alpha_m == 0.0 && alpha_f == 0.0) {
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
        residual =
            h * ((1 - alpha_m) * mass.cwiseProduct(a) - (1 - alpha_f) * total_ + old_balance);
      };
      system.jacobian = [&](const Vec& a, SparseMatrix& jacobian) {
        jacobian = ((1 - alpha_m) / (1 - alpha_f)) * mass_matrix_;
        const Vec q1 = q_predict + (h * h * beta_) * a;
        if (beta_ != 0.0) {
          eval_hessian(problem, q1, hessian_);
          inner_scale = std::abs(h) * (1 - alpha_f) * gradient_term_scale(hessian_, q1);
          jacobian += (beta_ * h * h) * hessian_;
        }
        if (forced) {
          const Vec v1 = v_predict + (h * gamma_) * a;
          if (problem.has(kForceJacobian)) {
            force_of(problem).force_jacobian_v(q1, v1, t1, damping_);
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
        jacobian *= h * (1 - alpha_f);
      };
      system.symmetric = !forced || (problem.has(kForceJacobian) && *damping_symmetric_);
      // total_ holds the force at q₁(a₀) after the first residual: h‖M a‖ and h‖∇V‖ are the
      // terms R cancels, and for hω ≫ 1 the latter dominates ‖p‖ + h‖M a₀‖ by (hω)².
      system.scale_after_first_residual = [&] { return std::abs(h) * robust_norm(total_); };
      const double residual_scale =
          robust_norm(state.p) + std::abs(h) * robust_norm(mass.cwiseProduct(a0_));
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

  // From the consistent start a₀ = −M⁻¹∇V(q₀) (as reset() takes it), with H₀, H₁ = ∇²V(q₀),
  // ∇²V(q₁):
  //   δa₀ = −M⁻¹H₀δq₀,  δq̃ = δq₀ + h δv₀ + h²(½−β)δa₀,  δṽ = δv₀ + h(1−γ)δa₀,
  //   [(1−α_m)M + (1−α_f)βh²H₁] δa₁ = −(1−α_f)H₁δq̃ − α_f H₀δq₀ − α_m M δa₀,
  //   δq₁ = δq̃ + βh²δa₁,  δp₁ = M(δṽ + γh δa₁).
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    const int n = problem.dof();
    const auto mass = MassOperator(problem).constant_diagonal().asDiagonal();
    const auto inverse_mass = MassOperator(problem).constant_inverse_diagonal().asDiagonal();
    const Eigen::MatrixXd start_hessian = dense_hessian(problem, state.q);
    cached_problem_ = nullptr;  // the consistent a₀, not a carried one
    const StepStatus status = step(problem, state, h);
    if (!status.ok) return status;
    const Eigen::MatrixXd end_hessian = dense_hessian(problem, state.q);
    const double alpha_m = alpha_.alpha_m, alpha_f = alpha_.alpha_f;
    const TangentBlock start(n);
    const Eigen::MatrixXd dv0 = inverse_mass * start.p;
    const Eigen::MatrixXd da0 = -(inverse_mass * (start_hessian * start.q));
    const Eigen::MatrixXd dq_predict = start.q + h * dv0 + (h * h * (0.5 - beta_)) * da0;
    const Eigen::MatrixXd dv_predict = dv0 + (h * (1 - gamma_)) * da0;
    const Eigen::MatrixXd matrix =
        (1 - alpha_m) * Eigen::MatrixXd(mass) + ((1 - alpha_f) * beta_ * h * h) * end_hessian;
    const Eigen::MatrixXd da1 =
        matrix.partialPivLu().solve(-(1 - alpha_f) * (end_hessian * dq_predict) -
                                    alpha_f * (start_hessian * start.q) - alpha_m * (mass * da0));
    TangentBlock block(n);
    block.q = dq_predict + (beta_ * h * h) * da1;
    block.p = mass * (dv_predict + (gamma_ * h) * da1);
    tangent = block.stacked();
    return status;
  }

 private:
  // a = M⁻¹(−∇V(q) + F(q, M⁻¹p, t)).
  void acceleration(const Problem& problem, const State& state, Vec& a) {
    eval_total_force(problem, state.q, MassOperator(problem).solve(state.q, state.p), state.t, a);
    a = MassOperator(problem).solve(state.q, a);
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
  Alpha alpha_;
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
  const double beta =
      params.real("beta", 0.25, "position weight beta (0: explicit; 1/4: average acceleration)",
                  Range::closed(0, 0.5));
  const double gamma =
      params.real("gamma", 0.5, "velocity weight gamma (1/2: second order, no numerical damping)",
                  Range::closed(0, 1));
  const NewtonOptions newton = read_newton_options(params, "|p| + h|M a0|");
  Newmark::Alpha plain;
  plain.second_order = gamma == 0.5;
  return std::make_unique<Newmark>(beta, gamma, newton, plain);
}

// HHT-α in Chung & Hulbert's notation: α_m = 0, α_f = −α, β = (1−α)²/4, γ = ½ − α; the
// high-frequency spectral radius is ρ∞ = (1+α)/(1−α).
std::unique_ptr<Integrator> make_hht(Params& params) {
  const double alpha =
      params.real("alpha", -0.05,
                  "HHT alpha in [-1/3, 0] (0: trapezoidal Newmark; rho_inf = (1+alpha)/(1-alpha))",
                  Range::closed(-1.0 / 3.0, 0));
  const NewtonOptions newton = read_newton_options(params, "|p| + h|M a0|");
  Newmark::Alpha hht;
  hht.name = "hht";
  hht.alpha_f = -alpha;
  hht.second_order = true;  // γ = ½ − α_m + α_f by construction
  hht.reference = "Hilber-Hughes-Taylor, EESD 1977; docs/METHOD.md §1, §7";
  return std::make_unique<Newmark>((1 - alpha) * (1 - alpha) / 4, 0.5 - alpha, newton, hht);
}

// Generalized-α (Chung & Hulbert, J. Appl. Mech. 1993, eqs. 25 and 17–18): the parameters that
// put all three roots of the amplification matrix at −ρ∞ for hω → ∞ with second order.
std::unique_ptr<Integrator> make_generalized_alpha(Params& params) {
  const double rho = params.real(
      "rho_inf", 0.8, "spectral radius at h*omega -> infinity, in [0, 1] (1: trapezoidal Newmark)",
      Range::closed(0, 1));
  const NewtonOptions newton = read_newton_options(params, "|p| + h|M a0|");
  Newmark::Alpha alpha;
  alpha.name = "generalized_alpha";
  alpha.alpha_m = (2 * rho - 1) / (rho + 1);
  alpha.alpha_f = rho / (rho + 1);
  alpha.second_order = true;  // γ = ½ − α_m + α_f by construction
  alpha.reference = "generalized-alpha, Chung-Hulbert J. Appl. Mech. 1993; docs/METHOD.md §1, §7";
  const double sum = 1 - alpha.alpha_m + alpha.alpha_f;
  return std::make_unique<Newmark>(sum * sum / 4, 0.5 - alpha.alpha_m + alpha.alpha_f, newton,
                                   alpha);
}

}  // namespace geomint
