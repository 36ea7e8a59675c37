// Variational integrators generated from a quadrature discrete Lagrangian (docs/METHOD.md §1–2;
// Marsden & West 2001, §1.6, §2.3 and §3.2 (forced DEL); Kharevych et al. 2006, §3): the forced
// discrete Euler–Lagrange map p_k = −D₁L_d − F_d⁻, p_{k+1} = D₂L_d + F_d⁺, derived once for every
// rule.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
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

namespace geomint {
namespace {

// Every rule is a quadrature of the Lagrangian along the straight path q(s) = (1 − s)q_k + s
// q_{k+1} with the constant velocity v = (q_{k+1} − q_k)/h:
//
//   L_d(q_k, q_{k+1}) = h Σ_j w_j [½ vᵀMv − V(q^j)],   q^j = (1 − a_j) q_k + a_j q_{k+1},
//
// with Σ_j w_j = 1 (left {(0,1)}, right {(1,1)}, trapezoid {(0,½),(1,½)}, midpoint {(½,1)},
// alpha {(α,1)}, symmetric_alpha {(α,½),(1−α,½)}),
// so that (with g_j = ∇V(q^j))
//
//   D₁L_d = −Mv − h Σ_j w_j (1 − a_j) g_j,        D₂L_d = Mv − h Σ_j w_j a_j g_j.
//
// Properties follow from the nodes instead of being declared per rule:
//  - explicit iff every a_j(1 − a_j) = 0: the equation for v then sees ∇V only at q_k, so it is
//    linear in v with matrix M;
//  - symmetric (L_d(q_k, q_{k+1}) = L_d(q_{k+1}, q_k) with h → −h) iff the node set is invariant
//    under (a, w) → (1 − a, w);
//  - order 2 iff Σ_j w_j a_j = ½, the quadrature's first moment: L_d then matches the exact
//    discrete Lagrangian to O(h³) (Marsden–West Thm 2.3.1), otherwise only to O(h²) — order 1.
// The step solves p_k = −D₁L_d − F_d⁻ for v by Newton from v₀ = M⁻¹p_k with the matrix
// M + h² Σ_j w_j a_j(1 − a_j)∇²V(q^j) (+ the impulse's hC), symmetric → sparse LDLT, globalised
// by backtracking on ½‖R‖² (hp adds the minimisation form), then evaluates p_{k+1} = D₂L_d + F_d⁺.
// An explicit rule with an impulse in the minus slot still solves (M + hC)v = … by Newton (one
// iteration for a force linear in v), without the Hessian. Constraints (rule=midpoint only,
// docs/METHOD.md §3): p_k = −D₁L_d − G(q_k)ᵀΛ with g(q_{k+1}) = 0, by
// integrators/constrained_step.hpp, then p_{k+1} projected onto the tangent space.
//
// The general kind L = ½vᵀM(q)v + a(q)ᵀv − V(q) (docs/MECHANICS_GENERAL.md §2) runs the same step
// for the one-node rules (α = a₁ ∈ (0, 1), L_d = h L(q̄, v) with q̄ = q_k + αhv): with ∇V(q^j)
// read as g_j = −L_q(q^j, v) and Mv as L_v(q̄, v) the equation for v is
//   R(v) = L_v(q̄, v) − p_k + h(1−α)g(v) − F_d⁻ = 0,
//   ∂R/∂v = M(q̄) + hα L_vq − h(1−α) L_qv − h²α(1−α) L_qq   (GeneralVelocityJacobian; not
//   symmetric, so SparseLU), started at v(q_k, p_k) = M(q_k)⁻¹(p_k − a(q_k)),
// and p_{k+1} = p_k − h g + F_d⁻ + F_d⁺ (= L_v(q̄, v) − hαg + F_d⁺ at R = 0), which keeps the
// momentum of a cyclic coordinate (L_q ≡ 0: polar Kepler's p_φ) exact whatever residual the solve
// left.
// On constrained problems of the general kind (a mass M(q)) the step is
// integrators/general_constrained_step.hpp's, forced the same way.
struct Node {
  double a;  // position along the step, in [0, 1]
  double w;  // weight, Σ w = 1
};

class DiscreteLagrangianVI final : public Integrator {
 public:
  DiscreteLagrangianVI(std::string rule, std::vector<Node> nodes, Forcing forcing,
                       const NewtonOptions& newton, VelocitySolve solve)
      : rule_(std::move(rule)),
        nodes_(std::move(nodes)),
        forcing_(forcing),
        newton_(newton),
        solve_(solve) {
    newton_.options().polish = true;  // momentum maps to round-off, not to the tolerance
    double first_moment = 0.0;
    for (const Node& node : nodes_) {
      first_moment += node.w * node.a;
      if (node.a == 0.0) start_weight_ += node.w;
      if (node.a == 1.0) end_weight_ += node.w;
      if (node.a > 0.0 && node.a < 1.0) interior_.push_back(node);
    }
    order_ = std::abs(first_moment - 0.5) <= 1e-14 ? 2 : 1;
    midpoint_ = nodes_.size() == 1 && nodes_[0].a == 0.5;
    symmetric_ = std::all_of(nodes_.begin(), nodes_.end(), [&](const Node& node) {
      return std::any_of(nodes_.begin(), nodes_.end(), [&](const Node& mirror) {
        return std::abs(mirror.a - (1 - node.a)) <= 1e-14 && std::abs(mirror.w - node.w) <= 1e-14;
      });
    });
  }

