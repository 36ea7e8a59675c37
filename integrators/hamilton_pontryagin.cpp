// Discrete Hamilton–Pontryagin integrator in (q, v, p) and its update as the minimisation of
// E_k(v) = ½vᵀMv − p_kᵀv + ((1−α)/α)V(q_k + αhv) (docs/METHOD.md §4; Kharevych et al. 2006, §4),
// with the discrete Lagrange–d'Alembert force impulses of docs/METHOD.md §2 (Marsden & West 2001,
// §3.2).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "integrators/constrained_step.hpp"
#include "integrators/forcing.hpp"
#include "integrators/general_constrained_step.hpp"
#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "integrators/operator_del_solve.hpp"
#include "integrators/step_implementation.hpp"
#include "integrators/tangent.hpp"
#include "problems/mass_operator.hpp"
#include "problems/parallel.hpp"

namespace geomint {
namespace {

// J = diag(m) + c·H with the bits of Eigen's `J = M; J += c * H` for the sparse diagonal M (an
// entry m_i + c·H_ii on the diagonal and 0 + c·H_ij elsewhere: Eigen's sum adds 0 where an operand
// has no entry), but in one threaded pass over H's values into J's storage (reused from the last
// call) instead of a serial merge into a newly allocated matrix: at 10⁵ tetrahedra that merge was
// a quarter of a Newton iteration's Jacobian time (docs/PERF.md "Implicit step"). Needs H square,
// compressed and with every diagonal entry in its pattern (the assembled Hessians of the mesh and
// spring problems); false otherwise, and the caller sums as before.
bool diagonal_plus_scaled(const Vec& m, double c, const SparseMatrix& H, SparseMatrix& J) {
  const Eigen::Index n = H.outerSize();
  if (!H.isCompressed() || H.rows() != n || m.size() != n) return false;
  const int* outer = H.outerIndexPtr();
  const int* inner = H.innerIndexPtr();
  std::vector<int> diagonal(static_cast<std::size_t>(n));
  for (Eigen::Index j = 0; j < n; ++j) {
    const int* at = std::lower_bound(inner + outer[j], inner + outer[j + 1], static_cast<int>(j));
    if (at == inner + outer[j + 1] || *at != j) return false;
    diagonal[static_cast<std::size_t>(j)] = static_cast<int>(at - inner);
  }
  J = H;
  const double* from = H.valuePtr();
  double* to = J.valuePtr();
  const auto entries = static_cast<std::size_t>(H.nonZeros());
  for_each_chunk(chunk_count(entries, std::size_t{1} << 16), entries,
                 [&](int, std::size_t begin, std::size_t end) {
                   for (std::size_t k = begin; k < end; ++k) to[k] = 0.0 + c * from[k];
                 });
  for (Eigen::Index j = 0; j < n; ++j) {
    const auto k = static_cast<std::size_t>(diagonal[static_cast<std::size_t>(j)]);
    to[k] = m[j] + c * from[k];
  }
  return true;
}

// Update from (q_k, p_k), with q^α = q_k + αhv and the impulses F_d∓ of the force_slot/force_at
// options (integrators/forcing.hpp; discrete_lagrangian.cpp's α-rule is the same map):
//   1. solve R(v) = Mv − p_k + (1−α)h∇V(q^α) − F_d⁻(v) = 0   (α = 0: ∇V(q_k), explicit)
//   2. q_{k+1} = q_k + hv,   3. p_{k+1} = Mv − αh∇V(q^α) + F_d⁺(v).
// v = (q_{k+1} − q_k)/h is the HP velocity variable; it is kept inside the integrator (velocity()),
// State carries (q, p) only. α ∈ {0, 1} without an implicit impulse needs no solve (symplectic
// Euler kick-first and drift-first); α = 1 has (1−α)/α = 0, so E_k is ½vᵀMv − p_kᵀv and nothing is
// divided by α.
//
// Solvers (same start v₀ = M⁻¹p_k — then Σ(Mv − p_k) = 0 and every Newton update keeps it, so
// linear momentum is exact through every iterate —, same tolerance ‖R‖ ≤ tol·max(1, ‖p_k‖ +
// ‖p_k − b‖ + ‖(1−α)h∇V(q^α(v₀)) − F_d⁻(v₀)‖) with b = p_k (α > 0) or p_k − h∇V(q_k) (α = 0),
// same polishing correction (NewtonOptions::polish), same sparse LDLT):
//  - minimize: Newton on ∇E_k = R with an Armijo backtracking line search on E_k itself (counted
//    in energy_evals) and an SPD safeguard: when the LDLT factor of the Hessian
//    M + α(1−α)h²∇²V(q^α) (+ hC) has a non-positive pivot (non-convex V: springs or elements under
//    compression, a pendulum past horizontal), M + α(1−α)h²∇²V + μM is factorised instead with
//    μ = 10⁻³, 10⁻², … until every pivot is positive (NewtonSystem::spd_shift). The step is then a
//    descent direction of E_k, so the iteration decreases E_k monotonically and cannot cycle;
//    near a strict local minimiser the Hessian is SPD again and convergence is quadratic.
//  - newton: plain Newton on R — full steps, no line search and no safeguard. This is the
//    root-finding baseline of the paper's "> 2×" claim and deliberately has neither of the
//    minimiser's globalisation devices: at large h it can cycle, diverge or land on a
//    non-minimising stationary point where the minimiser succeeds.
//
// Forces and the minimiser. An impulse in the plus slot only enters step 3, so E_k is unchanged.
// In the minus slot (or half of it, split) evaluated at the node q_k, a force that is affine in v
// with a symmetric damping matrix, F(q_k, v) = F(q_k, 0) − C(q_k)v (linear damping: spring_net,
// damped_oscillator), makes −F_d⁻ the gradient of the dissipation function
// w⁻h[½vᵀC(q_k)v − F(q_k, 0)ᵀv], which is added to E_k exactly: the update stays a minimisation
// (a Rayleigh-dissipation "incremental potential"). That structure is checked once per run (C
// symmetric; F at a test velocity equal to the affine model). Otherwise — force_at=midpoint, where
// F(q_k + (h/2)v, v) depends on v through q as well, non-symmetric C, or a force that is not affine
// in v — R is not a gradient: minimize then falls back to Newton with a backtracking line search
// on the merit ½‖R‖² (no objective, hence no SPD safeguard: the shifted step need not descend the
// merit). The default (force_slot=split, force_at=midpoint, as in discrete_lagrangian.cpp) is such
// a case: on a forced problem minimize is a line-searched Newton on R; force_at=node keeps the
// exact objective.
//
// The general Lagrangian kind (L = ½vᵀM(q)v + a(q)ᵀv − V, ../shared/MECHANICS.md §3) runs the
// same step, with ∇V(q^α) read as g = −L_q(q^α, v) and Mv as L_v(q^α, v): it solves
// R(v) = L_v(q^α, v) − p_k + (1−α)h g − F_d⁻ = 0, then q_{k+1} = q_k + hv and
// p_{k+1} = p_k − hg + F_d⁻ + F_d⁺ (= L_v − αhg + F_d⁺ at R = 0; exact for a cyclic coordinate
// whatever residual the solve left) — the α-rule DEL step in position–momentum form, with the
// matrix M(q^α) + hα L_vq − h(1−α) L_qv − h²α(1−α) L_qq (GeneralVelocityJacobian, SparseLU).
// That matrix is the Hessian of no scalar E_k unless L_vq is symmetric, so the minimiser does
// not exist there: `solver=minimize` written out is refused on non-separable problems
// (general_lagrangian_refusal), while the default (solver not given) runs the Newton form, no
// line search, exactly as solver=newton; 0 < α < 1 only, as for del (α = 0, 1 are declared
// explicit, which they are not when M depends on q).
//
// Constraints (α = ½ only, docs/METHOD.md §3): the same system with the multiplier impulse
// G(q_k)ᵀΛ and g(q_k + hv) = 0, solved by integrators/constrained_step.hpp, then p_{k+1}
// projected onto the tangent space at q_{k+1}. On the general kind (a mass M(q): andrews) the
// same constrained, forced α-rule DEL step by integrators/general_constrained_step.hpp.
class HamiltonPontryagin final : public Integrator,
                                 public ExplainsGeneralRefusal,
                                 public ResolvesOnGeneralLagrangian {
 public:
  HamiltonPontryagin(double alpha, bool minimize, bool minimize_written, Forcing forcing,
                     const NewtonOptions& newton, VelocitySolve solve)
      : alpha_(alpha),
        minimize_(minimize),
        minimize_written_(minimize_written),
        forcing_(forcing),
        newton_(newton),
        solve_(solve) {
    NewtonOptions& options = newton_.options();
    options.polish = true;  // momentum maps to round-off, not to the tolerance
    options.line_search = minimize;
  }

  MethodInfo info() const override {
    unsigned flags = kSymplectic | kVariational;
    flags |= (alpha_ == 0.0 || alpha_ == 1.0) ? kExplicit : (kImplicit | kNeedsHessian);
    if (alpha_ == 0.5) flags |= kSymmetric | kConstrained | kRheonomic;
    if (alpha_ > 0.0 && alpha_ < 1.0 && !minimize_written_) flags |= kGeneralLagrangian;
    return {"hp", alpha_ == 0.5 ? 2 : 1, flags,
            "discrete Hamilton-Pontryagin, update as minimisation of E_k, Kharevych et al. 2006 "
            "§4; docs/METHOD.md §4"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return alpha_rule_stability(alpha_);
  }

  std::string general_lagrangian_refusal() const override {
    if (!minimize_written_ || alpha_ == 0.0 || alpha_ == 1.0) return {};
    return "hp:solver=minimize needs the step to be the minimiser of a scalar E_k(v), and on a "
           "general L(q, v) it is not (its Jacobian L_vv + h(alpha L_vq - (1-alpha) L_qv) - "
           "alpha(1-alpha)h^2 L_qq is not symmetric); hp:solver=newton or hp without solver= "
           "runs it";
  }

  // Without solver= the general step is Newton's (general_step below, same tol and max_iter):
  // the canonical spec with solver=newton runs the same step, bit for bit.
  std::string general_lagrangian_spec() const override {
    if (!minimize_ || minimize_written_) return spec();
    Spec resolved = Spec::parse(spec());
    resolved.values["solver"] = "newton";
    std::vector<std::string> options;
    for (const auto& [key, value] : resolved.values) options.push_back(key + "=" + value);
    return make_integrator(fmt::format("{}:{}", resolved.name, fmt::join(options, ",")))->spec();
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    newton_.forget_pattern();
    damping_symmetric_.reset();
    dissipation_potential_.reset();
    velocity_ = problem.kind() == ProblemKind::kLagrangian
                    ? problem.as_lagrangian()->velocity(state.q, state.p)
                    : Vec(MassOperator(problem).solve(state.q, state.p));
  }

  // The HP velocity v_{k+1} = (q_{k+1} − q_k)/h of the last step (p_{k+1} ≠ M v_{k+1} unless α =
  // 0).
  const Vec& velocity() const { return velocity_; }

  // The one step of both kinds (integrators/step_implementation.hpp): they differ only in what
  // the view gives at q^α — Mv through the mass operator, ∇V and its Hessian on the separable
  // kind; L_v, −L_q and the GeneralVelocityJacobian blocks of the problem's LagrangianSystem on
  // the general one, where the minimiser has no objective and the Newton form runs.
  StepStatus step(const Problem& problem, State& state, double h) override {
    mark_step_implementation();
    constraint_impulses_.reset();
    if (problem.kind() == ProblemKind::kLagrangian && problem.has(kConstraints)) {
      const Vec q0 = state.q;
      const StepStatus status = general_constrained_step(
          problem, *problem.as_lagrangian(), {.nodes = {{alpha_, 1.0}}, .forcing = forcing_}, state,
          h, {newton_.options().tolerance, newton_.options().max_iterations}, counters_,
          constraint_impulses_, "hp");
      if (status.ok) velocity_ = (state.q - q0) / h;
      return status;
    }
    const MassOperator mass_operator(problem);
    general_ = problem.as_lagrangian();
    // The constant diagonal M on the separable kind (its products below are those of the
    // separable step before the kinds shared it, bit for bit); unused on the general kind.
    diagonal_ = general_ != nullptr ? nullptr : &mass_operator.constant_diagonal();
    if (general_ == nullptr) update_sparse_mass_matrix(problem, mass_diagonal_, mass_matrix_);
    minimizing_ = minimize_ && general_ == nullptr;
    newton_.options().line_search = minimizing_;
    const bool forced = problem.has(kForce);
    minus_ = forced ? forcing_.minus_weight() : 0.0;
    const double plus = forced ? forcing_.plus_weight() : 0.0;
    q0_ = state.q;
    t0_ = state.t;
    h_ = h;
    memo_valid_ = false;
    potential_memo_valid_ = false;
    potential_with_gradient_ = false;

    // b = p_k, or p_k − h∇V(q_k) for α = 0, where the potential impulse does not depend on v.
    b_ = state.p;
    if (alpha_ == 0.0) {
      eval_gradient(problem, state.q, gradient_);
      b_ -= h * gradient_;
    }

    // v₀ = v(q_k, p_k): M⁻¹p_k, or M(q_k)⁻¹(p_k − a(q_k)) on the general kind.
    Vec v = general_ != nullptr ? general_->velocity(state.q, state.p)
                                : mass_operator.solve(state.q, state.p);
    const bool coupled = alpha_ > 0.0 && alpha_ < 1.0;  // ∇V(q^α) depends on v
    if (!coupled && minus_ == 0.0) {
      // E_k is quadratic with Hessian M: no solve (separable kind only, info()).
      v = mass_operator.constant_inverse_diagonal().cwiseProduct(b_);
    } else {
      const StepStatus status = solve(problem, state, coupled, v);
      if (!status.ok) return status;
    }

    // p_{k+1} = Mv − αh∇V(q^α) + F_d⁺; on the general kind L_v(q^α, v) = p_k − implicit_term_ is
    // read from the equation (the comment above the class).
    const Vec q1 = state.q + h * v;
    if (general_ != nullptr) implicit_terms(problem, v);  // memoised: the accepted v's
    Vec p1 = general_ != nullptr ? Vec(state.p - implicit_term_) : Vec(diagonal_->cwiseProduct(v));
    if (coupled) {
      implicit_terms(problem, v);  // no-op unless the last evaluation was elsewhere
      p1 -= (alpha_ * h) * gradient_;
    } else if (alpha_ == 1.0) {
      eval_gradient(problem, q1, gradient_);
      p1 -= h * gradient_;
    }
    if (plus > 0.0)
      add_plus_impulse(problem, forcing_, state, q1, h, v, plus, p1, force_, counters_);
    // The second multiplier: p_{k+1} on the tangent space at q_{k+1} (docs/METHOD.md §3).
    if (problem.has(kConstraints)) {
      Vec nu = project_momentum_to_tangent_space(problem, state.t + h, q1, p1);
      if (constraint_impulses_) constraint_impulses_->end = std::move(nu);
    }
    state.q = q1;
    state.p = p1;
    state.t += h;
    velocity_ = v;
    ++counters_.steps;
    return StepStatus::success();
  }

  // The α-rule DEL map (integrators/tangent.hpp) at the converged v, either solver.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    const Vec q0 = state.q;
    const StepStatus status = step(problem, state, h);
    if (status.ok)
      tangent = quadrature_del_tangent(problem, q0, state.q, velocity_, h, {{alpha_, 1.0}});
    return status;
  }

 private:
  // Builds the step's velocity equation R(v) = 0 (and, for the minimiser, E_k) and solves it
  // from v through solve_velocity_equation.
  StepStatus solve(const Problem& problem, const State& state, bool coupled, Vec& v) {
    if (minus_ > 0.0) {
      decide_damping_symmetry(problem, state.q, v, state.t, damping_, damping_symmetric_);
    }
    // The exact-objective form needs −F_d⁻ to be a gradient in v (see the file comment).
    linearised_ = false;
    if (minimizing_ && minus_ > 0.0 && forcing_.at == ForceAt::kNode &&
        problem.has(kForceJacobian) && *damping_symmetric_) {
      if (!dissipation_potential_) dissipation_potential_ = force_is_affine(problem, state, v);
      if (*dissipation_potential_) {
        // F(q_k, v) = F₀ − C₀v for this step; the residual uses the same model, so ∇E_k = R.
        eval_counted_force(problem, q0_, Vec::Zero(v.size()), t0_, force_zero_);
        force_of(problem).force_jacobian_v(q0_, Vec::Zero(v.size()), t0_, damping_zero_);
        linearised_ = true;
      }
    }
    const bool exact_objective = minimizing_ && (minus_ == 0.0 || linearised_);

    double inner_scale = 0.0;
    const bool matrix_free = resolve_velocity_solve(solve_, problem) != VelocitySolve::kDense;
    NewtonSystem system;
    system.inner_term_scale = [&] { return inner_scale; };
    system.residual = [&](const Vec& x, Vec& residual) {
      implicit_terms(problem, x);
      if (general_ != nullptr) {
        const Vec q_alpha = q0_ + (alpha_ * h_) * x;
        residual = (matrix_free ? general_->momentum_by_operator(q_alpha, x)
                                : general_->momentum(q_alpha, x)) -
                   b_ + implicit_term_;
      } else {
        residual = diagonal_->cwiseProduct(x) - b_ + implicit_term_;
      }
    };
    system.jacobian = [&](const Vec& x, SparseMatrix& jacobian) {
      if (general_ != nullptr) {  // coupled: the general kind runs 0 < α < 1 only
        inner_scale =
            general_jacobian_.assemble(*general_, q0_ + (alpha_ * h_) * x, x, h_, alpha_, jacobian);
      } else if (coupled) {
        const Vec q_alpha = q0_ + (alpha_ * h_) * x;
        eval_hessian(problem, q_alpha, hessian_);
        inner_scale = std::abs((1 - alpha_) * h_) * gradient_term_scale(hessian_, q_alpha);
        const double weight = alpha_ * (1 - alpha_) * h_ * h_;
        if (!diagonal_plus_scaled(*diagonal_, weight, hessian_, jacobian)) {
          jacobian = mass_matrix_;
          jacobian += weight * hessian_;
        }
      } else {
        jacobian = mass_matrix_;
      }
      if (minus_ > 0.0) add_impulse_jacobian(problem, x, jacobian);
    };
    // The general kind's matrix has the non-symmetric part hα L_vq − h(1−α) L_qv.
    system.symmetric = general_ == nullptr &&
                       (minus_ == 0.0 || (problem.has(kForceJacobian) && *damping_symmetric_));
    if (exact_objective) {
      // E_k and the sum of its terms' magnitudes (its round-off scale).
      const auto terms = [&](const Vec& x, double& scale) {
        const double kinetic = 0.5 * x.dot(diagonal_->cwiseProduct(x));
        const double linear = b_.dot(x);
        double energy = kinetic - linear;
        scale = std::abs(kinetic) + std::abs(linear);
        if (coupled) {
          // Memoised: the solver's first evaluation repeats the one at v₀ below.
          if (!(potential_memo_valid_ && potential_memo_v_ == x)) {
            potential_memo_ = eval_potential(problem, q0_ + (alpha_ * h_) * x);
            potential_memo_v_ = x;
            potential_memo_valid_ = true;
            potential_memo_uncounted_ = false;
          } else if (potential_memo_uncounted_) {
            ++counters_.energy_evals;
            potential_memo_uncounted_ = false;
          }
          const double potential = ((1 - alpha_) / alpha_) * potential_memo_;
          energy += potential;
          scale += std::abs(potential);
        }
        if (linearised_) {
          const double dissipation =
              minus_ * h_ * (0.5 * x.dot(damping_zero_ * x) - force_zero_.dot(x));
          energy += dissipation;
          scale += std::abs(dissipation);
        }
        return energy;
      };
      // By value: `terms` is local to this block and the solver calls the objective after it.
      system.objective = [terms](const Vec& x) {
        double scale = 0.0;
        return terms(x, scale);
      };
      // E_k at v₀ is near −½p_kᵀM⁻¹p_k + V: its terms can cancel, so |E_k| understates the noise.
      // V(x) itself is computed with an error of about ε(|V| + Σ|x_i||∂_iV|) — its terms, plus the
      // rounding of the argument x (a pendulum after many turns, a net far from the origin).
      potential_with_gradient_ = coupled;
      if (coupled) implicit_terms(problem, v);  // memoised: ∇V(q^α(v₀)), and V with it if it can
      terms(v, system.objective_scale);
      if (coupled) {
        system.objective_scale += ((1 - alpha_) / alpha_) *
                                  (q0_ + (alpha_ * h_) * v).cwiseAbs().dot(gradient_.cwiseAbs());
      }
      system.spd_shift = mass_matrix_;
    }

    implicit_terms(problem, v);
    const double residual_scale =
        robust_norm(state.p) + robust_norm(b_ - state.p) + robust_norm(implicit_term_);
    return solve_velocity_equation(problem, system, residual_scale, v);
  }

  // Solves the step's velocity equation R(v) = 0 (`system`, from the start v): the one place
  // where how it is solved is chosen — NewtonSolver (the minimiser when `system` has an
  // objective), in the constrained KKT form with G(q_k)ᵀΛ and g(q_k + hv) = 0 when the problem
  // has constraints (docs/METHOD.md §3).
  StepStatus solve_velocity_equation(const Problem& problem, const NewtonSystem& system,
                                     double residual_scale, Vec& v) {
    if (problem.has(kConstraints)) {
      const ConstrainedStepResult constrained = solve_constrained_step(
          problem, q0_, t0_, h_, system, newton_.options(), residual_scale, v);
      count_solve(constrained.newton);
      if (!constrained.newton.converged) return failure(constrained.newton, describe(constrained));
      constraint_impulses_ = ConstraintImpulses{constrained.impulse, Vec(), h_};
      return StepStatus::success();
    }
    const VelocitySolve solve = resolve_velocity_solve(solve_, problem);
    const NewtonResult result =
        solve == VelocitySolve::kDense
            ? newton_.solve(system, v, residual_scale)
            : matrix_free_velocity_solve(
                  system, velocity_equation_preconditioner(problem, q0_, h_, alpha_), v,
                  residual_scale, newton_.options(), solve == VelocitySolve::kNewtonKrylov);
    count_solve(result);
    if (!result.converged) return failure(result, describe(result));
    return StepStatus::success();
  }

  void count_solve(const NewtonResult& result) {
    counters_.newton_iters += result.iterations;
    // A shifted refactorisation costs what a linear solve costs: count it as one.
    counters_.linear_solves += result.linear_solves + result.shift_factorisations;
    counters_.factorizations += result.factorizations;
  }

  StepStatus failure(const NewtonResult& result, const std::string& description) const {
    return StepStatus::failure(result.reason,
                               fmt::format("hp:alpha={},solver={}: {}", format_number(alpha_),
                                           minimizing_ ? "minimize" : "newton", description));
  }

  // F(q_k, v) = F(q_k, 0) − C(q_k)v at a test velocity, and C independent of v: the structure
  // that makes the minus impulse a dissipation gradient. Checked once per run.
  bool force_is_affine(const Problem& problem, const State& state, const Vec& v_start) {
    Vec v_test = v_start;
    if (v_test.norm() == 0.0) v_test.setOnes();
    Vec f_zero, f_test;
    SparseMatrix c_zero, c_test;
    eval_counted_force(problem, state.q, Vec::Zero(v_test.size()), state.t, f_zero);
    eval_counted_force(problem, state.q, v_test, state.t, f_test);
    force_of(problem).force_jacobian_v(state.q, Vec::Zero(v_test.size()), state.t, c_zero);
    force_of(problem).force_jacobian_v(state.q, v_test, state.t, c_test);
    const Vec model = f_zero - c_zero * v_test;
    const double scale = f_test.norm() + f_zero.norm() + (c_zero * v_test).norm();
    return (f_test - model).norm() <= 1e-12 * scale &&
           (c_test - c_zero).norm() <= 1e-12 * c_zero.norm();
  }

  void eval_counted_force(const Problem& problem, const Vec& q, const Vec& v, double t, Vec& f) {
    ++counters_.force_evals;
    eval_force(problem, q, v, t, f);
  }

  ImpulseStep impulse_step() const { return {q0_, t0_, h_, minus_}; }

  // F_d⁻(v) = w⁻·h·F(x⁻, v, t⁻), with the affine model F₀ − C₀v in the dissipation-potential form.
  void minus_impulse(const Problem& problem, const Vec& v, Vec& impulse) {
    if (linearised_) {
      impulse = force_zero_ - damping_zero_ * v;
      impulse *= minus_ * h_;
    } else {
      geomint::minus_impulse(problem, forcing_, impulse_step(), v, impulse, counters_);
    }
  }

  // implicit_term_ = (1−α)h g(v) − F_d⁻(v) with g = ∇V(q^α(v)), or −L_q(q^α(v), v) on the
  // general kind, memoised on v so that the gradient at the
  // accepted iterate is reused for p_{k+1}.
  void implicit_terms(const Problem& problem, const Vec& v) {
    if (memo_valid_ && memo_v_ == v) return;
    implicit_term_.setZero(v.size());
    if (alpha_ > 0.0 && alpha_ < 1.0) {
      const Vec q_alpha = q0_ + (alpha_ * h_) * v;
      if (general_ != nullptr) {
        ++counters_.force_evals;
        general_->lagrangian_q(q_alpha, v, gradient_);
        gradient_ = -gradient_;  // g = −L_q, ∇V on the separable kind
      } else if (potential_with_gradient_) {
        double potential = 0.0;
        if (eval_gradient_with_potential(problem, q_alpha, gradient_, potential)) {
          potential_memo_ = potential;
          potential_memo_v_ = v;
          potential_memo_valid_ = true;
          potential_memo_uncounted_ = true;
        }
      } else {
        eval_gradient(problem, q_alpha, gradient_);
      }
      implicit_term_ += ((1 - alpha_) * h_) * gradient_;
    }
    if (minus_ > 0.0) {
      minus_impulse(problem, v, impulse_);
      implicit_term_ -= impulse_;
    }
    memo_valid_ = true;
    memo_v_ = v;
  }

  // −∂F_d⁻/∂v = w⁻·h·C (forcing.hpp), with C₀ in the dissipation-potential form.
  void add_impulse_jacobian(const Problem& problem, const Vec& v, SparseMatrix& jacobian) {
    if (linearised_) {
      jacobian += (minus_ * h_) * damping_zero_;
    } else {
      add_minus_impulse_jacobian(problem, forcing_, impulse_step(), v, jacobian, damping_,
                                 counters_);
    }
  }

  double alpha_;
  bool minimize_;
  bool minimize_written_;  // solver=minimize given explicitly: refused on non-separable problems
  Forcing forcing_;
  NewtonSolver newton_;
  VelocitySolve solve_;
  Vec velocity_;  // HP velocity v_{k+1}

  // Per-step data used by the residual and objective.
  Vec q0_, b_;
  double t0_ = 0.0, h_ = 0.0, minus_ = 0.0;
  bool linearised_ = false;
  Vec force_zero_;             // F(q_k, 0) in the dissipation-potential form
  SparseMatrix damping_zero_;  // C(q_k) in the dissipation-potential form
  Vec implicit_term_, impulse_, gradient_, force_;
  bool memo_valid_ = false;
  Vec memo_v_;
  bool potential_memo_valid_ = false;
  double potential_memo_ = 0.0;  // V(q^α(potential_memo_v_))
  Vec potential_memo_v_;
  // The memo was filled by implicit_terms with the gradient and not yet used by the objective,
  // which counts the energy evaluation when it first uses it.
  bool potential_memo_uncounted_ = false;
  // implicit_terms takes V with ∇V where the problem has one pass for both: set while the
  // minimiser, whose line search takes E_k wherever it takes R, solves.
  bool potential_with_gradient_ = false;

  // This step's view: the problem's LagrangianSystem on the general kind, the constant diagonal M
  // on the separable one; and whether the minimiser runs (separable kind, solver=minimize).
  const LagrangianSystem* general_ = nullptr;
  const Vec* diagonal_ = nullptr;
  bool minimizing_ = false;
  GeneralVelocityJacobian general_jacobian_;
  Vec mass_diagonal_;
  SparseMatrix mass_matrix_, hessian_, damping_;
  std::optional<bool> damping_symmetric_;      // C = Cᵀ, decided on the first forced solve
  std::optional<bool> dissipation_potential_;  // F affine in v at the node, decided once per run
};

}  // namespace

std::unique_ptr<Integrator> make_hp(Params& params) {
  const double alpha =
      params.real("alpha", 0.5, "position of the potential's node q_k + alpha h v, in [0, 1]",
                  Range::closed(0, 1));
  const std::string solver = params.choice(
      "solver", "minimize", {"minimize", "newton"},
      "minimise E_k with line search and SPD safeguard, or plain Newton on the residual");
  const bool minimize_written = params.given("solver") && solver == "minimize";
  const Forcing forcing = read_forcing(params);
  const NewtonOptions newton = read_newton_options(params, "|p| + h|grad V| + |F_d-|");
  const VelocitySolve solve = read_velocity_solve_option(params);
  return std::make_unique<HamiltonPontryagin>(alpha, solver == "minimize", minimize_written,
                                              forcing, newton, solve);
}

}  // namespace geomint
