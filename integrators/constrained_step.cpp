// The constrained variational step's KKT solve and momentum projection (docs/METHOD.md §3;
// SQP with an augmented-Lagrangian merit: Nocedal & Wright, "Numerical Optimization", §18.3).
#include "integrators/constrained_step.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// rattle's default: the position constraint is kept at round-off relative to the state's scale.
constexpr double kConstraintTolerance = 1e-14;
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// The residuals at one iterate (v, Λ).
struct KktPoint {
  Vec v, impulse, q_next, g, F1, F2;
  double f1_norm = 0.0, g_norm = 0.0;
  double multiplier_force_norm = 0.0;  // ‖G₀ᵀΛ‖: F₁ cannot be rounded below ε times it
  bool finite = false;
};

// g and G at one time: g(q, t) and G(q, t) for rheonomic constraints, the time-free calls
// otherwise (so that time-free results stay bit-identical).
struct ConstraintsAt {
  ConstraintsAt(const Problem& problem, double t_in)
      : constraints(constraints_of(problem)), t(t_in), rheonomic(constraints.time_dependent()) {}
  void value(const Vec& q, Vec& g) const {
    rheonomic ? constraints.constraint_at(t, q, g) : constraints.constraint(q, g);
  }
  void jacobian(const Vec& q, SparseMatrix& G) const {
    rheonomic ? constraints.constraint_jacobian_at(t, q, G) : constraints.constraint_jacobian(q, G);
  }
  const HolonomicConstraints& constraints;
  double t;
  bool rheonomic;
};

// ‖G‖∞, the largest absolute row sum.
double row_sum_norm(const Eigen::MatrixXd& G) {
  return G.rows() > 0 ? G.cwiseAbs().rowwise().sum().maxCoeff() : 0.0;
}

// H (or H + μS) factorised once, solved for the m + 1 right-hand sides of the Schur complement.
// Symmetric H (every unforced step) through the sparse LDLᵀ, otherwise sparse LU.
class StepMatrixSolver {
 public:
  // False when the factorisation fails or, with `need_positive`, when a pivot of D is ≤ 0.
  bool factorise(const SparseMatrix& H, bool symmetric, bool need_positive) {
    symmetric_ = symmetric;
    if (symmetric) {
      ldlt_.compute(H);
      if (ldlt_.info() != Eigen::Success) return false;
      return !need_positive || ldlt_.vectorD().minCoeff() > 0.0;
    }
    lu_.compute(H);
    return lu_.info() == Eigen::Success;
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) {
    return symmetric_ ? Eigen::MatrixXd(ldlt_.solve(rhs)) : Eigen::MatrixXd(lu_.solve(rhs));
  }

 private:
  bool symmetric_ = true;
  Eigen::SimplicialLDLT<SparseMatrix> ldlt_;
  Eigen::SparseLU<SparseMatrix> lu_;
};

}  // namespace

