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

#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"

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
// iteration for a force linear in v), without the Hessian.
struct Node {
  double a;  // position along the step, in [0, 1]
  double w;  // weight, Σ w = 1
};

enum class ForceSlot { kMinus, kPlus, kSplit };
enum class ForceAt { kNode, kMidpoint };

// Discrete Lagrange–d'Alembert impulses of one step (docs/METHOD.md §2): the step's impulse h·F is
// put into F_d⁻ (minus), F_d⁺ (plus) or half into each (split); each part is evaluated with the
// step velocity v at its own node (q_k for F_d⁻, q_{k+1} for F_d⁺) or, force_at=midpoint, at
// q_{k+½} = q_k + (h/2)v. Forced discrete Noether: the change of a momentum map J over a step is
// the sum of the impulses' torques about the points where they act, so for a frame-invariant
// force (zero net force and torque about its own evaluation point, e.g. spring_net's damping)
// the node choice keeps linear and angular momentum to solver tolerance. At the midpoint the
// impulse hF(q_{k+½}) is torque-free about q_{k+½} but acts at q_k = q_{k+½} − (h/2)v (minus) or
// q_{k+1} = q_{k+½} + (h/2)v (plus): each step changes the angular momentum by ∓(h²/2) Σ_i v_i ×
// F_i = O(h²), i.e. O(h) over a time interval. split applies equal halves at both ends, whose
// torques cancel exactly, so it keeps angular momentum at the midpoint too. Linear momentum is kept
// in every case (Σ_i F_i = 0). docs/METHOD.md §2 reports drift for the minus slot only; measured
// here (results/dissipation, integrators/variational_test.cpp) minus and plus drift alike, with
// opposite signs, at the midpoint and neither drifts at the node. Default: split at the midpoint,
// docs/METHOD.md's "typical" F_d⁻ = F_d⁺ = (h/2)F(q_{k+½}, v) — second order, momenta kept, and on
// forced problems the same map as implicit_midpoint.
struct Forcing {
  ForceSlot slot = ForceSlot::kSplit;
  ForceAt at = ForceAt::kMidpoint;
  double minus_weight() const {
    return slot == ForceSlot::kMinus ? 1.0 : slot == ForceSlot::kSplit ? 0.5 : 0.0;
  }
  double plus_weight() const {
    return slot == ForceSlot::kPlus ? 1.0 : slot == ForceSlot::kSplit ? 0.5 : 0.0;
  }
};

// The force_slot and force_at options (docs/METHOD.md §2); hamilton_pontryagin.cpp reads the same
// keys.
Forcing read_forcing(Params& params) {
  Forcing forcing;
  const std::string slot =
      params.choice("force_slot", "split", {"minus", "plus", "split"},
                    "where the step's force impulse h F goes: F_d- (at q_k), F_d+ (at q_k+1), half "
                    "each");
  forcing.slot = slot == "minus"  ? ForceSlot::kMinus
                 : slot == "plus" ? ForceSlot::kPlus
                                  : ForceSlot::kSplit;
  const std::string at =
      params.choice("force_at", "midpoint", {"node", "midpoint"},
                    "evaluate each impulse's force at its own node, or at q_k+1/2 for all slots");
  forcing.at = at == "node" ? ForceAt::kNode : ForceAt::kMidpoint;
  return forcing;
}

