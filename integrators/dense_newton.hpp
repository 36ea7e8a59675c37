// The one dense Newton loop of the general-Lagrangian steps (integrators/general_step.cpp,
// integrators/generalized_leapfrog.cpp): a few unknowns, a non-symmetric Jacobian factorised with
// a partially pivoted LU, a relative stopping test and one polishing correction.
#pragma once

#include <functional>
#include <string>

#include "integrators/general_step.hpp"

namespace geomint {

// Smallest relative residual a dense step asks for (the same ε·16 as NewtonSolver's
// kRoundoffFloor): max(tolerance, this) is the `floor` passed to DenseNewtonSystem::converged.
inline constexpr double kDenseRoundoffFloor = 16 * 2.220446049250313e-16;

// The equation R(x) = 0 of one implicit stage. The callbacks may keep what they compute (the
// caller's force L_q, stage velocities): dense_newton says below which iterate that is at.
struct DenseNewtonSystem {
  // R(x) into `residual` (resized by the callback). Counts its own force evaluations.
  std::function<void(const Vec& x, Vec& residual)> residual;
  // The stopping test on the residual just evaluated, relative to the size of R's terms at that
  // iterate (which the residual callback records): e.g. ‖R‖∞ ≤ floor·scale.
  std::function<bool(const Vec& residual, double floor)> converged;
  // J = ∂R/∂x at x, dense and not necessarily symmetric.
  std::function<void(const Vec& x, DenseMatrix& jacobian)> jacobian;
  // After a polishing correction that did not lower ‖R‖, evaluate R at the kept x once more, so
  // that what the callbacks recorded is of the returned x (the DEL step's L_q, the partitioned RK
  // stages' velocities and forces). Off when the caller reads only x.
  bool reevaluate_after_rejected_polish = false;
  // Message prefix ("general del") and, for a method with several stage equations, the name of
  // this one's unknown ("p_half"), for the failure messages.
  std::string method;
  std::string unknown;
};

// Newton from x: evaluate R; non-finite → StepStatus "nan"; converged(max(tol, floor)) → one
// polishing correction with a fresh LU, kept only if ‖R‖∞ drops (invariants of a variational or
// symplectic step hold for the exact solve, not to the tolerance), then success; after
// newton.max_iterations updates → "newton_max_iter"; else x −= J⁻¹R. Counters: one
// factorisation and one linear solve per update and for the polish, one newton_iter per update
// (force evaluations are the residual callback's). x is the last iterate, also on failure.
StepStatus dense_newton(const DenseNewtonSystem& system, Vec& x,
                        const GeneralNewtonSettings& newton, Counters& counters);

// ‖x‖∞, 0 for an empty vector (max over no entries is not defined).
double dense_inf_norm(const Vec& x);

}  // namespace geomint