ConstrainedStepResult solve_constrained_step(const Problem& problem, const Vec& q_start,
                                             double t_start, double h, const NewtonSystem& system,
                                             const NewtonOptions& options, double residual_scale,
                                             Vec& v) {
  ConstrainedStepResult out;
  NewtonResult& result = out.newton;
  const ConstraintsAt start(problem, t_start), next(problem, t_start + h);
  SparseMatrix jacobian_start;
  start.jacobian(q_start, jacobian_start);
  // G(q_k): the multiplier force sits at the known node (docs/METHOD.md §3), so F₁ is linear in Λ
  // and H needs no constraint-curvature term.
  const Eigen::MatrixXd G0 = Eigen::MatrixXd(jacobian_start);
  const Eigen::MatrixXd G0_transpose = G0.transpose();
  const long m = G0.rows();
  // ρ turns ‖F₂‖² (a velocity squared) into the units of E_k; any ρ ≥ 0 keeps the SQP direction a
  // descent direction of the merit, ρ > 0 makes the merit reward feasibility.
  double rho = MassOperator(problem).max_diagonal(q_start);
  double threshold = std::max(options.tolerance, kRoundoffFloor) * residual_scale;
  result.threshold = threshold;

  const auto evaluate = [&](const Vec& x, const Vec& impulse, KktPoint& point) {
    point.v = x;
    point.impulse = impulse;
    point.q_next = q_start + h * x;
    next.value(point.q_next, point.g);
    system.residual(x, point.F1);
    ++result.residual_evals;
    const Vec multiplier_force = G0_transpose * impulse;
    point.multiplier_force_norm = robust_norm(multiplier_force);
    point.F1 += multiplier_force;
    point.F2 = point.g / h;
    point.finite = point.F1.allFinite() && point.g.allFinite() && point.q_next.allFinite();
    point.f1_norm = robust_norm(point.F1);
    point.g_norm = m > 0 ? point.g.lpNorm<Eigen::Infinity>() : 0.0;
  };

  const bool minimise = options.line_search && static_cast<bool>(system.objective);
  const bool safeguard = minimise && system.symmetric && system.spd_shift.nonZeros() > 0;
  KktPoint current, trial;
  evaluate(v, Vec::Zero(m), current);
  StepMatrixSolver solver;
  bool polishing = false;
  for (int iteration = 0;; ++iteration) {
    if (!current.finite) {
      result.reason = "nan";
      break;
    }
    SparseMatrix jacobian_next;
    next.jacobian(current.q_next, jacobian_next);
    const Eigen::MatrixXd G1 = Eigen::MatrixXd(jacobian_next);
    const double g_threshold =
        kConstraintTolerance * row_sum_norm(G1) * current.q_next.lpNorm<Eigen::Infinity>();
    result.residual_norm = current.f1_norm;
    out.constraint_residual = current.g_norm;
    out.constraint_threshold = g_threshold;
    // F₁ = ∇E_k + G₀ᵀΛ is a difference of terms as large as the multiplier force: its round-off
    // floor grows with ‖G₀ᵀΛ‖ (reactions of pinned nodes), which the unconstrained scale does not
    // see.
    threshold = std::max(threshold, kRoundoffFloor * current.multiplier_force_norm);
    result.threshold = threshold;
    const bool converged = current.f1_norm <= threshold && current.g_norm <= g_threshold;
    if (converged && (polishing || !options.polish)) {
      result.converged = true;
      break;
    }
    if (!converged && iteration >= options.max_iterations) {
      result.reason = "newton_max_iter";
      break;
    }
    polishing = converged;

    SparseMatrix H;
    system.jacobian(v, H);
    if (system.inner_term_scale) {
      threshold =
          std::max(threshold, kRoundoffFloor * (residual_scale + system.inner_term_scale()));
      result.threshold = threshold;
    }
    ++result.factorizations;
    bool factorised = solver.factorise(H, system.symmetric, safeguard);
    if (!factorised && safeguard) {
      // The SPD safeguard of the unconstrained minimiser (NewtonSystem::spd_shift): H + μM.
      ++result.shifted_iterations;
      double mu = std::max(options.spd_shift_initial, result.last_shift / options.spd_shift_growth);
      for (int shift = 0; shift < options.max_spd_shifts && !factorised; ++shift) {
        SparseMatrix shifted = H + mu * system.spd_shift;
        ++result.shift_factorisations;
        ++result.factorizations;
        factorised = solver.factorise(shifted, true, true);
        if (factorised) {
          H = std::move(shifted);
          result.last_shift = mu;
        }
        mu *= options.spd_shift_growth;
      }
    }
    if (!factorised) {
      result.reason = "linear_solve_failed";
      break;
    }
    // [H G₀ᵀ; G₁ 0][Δv; ΔΛ] = −[F₁; F₂] by the Schur complement S = G₁H⁻¹G₀ᵀ.
    Eigen::MatrixXd rhs(v.size(), m + 1);
    rhs.leftCols(m) = G0_transpose;
    rhs.col(m) = current.F1;
    const Eigen::MatrixXd solved = solver.solve(rhs);
    ++result.linear_solves;
    const Eigen::MatrixXd Y = solved.leftCols(m);
    const Vec y = solved.col(m);
    const Vec delta_impulse = (G1 * Y).partialPivLu().solve(current.F2 - G1 * y);
    const Vec delta_v = -y - Y * delta_impulse;
    ++result.iterations;
    if (!delta_v.allFinite() || !delta_impulse.allFinite()) {
      result.reason = "linear_solve_failed";
      break;
    }

    if (polishing) {
      // One more correction after convergence, kept only if it lowers ‖F₁‖ and keeps g.
      evaluate(v + delta_v, current.impulse + delta_impulse, trial);
      if (trial.finite && trial.f1_norm <= current.f1_norm && trial.g_norm <= g_threshold) {
        result.polished = true;
        current = trial;
        v = current.v;
      }
      result.residual_norm = current.f1_norm;
      out.constraint_residual = current.g_norm;
      result.converged = true;
      break;
    }
    if (!options.line_search) {
      evaluate(v + delta_v, current.impulse + delta_impulse, current);
      v = current.v;
      continue;
    }

    // Backtracking: on the augmented Lagrangian at Λ⁺ (minimise), else on ½(‖F₁‖² + ρ²‖F₂‖²).
    const Vec impulse_plus = current.impulse + delta_impulse;
    const auto merit = [&](const KktPoint& point) {
      if (minimise) {
        return system.objective(point.v) + impulse_plus.dot(G0 * point.v) +
               0.5 * rho * point.F2.squaredNorm();
      }
      return 0.5 * (point.F1.squaredNorm() + rho * rho * point.F2.squaredNorm());
    };
    const double merit_start = merit(current);
    // Directional derivatives: HΔv + G₀ᵀΔΛ = −F₁ − G₀ᵀ(Λ⁺ − Λ − ΔΛ) and G₁Δv = −F₂ give
    // −ΔvᵀHΔv − ρ‖F₂‖² (minimise; H after the safeguard is SPD), −2·merit (exact Newton).
    const double slope =
        minimise ? -delta_v.dot(H * delta_v) - rho * current.F2.squaredNorm() : -2 * merit_start;
    // Changes of the merit below its rounding are noise, as in NewtonSolver's line search.
    const double noise =
        minimise ? 8 * kEpsilon *
                       (std::max(system.objective_scale, std::abs(merit_start)) +
                        std::abs(impulse_plus.dot(G0 * v)) + 0.5 * rho * current.F2.squaredNorm())
                 : 0.5 * std::pow(kRoundoffFloor * residual_scale, 2);
    double step = 1.0;
    bool accepted = false;
    for (int backtrack = 0; backtrack <= options.max_backtracks; ++backtrack, step *= 0.5) {
      evaluate(v + step * delta_v, current.impulse + step * delta_impulse, trial);
      // Filter fallback (Fletcher & Leyffer 2002): a step that cuts the stationarity residual
      // without losing feasibility is also taken. Near a solution of a stiff step the merit's
      // change falls below the rounding of its large terms, while Newton still cuts ‖F₁‖
      // quadratically: measured on the pinned spinning elastic bar, where the merit test alone
      // stalled at ‖F₁‖ ~ 1e-7 (docs/METHODS.md "Holonomic constraints").
      const bool merit_decreases =
          merit(trial) <= merit_start + options.armijo * step * slope + noise;
      const bool residual_decreases =
          trial.f1_norm <= (1 - options.armijo * step) * current.f1_norm &&
          trial.g_norm <= std::max(current.g_norm, g_threshold);
      if (trial.finite && (merit_decreases || residual_decreases)) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      result.reason = "line_search_failed";
      break;
    }
    // Augmented-Lagrangian rule (Nocedal & Wright §17.4): when the constraint violation does not
    // fall by a quarter, the penalty is too weak against E_k's descent off the manifold (a
    // concave V makes E_k unbounded below there): stiffen it for the rest of the solve.
    if (minimise && trial.g_norm > 0.25 * current.g_norm && trial.g_norm > g_threshold) rho *= 10;
    current = trial;
    v = current.v;
  }
  v = current.finite ? current.v : v;
  out.impulse = current.impulse;
  return out;
}