  MethodInfo info() const override {
    unsigned flags = kSymplectic | kVariational;
    flags |= interior_.empty() ? kExplicit : (kImplicit | kNeedsHessian);
    if (symmetric_) flags |= kSymmetric;
    if (midpoint_) flags |= kConstrained | kRheonomic;
    // A one-node rule is L_d = h L((1−α)q_k + αq_{k+1}, v), which general_del_step solves for any
    // L(q, v) (docs/MECHANICS_GENERAL.md §2); left and right (α = 0, 1) are declared explicit,
    // which they are not when M depends on q, and the two-node rules assume constant M.
    if (nodes_.size() == 1 && !interior_.empty()) flags |= kGeneralLagrangian;
    return {"del", order_, flags,
            fmt::format("discrete Euler-Lagrange, quadrature L_d ({}), Marsden-West 2001 §2.3, "
                        "§3.2; Kharevych et al. 2006 §3; docs/METHOD.md §1-2",
                        rule_)};
  }

  StabilityPrediction predicted_linear_stability() const override {
    // Every rule is an α-rule or the mean of the α and 1 − α rules, whose linear recurrences share
    // β = α(1 − α), with α the first node: left and trapezoid α = 0, right α = 1, midpoint ½.
    return alpha_rule_stability(nodes_.front().a);
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    newton_.forget_pattern();
    cached_problem_ = nullptr;
    damping_symmetric_.reset();
  }

