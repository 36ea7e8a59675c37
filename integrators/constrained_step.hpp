// The constrained variational step shared by hp and del (docs/METHOD.md §3; Marsden & West 2001,
// §3.5): the KKT system ∇E_k(v) + G(q_k)ᵀΛ = 0, g(q_k + hv) = 0 solved by SQP with an
// augmented-Lagrangian merit (minimize) or by plain Newton, and the momentum projection.
#pragma once

#include <string>

#include "integrators/newton.hpp"
#include "problems/problem.hpp"

namespace geomint {

struct ConstrainedStepResult {
  NewtonResult newton;  // iterations, solves, reason ("newton_max_iter", "line_search_failed", …)
  double constraint_residual = 0.0;   // max|g(q_k + hv)| at the last iterate
  double constraint_threshold = 0.0;  // what it had to reach (tol·‖G‖∞‖q‖∞)
  Vec impulse;                        // Λ = hλ, the multipliers' impulse over the step
};

// Solves, for v (in: the start iterate, out: the last accepted one) and Λ,
//   F₁ = R(v) + G(q_k)ᵀΛ = 0,   F₂ = g(q_k + hv)/h = 0,
// with, for rheonomic constraints (kTimeDependentConstraints), G(q_k, t_k) in F₁ and
// g(q_k + hv, t_k + h) in F₂ — RATTLE's extended-configuration form (integrators/rattle.cpp);
// where R = system.residual is the unconstrained step's residual (∇E_k when system.objective is
// E_k) and system.jacobian its symmetric Jacobian H. Converged when ‖F₁‖ ≤ tol·residual_scale
// (options.tolerance, as the unconstrained solve) and max|g| ≤ 1e-14·‖G‖∞‖q_{k+1}‖∞ (rattle's
// position test), then one polishing correction. The options choose the globalisation:
//  - line_search with system.objective: SQP; H gets the SPD safeguard (system.spd_shift) and the
//    step is line-searched on the augmented Lagrangian φ(v) = E_k(v) + Λ⁺ᵀG(q_k)v + (ρ/2)‖F₂‖²
//    at the new multiplier Λ⁺ = Λ + ΔΛ, for which the SQP direction always descends (ρ starts at
//    max M and grows ×10 when an iteration does not cut max|g| by a quarter);
//  - line_search without an objective: Newton backtracked on ½(‖F₁‖² + ρ²‖F₂‖²);
//  - no line search: plain Newton on (F₁, F₂), full steps, no safeguard (solver=newton).
// Each KKT solve goes through the Schur complement: the sparse LDLᵀ of H (as the unconstrained
// solve's default), then the m × m system G(q_{k+1})H⁻¹G(q_k)ᵀ (dense LU: not symmetric, since
// the two Jacobians sit at different nodes, and m is a few rods). Never throws on numerical
// trouble.
ConstrainedStepResult solve_constrained_step(const Problem& problem, const Vec& q_start,
                                             double t_start, double h, const NewtonSystem& system,
                                             const NewtonOptions& options, double residual_scale,
                                             Vec& v);

// "KKT Newton stopped after 3 iterations: residual 1e-3 > 1e-12, max|g| 1e-9 > 1e-15 (reason)".
std::string describe(const ConstrainedStepResult& result);

// p ← p − G(q)ᵀν with (G M⁻¹ Gᵀ)ν = G M⁻¹ p: the M⁻¹-orthogonal projection onto the tangent
// space at q (the second multiplier of RATTLE), so that G(q) M⁻¹ p = 0. Returns the impulse ν.
// Rheonomic constraints: G(q, t) M⁻¹ p + ∂g/∂t(q, t) = 0 instead, the velocity constraint of the
// moving manifold at time t (the time-free calls otherwise, so time-free runs are unchanged).
Vec project_momentum_to_tangent_space(const Problem& problem, double t, const Vec& q, Vec& p);

}  // namespace geomint
