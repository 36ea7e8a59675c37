// The constrained discrete Euler–Lagrange step on the general Lagrangian kind (a mass M(q):
// andrews), shared by rattle, hp and del (Marsden & West 2001 §3.4–3.5; Leyendecker, Marsden &
// Ortiz 2008; GNI §VII.1.4): one dense Newton solve for the step velocity and the multipliers.
#pragma once

#include <optional>
#include <vector>

#include "integrators/forcing.hpp"
#include "integrators/general_step.hpp"
#include "integrators/tangent.hpp"

namespace geomint {

// The scheme: the quadrature discrete Lagrangian L_d = h Σ_j w_j L(q^j, v), q^j = q₀ + a_j h v,
// v = (q₁ − q₀)/h (trapezoid {(0,½), (1,½)}: RATTLE; midpoint {(½,1)}: hp and del), and the
// impulses of the force.
struct GeneralConstrainedScheme {
  std::vector<QuadratureNode> nodes;
  // F_d∓ as the forced hp/del steps take them (forcing.hpp) ...
  Forcing forcing;
  // ... or, for RATTLE, its own kicks: F_d⁻ = (h/2)F(q₀, M(q₀)⁻¹(p₀ − a(q₀)), t₀) (explicit, at
  // the start velocity) and F_d⁺ = (h/2)F(q₁, v, t₀ + h) — on a constant mass exactly rattle's
  // two half kicks (v = M⁻¹p½).
  bool rattle_kicks = false;
  // The position test max|g(q₁)| ≤ constraint_tolerance·‖G(q₁)‖∞‖q₁‖∞ (rattle's `tol`).
  double constraint_tolerance = 1e-14;
  // Project p₁ onto the tangent space at q₁ (the second multiplier μ); false: rattle's negative
  // control.
  bool velocity_projection = true;
};

// One step (q₀, p₀) → (q₁, p₁) of the constrained, forced DEL map of `scheme` on `system` (the
// problem's own LagrangianSystem, or its SeparableLagrangian view), with the problem's
// constraints g(q) = 0 (or g(q, t) = 0) and force F(q, v, t):
//   R₁(v, Λ) = Σ_j w_j [L_v(q^j, v) − h(1 − a_j) L_q(q^j, v)] − p₀ − F_d⁻ + G(q₀)ᵀΛ = 0,
//   R₂(v)    = ρ g(q₀ + hv, t₀ + h)/h = 0             (ρ = max M_ii(q₀): R₂ in momentum units),
//   p₁ = Σ_j w_j [L_v(q^j, v) + h a_j L_q(q^j, v)] + F_d⁺,
// then, with velocity_projection, p₁ ← p₁ − G(q₁)ᵀν with G(q₁)M(q₁)⁻¹(p₁ − a(q₁)) + g_t = 0.
// Λ is the start impulse (h/2)λ of RATTLE (rattle.cpp), hΛ-form of the constrained hp/del step
// (constrained_step.hpp); ν the end one. On a constant diagonal mass R₁ is the separable step's
// residual, so the map is the same one those steps solve (to round-off). Dense Newton
// (dense_newton.hpp) on the (n + m) unknowns, from v = M(q₀)⁻¹(p₀ − a) and Λ = 0; converged when
// ‖R₁‖∞ ≤ max(tol, 16ε)·(size of R₁'s terms) and the position test holds. Failures are step
// statuses ("newton_max_iter", "nan"), with `method` in their message.
StepStatus general_constrained_step(const Problem& problem, const LagrangianSystem& system,
                                    const GeneralConstrainedScheme& scheme, State& state, double h,
                                    const GeneralNewtonSettings& newton, Counters& counters,
                                    std::optional<ConstraintImpulses>& impulses,
                                    const char* method);

}  // namespace geomint