  // The one step of both kinds (integrators/step_implementation.hpp): they differ only in what
  // the view gives at the nodes — Mv through the mass operator, ∇V and its Hessian on the
  // separable kind; L_v, −L_q and the GeneralVelocityJacobian blocks of the problem's
  // LagrangianSystem on the general one (one interior node there, info()).
  StepStatus step(const Problem& problem, State& state, double h) override {
    mark_step_implementation();
    constraint_impulses_.reset();
    if (problem.kind() == ProblemKind::kLagrangian && problem.has(kConstraints)) {
      std::vector<QuadratureNode> nodes;
      for (const Node& node : nodes_) nodes.push_back({node.a, node.w});
      return general_constrained_step(
          problem, *problem.as_lagrangian(), {.nodes = std::move(nodes), .forcing = forcing_},
          state, h, {newton_.options().tolerance, newton_.options().max_iterations}, counters_,
          constraint_impulses_, "del");
    }
    const MassOperator mass_operator(problem);
    general_ = problem.as_lagrangian();
    // The constant diagonal M on the separable kind (its products below are those of the
    // separable step before the kinds shared it, bit for bit); unused on the general kind.
    const Vec* diagonal = general_ != nullptr ? nullptr : &mass_operator.constant_diagonal();
    if (general_ == nullptr) update_sparse_mass_matrix(problem, mass_diagonal_, mass_matrix_);
    const bool forced = problem.has(kForce);
    const double minus = forced ? forcing_.minus_weight() : 0.0;
    const double plus = forced ? forcing_.plus_weight() : 0.0;
    q0_ = state.q;
    t0_ = state.t;
    h_ = h;
    minus_ = minus;

    // The v-independent part of the equation for v: −p_k + h Σ_{a_j=0} w_j ∇V(q_k).
    constant_ = -state.p;
    if (start_weight_ > 0.0) {
      start_gradient(problem, state.q);
      constant_ += (h * start_weight_) * gradient_start_;
    }

    // v₀ = v(q_k, p_k): M⁻¹p_k, or M(q_k)⁻¹(p_k − a(q_k)) on the general kind.
    Vec v = general_ != nullptr ? general_->velocity(state.q, state.p)
                                : mass_operator.solve(state.q, state.p);
    if (interior_.empty() && minus == 0.0) {
      // Explicit rule and no implicit impulse: M v = p_k − h Σ_{a_j=0} w_j ∇V(q_k) (separable
      // kind only: info() declares no general kind for rules without an interior node).
      v = -mass_operator.constant_inverse_diagonal().cwiseProduct(constant_);
    } else {
      // Start from v₀ = M⁻¹p_k: the residual's linear momentum Σ(Mv − p_k) is then zero and the
      // Newton updates (whose matrix has the translations in the kernel of its ∇²V and C parts)
      // keep it zero, so linear momentum is exact through every iterate, not only at convergence.
      if (forced && minus > 0.0) {
        decide_damping_symmetry(problem, state.q, v, state.t, damping_, damping_symmetric_);
      }
      double inner_scale = 0.0;
      const bool matrix_free = resolve_velocity_solve(solve_, problem) != VelocitySolve::kDense;
      NewtonSystem system;
      system.inner_term_scale = [&] { return inner_scale; };
      system.residual = [&](const Vec& x, Vec& residual) {
        implicit_terms(problem, x);
        if (general_ != nullptr) {
          const Vec q_bar = q0_ + (interior_.front().a * h) * x;
          residual = (matrix_free ? general_->momentum_by_operator(q_bar, x)
                                  : general_->momentum(q_bar, x)) +
                     constant_ + implicit_term_;
        } else {
          residual = diagonal->cwiseProduct(x) + constant_ + implicit_term_;
        }
      };
      system.jacobian = [&](const Vec& x, SparseMatrix& jacobian) {
        if (general_ != nullptr) {
          const double alpha = interior_.front().a;  // the one node, weight 1
          inner_scale =
              general_jacobian_.assemble(*general_, q0_ + (alpha * h) * x, x, h, alpha, jacobian);
          if (minus > 0.0) {
            add_minus_impulse_jacobian(problem, forcing_, impulse_step(), x, jacobian, damping_,
                                       counters_);
          }
          return;
        }
        jacobian = mass_matrix_;
        inner_scale = 0.0;
        for (const Node& node : interior_) {
          const Vec q_node = q0_ + (node.a * h) * x;
          eval_hessian(problem, q_node, hessian_);
          inner_scale += std::abs(h * node.w) * gradient_term_scale(hessian_, q_node);
          jacobian += (h * h * node.w * node.a * (1 - node.a)) * hessian_;
        }
        if (minus > 0.0) {
          add_minus_impulse_jacobian(problem, forcing_, impulse_step(), x, jacobian, damping_,
                                     counters_);
        }
      };
      // The general kind's matrix has the non-symmetric part hα L_vq − h(1−α) L_qv.
      system.symmetric = general_ == nullptr &&
                         (minus == 0.0 || (problem.has(kForceJacobian) && *damping_symmetric_));

      implicit_terms(problem, v);
      // The sizes of the terms the residual balances, at the start iterate.
      const double residual_scale =
          robust_norm(state.p) + robust_norm(constant_ + state.p) + robust_norm(implicit_term_);
      const StepStatus solved = solve_velocity_equation(problem, system, residual_scale, v);
      if (!solved.ok) return solved;
      implicit_terms(problem, v);  // no-op unless the last evaluation was elsewhere
    }

    // p_{k+1} = D₂L_d + F_d⁺ = M v − h Σ_j w_j a_j ∇V(q^j) + F_d⁺; on the general kind
    // L_v(q̄, v) = p_k + F_d⁻ − h(1−α)g is read from the equation (the comment above Node).
    const Vec q1 = state.q + h * v;
    Vec p1 = general_ != nullptr ? Vec(state.p - implicit_term_) : Vec(diagonal->cwiseProduct(v));
    for (size_t j = 0; j < interior_.size(); ++j) {
      p1 -= (h * interior_[j].w * interior_[j].a) * interior_gradients_[j];
    }
    if (end_weight_ > 0.0) {
      eval_gradient(problem, q1, gradient_end_);
      p1 -= (h * end_weight_) * gradient_end_;
      // First same as last: ∇V(q_{k+1}) is the next step's ∇V(q_k) (trapezoid = Störmer–Verlet).
      cached_problem_ = &problem;
      cached_q_ = q1;
      gradient_cache_ = gradient_end_;
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
    ++counters_.steps;
    return StepStatus::success();
  }

  // The quadrature DEL map's tangent (integrators/tangent.hpp) at v = (q₁ − q₀)/h.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    const Vec q0 = state.q;
    const StepStatus status = step(problem, state, h);
    if (!status.ok) return status;
    std::vector<QuadratureNode> nodes;
    for (const Node& node : nodes_) nodes.push_back({node.a, node.w});
    tangent = quadrature_del_tangent(problem, q0, state.q, (state.q - q0) / h, h, nodes);
    return status;
  }