std::string describe(const ConstrainedStepResult& result) {
  const NewtonResult& newton = result.newton;
  return fmt::format(
      "KKT Newton {} {} iterations: residual {:.3g} (tolerance {:.3g}), max|g| {:.3g} "
      "(tolerance {:.3g}){}",
      newton.converged ? "converged in" : "stopped after", newton.iterations, newton.residual_norm,
      newton.threshold, result.constraint_residual, result.constraint_threshold,
      newton.converged ? "" : fmt::format(" ({})", newton.reason));
}

Vec project_momentum_to_tangent_space(const Problem& problem, double t, const Vec& q, Vec& p) {
  const ConstraintsAt at(problem, t);
  SparseMatrix jacobian;
  at.jacobian(q, jacobian);
  const Eigen::MatrixXd G = Eigen::MatrixXd(jacobian);
  const Eigen::MatrixXd G_Minv = G * MassOperator(problem).constant_inverse_diagonal().asDiagonal();
  Vec rate = G_Minv * p;
  if (at.rheonomic) {
    Vec g_t, a_t;
    at.constraints.constraint_time_terms(t, q, MassOperator(problem).solve(q, p), g_t, a_t);
    rate += g_t;  // G M⁻¹p + ∂g/∂t = 0 at t
  }
  const Vec nu = (G_Minv * G.transpose()).ldlt().solve(rate);
  p -= G.transpose() * nu;
  return nu;
}

}  // namespace geomint