class DiscreteLagrangianVI final : public Integrator {
 public:
  DiscreteLagrangianVI(std::string rule, std::vector<Node> nodes, Forcing forcing, double tolerance,
                       int max_iterations, LinearSolverOptions linear)
      : rule_(std::move(rule)), nodes_(std::move(nodes)), forcing_(forcing) {
    newton_.options().tolerance = tolerance;
    newton_.options().max_iterations = max_iterations;
    newton_.options().linear = linear;
    newton_.options().polish = true;  // momentum maps to round-off, not to the tolerance
    double first_moment = 0.0;
    for (const Node& node : nodes_) {
      first_moment += node.w * node.a;
      if (node.a == 0.0) start_weight_ += node.w;
      if (node.a == 1.0) end_weight_ += node.w;
      if (node.a > 0.0 && node.a < 1.0) interior_.push_back(node);
    }
    order_ = std::abs(first_moment - 0.5) <= 1e-14 ? 2 : 1;
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
    return {"del", order_, flags,
            fmt::format("discrete Euler-Lagrange, quadrature L_d ({}), Marsden-West 2001 §2.3, "
                        "§3.2; Kharevych et al. 2006 §3; docs/METHOD.md §1-2",
                        rule_)};
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    newton_.forget_pattern();
    cached_problem_ = nullptr;
    damping_symmetric_.reset();
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    const Vec& mass = problem.mass();
    const Vec& inverse_mass = problem.inverse_mass();
    if (mass_matrix_.rows() != problem.dof() || mass_diagonal_ != mass) {
      mass_diagonal_ = mass;
      mass_matrix_ = SparseMatrix(mass.asDiagonal());
    }
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

    Vec v = inverse_mass.cwiseProduct(state.p);
    if (interior_.empty() && minus == 0.0) {
      // Explicit rule and no implicit impulse: M v = p_k − h Σ_{a_j=0} w_j ∇V(q_k).
      v = -inverse_mass.cwiseProduct(constant_);
    } else {
      // Start from v₀ = M⁻¹p_k: the residual's linear momentum Σ(Mv − p_k) is then zero and the
      // Newton updates (whose matrix has the translations in the kernel of its ∇²V and C parts)
      // keep it zero, so linear momentum is exact through every iterate, not only at convergence.
      if (forced && minus > 0.0 && problem.has(kForceJacobian) && !damping_symmetric_) {
        // Decided once per run: C = −∂F/∂v is symmetric for dissipative forces, not gyroscopic.
        problem.force_jacobian_v(state.q, v, state.t, damping_);
        damping_symmetric_ = (damping_ - SparseMatrix(damping_.transpose())).norm() == 0.0;
      }
      double inner_scale = 0.0;
      NewtonSystem system;
      system.inner_term_scale = [&] { return inner_scale; };
      system.residual = [&](const Vec& x, Vec& residual) {
        implicit_terms(problem, x);
        residual = mass.cwiseProduct(x) + constant_ + implicit_term_;
      };
      system.jacobian = [&](const Vec& x, SparseMatrix& jacobian) {
        jacobian = mass_matrix_;
        inner_scale = 0.0;
        for (const Node& node : interior_) {
          const Vec q_node = q0_ + (node.a * h) * x;
          eval_hessian(problem, q_node, hessian_);
          inner_scale += std::abs(h * node.w) * gradient_term_scale(hessian_, q_node);
          jacobian += (h * h * node.w * node.a * (1 - node.a)) * hessian_;
        }
        if (minus > 0.0) add_impulse_jacobian(problem, x, jacobian);
      };
      system.symmetric = minus == 0.0 || (problem.has(kForceJacobian) && *damping_symmetric_);

      implicit_terms(problem, v);
      // The sizes of the terms the residual balances, at the start iterate.
      const double residual_scale =
          state.p.norm() + (constant_ + state.p).norm() + implicit_term_.norm();
      const NewtonResult result = newton_.solve(system, v, residual_scale);
      counters_.newton_iters += result.iterations;
      counters_.linear_solves += result.linear_solves;
      counters_.factorizations += result.factorizations;
      if (!result.converged) return StepStatus::failure(result.reason, describe(result));
      implicit_terms(problem, v);  // no-op unless the last evaluation was elsewhere
    }

    // p_{k+1} = D₂L_d + F_d⁺ = M v − h Σ_j w_j a_j ∇V(q^j) + F_d⁺.
    const Vec q1 = state.q + h * v;
    Vec p1 = mass.cwiseProduct(v);
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
    if (plus > 0.0) {
      const bool node = forcing_.at == ForceAt::kNode;
      eval_counted_force(problem, node ? q1 : Vec(state.q + (h / 2) * v), v,
                         node ? state.t + h : state.t + h / 2, force_);
      p1 += (plus * h) * force_;
    }
    state.q = q1;
    state.p = p1;
    state.t += h;
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  void eval_counted_force(const Problem& problem, const Vec& q, const Vec& v, double t, Vec& f) {
    ++counters_.force_evals;
    eval_force(problem, q, v, t, f);
  }

  void start_gradient(const Problem& problem, const Vec& q) {
    if (cached_problem_ == &problem && cached_q_.size() == q.size() && cached_q_ == q) {
      gradient_start_ = gradient_cache_;
    } else {
      eval_gradient(problem, q, gradient_start_);
    }
  }

  // F_d⁻(v) = minus·h·F(x⁻, v, t⁻) with x⁻ = q_k (node) or q_k + (h/2)v (midpoint).
  void minus_impulse(const Problem& problem, const Vec& v, Vec& impulse) {
    if (forcing_.at == ForceAt::kNode) {
      eval_counted_force(problem, q0_, v, t0_, impulse);
    } else {
      eval_counted_force(problem, q0_ + (h_ / 2) * v, v, t0_ + h_ / 2, impulse);
    }
    impulse *= minus_ * h_;
  }

  // implicit_term_ = h Σ_interior w_j (1 − a_j) ∇V(q^j(v)) − F_d⁻(v), memoised on v so that the
  // gradients of the accepted iterate are reused for p_{k+1}.
  void implicit_terms(const Problem& problem, const Vec& v) {
    if (memo_valid_ && memo_v_.size() == v.size() && memo_v_ == v && memo_q_ == q0_ &&
        memo_h_ == h_ && memo_problem_ == &problem) {
      return;
    }
    interior_gradients_.resize(interior_.size());
    implicit_term_.setZero(v.size());
    for (size_t j = 0; j < interior_.size(); ++j) {
      eval_gradient(problem, q0_ + (interior_[j].a * h_) * v, interior_gradients_[j]);
      implicit_term_ += (h_ * interior_[j].w * (1 - interior_[j].a)) * interior_gradients_[j];
    }
    if (minus_ > 0.0) {
      minus_impulse(problem, v, impulse_);
      implicit_term_ -= impulse_;
    }
    memo_valid_ = true;
    memo_v_ = v;
    memo_q_ = q0_;
    memo_h_ = h_;
    memo_problem_ = &problem;
  }

  // −∂F_d⁻/∂v: minus·h·C(x⁻, v) with C = −∂F/∂v. Exact at the node x⁻ = q_k; at the midpoint
  // the (h/2)∂F/∂q part is left out (problems do not provide it): only the Newton matrix is
  // approximate, the residual and hence the solution are exact (as in implicit_euler).
  void add_impulse_jacobian(const Problem& problem, const Vec& v, SparseMatrix& jacobian) {
    if (problem.has(kForceJacobian)) {
      const bool node = forcing_.at == ForceAt::kNode;
      problem.force_jacobian_v(node ? q0_ : Vec(q0_ + (h_ / 2) * v), v, node ? t0_ : t0_ + h_ / 2,
                               damping_);
      jacobian += (minus_ * h_) * damping_;
      return;
    }
    const bool node = forcing_.at == ForceAt::kNode;
    jacobian -= central_difference_jacobian(
        [&](const Vec& x, Vec& impulse) {
          eval_force(problem, node ? q0_ : Vec(q0_ + (h_ / 2) * x), x, node ? t0_ : t0_ + h_ / 2,
                     impulse);
          impulse *= minus_ * h_;
        },
        v);
    counters_.force_evals += 2 * v.size();
  }

  std::string rule_;
  std::vector<Node> nodes_;
  std::vector<Node> interior_;  // nodes with 0 < a < 1: the implicit part
  double start_weight_ = 0.0;   // Σ w over nodes at q_k
  double end_weight_ = 0.0;     // Σ w over nodes at q_{k+1}
  int order_ = 1;
  bool symmetric_ = false;
  Forcing forcing_;
  NewtonSolver newton_;

  // Per-step data used by the residual.
  Vec q0_;
  double t0_ = 0.0, h_ = 0.0, minus_ = 0.0;
  Vec constant_, implicit_term_, impulse_, force_;
  std::vector<Vec> interior_gradients_;
  bool memo_valid_ = false;
  Vec memo_v_, memo_q_;
  double memo_h_ = 0.0;
  const Problem* memo_problem_ = nullptr;

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
    const double alpha = params.real(
        "alpha", rule == "alpha" ? 0.5 : 0.25,
        "quadrature node in [0, 1] (rule=alpha, symmetric_alpha only)",
        [](double x) { return x >= 0.0 && x <= 1.0; }, "in [0, 1]");
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
  const double tolerance = params.real(
      "tol", 1e-12, "Newton relative residual tolerance (scale |p| + h|grad V| + |F_d-|)",
      [](double x) { return x > 0.0 && x < 1.0; }, "in (0, 1)");
  const long max_iterations =
      params.integer("max_iter", 50, "Newton iterations per step before the step fails", 1, 10000);
  const LinearSolverOptions linear = read_linear_solver_option(params);
  return std::make_unique<DiscreteLagrangianVI>(label, std::move(nodes), forcing, tolerance,
                                                static_cast<int>(max_iterations), linear);
}

}  // namespace geomint