 private:
  // Solves the step's velocity equation R(v) = 0 (`system`, from the start v): the one place
  // where how it is solved is chosen — NewtonSolver, or matrix-free (solve=,
  // operator_del_solve.hpp; auto on a recursive mass), in the constrained KKT form with G(q_k)ᵀΛ
  // and g(q_k + hv) = 0 when the problem has constraints (docs/METHOD.md §3).
  StepStatus solve_velocity_equation(const Problem& problem, const NewtonSystem& system,
                                     double residual_scale, Vec& v) {
    if (problem.has(kConstraints)) {
      const ConstrainedStepResult constrained = solve_constrained_step(
          problem, q0_, t0_, h_, system, newton_.options(), residual_scale, v);
      count_solve(constrained.newton);
      if (!constrained.newton.converged) {
        return StepStatus::failure(constrained.newton.reason, describe(constrained));
      }
      constraint_impulses_ = ConstraintImpulses{constrained.impulse, Vec(), h_};
      return StepStatus::success();
    }
    const VelocitySolve solve = resolve_velocity_solve(solve_, problem);
    const NewtonResult result =
        solve == VelocitySolve::kDense
            ? newton_.solve(system, v, residual_scale)
            : matrix_free_velocity_solve(
                  system,
                  velocity_equation_preconditioner(problem, q0_, h_,
                                                   interior_.empty() ? 0.0 : interior_.front().a),
                  v, residual_scale, newton_.options(), solve == VelocitySolve::kNewtonKrylov);
    count_solve(result);
    if (!result.converged) return StepStatus::failure(result.reason, describe(result));
    return StepStatus::success();
  }

  void count_solve(const NewtonResult& result) {
    counters_.newton_iters += result.iterations;
    counters_.linear_solves += result.linear_solves;
    counters_.factorizations += result.factorizations;
  }

  ImpulseStep impulse_step() const { return {q0_, t0_, h_, minus_}; }

  void start_gradient(const Problem& problem, const Vec& q) {
    if (cached_problem_ == &problem && cached_q_.size() == q.size() && cached_q_ == q) {
      gradient_start_ = gradient_cache_;
    } else {
      eval_gradient(problem, q, gradient_start_);
    }
  }

  // implicit_term_ = h Σ_interior w_j (1 − a_j) g_j(v) − F_d⁻(v) with g_j = ∇V(q^j(v)), or
  // −L_q(q^j(v), v) on the general kind, memoised on v so that the gradients of the accepted
  // iterate are reused for p_{k+1}.
  void implicit_terms(const Problem& problem, const Vec& v) {
    if (memo_valid_ && memo_v_.size() == v.size() && memo_v_ == v && memo_q_ == q0_ &&
        memo_h_ == h_ && memo_problem_ == &problem) {
      return;
    }
    interior_gradients_.resize(interior_.size());
    implicit_term_.setZero(v.size());
    for (size_t j = 0; j < interior_.size(); ++j) {
      const Vec q_node = q0_ + (interior_[j].a * h_) * v;
      if (general_ != nullptr) {
        ++counters_.force_evals;
        general_->lagrangian_q(q_node, v, interior_gradients_[j]);
        interior_gradients_[j] = -interior_gradients_[j];
      } else {
        eval_gradient(problem, q_node, interior_gradients_[j]);
      }
      implicit_term_ += (h_ * interior_[j].w * (1 - interior_[j].a)) * interior_gradients_[j];
    }
    if (minus_ > 0.0) {
      minus_impulse(problem, forcing_, impulse_step(), v, impulse_, counters_);
      implicit_term_ -= impulse_;
    }
    memo_valid_ = true;
    memo_v_ = v;
    memo_q_ = q0_;
    memo_h_ = h_;
    memo_problem_ = &problem;
  }

