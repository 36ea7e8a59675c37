// Steps of the variational and Hamiltonian-side schemes on the general Lagrangian kind
// L = ½vᵀM(q)v + a(q)ᵀv − V(q) (docs/MECHANICS_GENERAL.md §2–3; Marsden & West 2001 §2.1, §2.6):
// dense Newton on the non-symmetric step Jacobian with a partially pivoted LU.
#pragma once

#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"

namespace geomint {

// MethodInfo::flags bit kGeneralLagrangian (integrator.hpp): without it a method assumes the
// separable constant-mass form (its step uses M⁻¹p and ∇V: Verlet, symplectic Euler, Newmark,
// RATTLE, hp's minimisation form), and applicable() refuses it on is_non_separable problems.

// The registry's test specs flagged kGeneralLagrangian (for refusal messages and tests).
std::vector<std::string> general_lagrangian_methods();

struct GeneralNewtonSettings {
  double tolerance = 1e-12;  // relative to the terms each residual balances
  int max_iterations = 50;
};

// The α-rule DEL step, L_d = h L((1−α)q₀ + αq₁, (q₁ − q₀)/h), in position–momentum form:
//   solve  L_v(q̄, v̄) − h(1−α) L_q(q̄, v̄) = p₀   for v̄ = (q₁ − q₀)/h,
//   then   p₁ = L_v(q̄, v̄) + hα L_q(q̄, v̄).
// Counts force evaluations (one per L_q), Newton iterations and linear solves in `counters`.
StepStatus general_del_step(const LagrangianSystem& system, State& state, double h, double alpha,
                            const GeneralNewtonSettings& newton, Counters& counters);

// The implicit midpoint rule on the Hamiltonian view, z = (q, p), z₁ = z₀ + h f((z₀ + z₁)/2),
// f = (v(q, p), L_q(q, v(q, p))) (symplectic for any H).
StepStatus general_implicit_midpoint_step(const LagrangianSystem& system, State& state, double h,
                                          const GeneralNewtonSettings& newton, Counters& counters);

}  // namespace geomint
