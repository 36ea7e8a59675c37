// Discrete Lagrange–d'Alembert force impulses shared by the forced variational integrators
// (discrete_lagrangian.cpp, hamilton_pontryagin.cpp): the force_slot/force_at options and where
// each impulse is evaluated (docs/METHOD.md §2; Marsden & West 2001, §3.2).
#pragma once

#include <optional>

#include "integrators/integrator.hpp"

namespace geomint {

enum class ForceSlot { kMinus, kPlus, kSplit };
enum class ForceAt { kNode, kMidpoint };

// The step's impulse h·F is put into F_d⁻ (minus), F_d⁺ (plus) or half into each (split); each
// part is evaluated with the step velocity v at its own node (q_k for F_d⁻, q_{k+1} for F_d⁺) or,
// force_at=midpoint, at q_{k+½} = q_k + (h/2)v. Forced discrete Noether: the change of a momentum
// map J over a step is the sum of the impulses' torques about the points where they act, so for a
// frame-invariant force (zero net force and torque about its own evaluation point, e.g.
// spring_net's damping) the node choice keeps linear and angular momentum to solver tolerance. At
// the midpoint the impulse hF(q_{k+½}) is torque-free about q_{k+½} but acts at
// q_k = q_{k+½} − (h/2)v (minus) or q_{k+1} = q_{k+½} + (h/2)v (plus): each step changes the
// angular momentum by ∓(h²/2) Σ_i v_i × F_i = O(h²), i.e. O(h) over a time interval. split applies
// equal halves at both ends, whose torques cancel exactly, so it keeps angular momentum at the
// midpoint too. Linear momentum is kept in every case (Σ_i F_i = 0). docs/METHOD.md §2 reports
// drift for the minus slot only; measured here (results/dissipation,
// integrators/variational_test.cpp) minus and plus drift alike, with opposite signs, at the
// midpoint and neither drifts at the node. Default: split at the midpoint, docs/METHOD.md's
// "typical" F_d⁻ = F_d⁺ = (h/2)F(q_{k+½}, v) — second order, momenta kept, and on forced problems
// the same map as implicit_midpoint.
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

// The force_slot and force_at options (docs/METHOD.md §2).
Forcing read_forcing(Params& params);

// One step's data the impulses are evaluated from: q_k, t_k, h and the minus slot's weight w⁻
// (0 on unforced problems).
struct ImpulseStep {
  const Vec& q0;
  double t0;
  double h;
  double minus_weight;
};

// F_d⁻(v) = w⁻·h·F(x⁻, v, t⁻) with x⁻ = q_k (node) or q_k + (h/2)v (midpoint); one force
// evaluation, counted.
void minus_impulse(const Problem& problem, const Forcing& forcing, const ImpulseStep& step,
                   const Vec& v, Vec& impulse, Counters& counters);

// Adds −∂F_d⁻/∂v = w⁻·h·C(x⁻, v) with C = −∂F/∂v to `jacobian`. Exact at the node x⁻ = q_k; at
// the midpoint the (h/2)∂F/∂q part is left out (problems do not provide it): only the Newton
// matrix is approximate, the residual and hence the solution are exact (as in implicit_euler).
// Without force_jacobian_v the v-derivative is differenced (2·dim(v) counted force evaluations).
// `damping` is scratch space for C.
void add_minus_impulse_jacobian(const Problem& problem, const Forcing& forcing,
                                const ImpulseStep& step, const Vec& v, SparseMatrix& jacobian,
                                SparseMatrix& damping, Counters& counters);

// p_{k+1} += F_d⁺ = w⁺·h·F(x⁺, v, t⁺) with x⁺ = q_{k+1} (node) or q_k + (h/2)v (midpoint), from
// the step's `start` state; one force evaluation (into `force`), counted.
void add_plus_impulse(const Problem& problem, const Forcing& forcing, const State& start,
                      const Vec& q1, double h, const Vec& v, double plus_weight, Vec& p1,
                      Vec& force, Counters& counters);

// Decided once per run (a no-op once `symmetric` is set, or without force_jacobian_v): whether
// C = −∂F/∂v at (q, v, t) is symmetric — true for dissipative forces, false for gyroscopic ones —
// which decides between the symmetric (LDLT) and the general (LU) Newton factorisation.
void decide_damping_symmetry(const Problem& problem, const Vec& q, const Vec& v, double t,
                             SparseMatrix& damping, std::optional<bool>& symmetric);

}  // namespace geomint