  std::string rule_;
  std::vector<Node> nodes_;
  std::vector<Node> interior_;  // nodes with 0 < a < 1: the implicit part
  double start_weight_ = 0.0;   // Σ w over nodes at q_k
  double end_weight_ = 0.0;     // Σ w over nodes at q_{k+1}
  int order_ = 1;
  bool symmetric_ = false;
  bool midpoint_ = false;  // the constrained step is enabled (and tested) for the midpoint rule
  Forcing forcing_;
  NewtonSolver newton_;
  VelocitySolve solve_;

  // Per-step data used by the residual.
  Vec q0_;
  double t0_ = 0.0, h_ = 0.0, minus_ = 0.0;
  Vec constant_, implicit_term_, impulse_, force_;
  std::vector<Vec> interior_gradients_;
  bool memo_valid_ = false;
  Vec memo_v_, memo_q_;
  double memo_h_ = 0.0;
  const Problem* memo_problem_ = nullptr;

  const LagrangianSystem* general_ = nullptr;  // this step's problem's, on the general kind
  GeneralVelocityJacobian general_jacobian_;
  Vec mass_diagonal_;
  SparseMatrix mass_matrix_, hessian_, damping_;
  std::optional<bool> damping_symmetric_;
  Vec gradient_start_, gradient_end_;
  const Problem* cached_problem_ = nullptr;  // ∇V(q_{k+1}) cache for the next step's ∇V(q_k)
  Vec cached_q_, gradient_cache_;
};

}  // namespace

std::unique_ptr<Integrator> make_del(Params& params) {
  const std::string rule = params.choice(
      "rule", "midpoint", {"left", "right", "trapezoid", "midpoint", "alpha", "symmetric_alpha"},
      "quadrature of L_d: h L(q_k,v), h L(q_k+1,v), trapezoid (Verlet), midpoint, "
      "h L((1-alpha)q_k + alpha q_k+1, v), or the mean of alpha and 1-alpha");
  std::vector<Node> nodes;
  if (rule == "left") nodes = {{0.0, 1.0}};
  if (rule == "right") nodes = {{1.0, 1.0}};
  if (rule == "trapezoid") nodes = {{0.0, 0.5}, {1.0, 0.5}};
  if (rule == "midpoint") nodes = {{0.5, 1.0}};
  std::string label = rule;
  if (rule == "alpha" || rule == "symmetric_alpha") {
    // rule=alpha defaults to the midpoint (the paper's α = ½); symmetric_alpha to ¼, since its
    // α = ½ is the midpoint again and α ∈ {0, 1} the trapezoid.
    const double alpha = params.real("alpha", rule == "alpha" ? 0.5 : 0.25,
                                     "quadrature node in [0, 1] (rule=alpha, symmetric_alpha only)",
                                     Range::closed(0, 1));
    if (rule == "alpha") {
      nodes = {{alpha, 1.0}};
    } else if (alpha == 0.5) {
      nodes = {{0.5, 1.0}};  // the two nodes coincide
    } else {
      nodes = {{alpha, 0.5}, {1 - alpha, 0.5}};
    }
    label = fmt::format("{}, alpha={}", rule, format_number(alpha));
  }
  const Forcing forcing = read_forcing(params);
  const NewtonOptions newton = read_newton_options(params, "|p| + h|grad V| + |F_d-|");
  const VelocitySolve solve = read_velocity_solve_option(params);
  return std::make_unique<DiscreteLagrangianVI>(label, std::move(nodes), forcing, newton, solve);
}

}  // namespace geomint
