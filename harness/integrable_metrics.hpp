// Optional metrics of a run's invariants and of its one-step map that read a problem's structure
// (docs/USAGE.md "Optional structure metrics"): Flaschka's Toda invariants, the Kepler
// eccentricity (Laplace–Runge–Lenz) vector, and the action ∮p·dq of a loop carried by one step.
#pragma once

#include <string>

#include "harness/observers.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

class MethodFactory;  // harness/run_spec.hpp

// toda_invariants_err_max = max over step points and k = 1 … n of |tr Lᵏ − tr L₀ᵏ| / Σ|λ_i(L₀)|ᵏ:
// each of Flaschka's traces relative to the size its terms have (a trace itself may be 0, as
// tr L = −Σp/2 is). Up to this many particles (n matrix products per step point).
inline constexpr int kMaxTodaInvariantParticles = 64;

// lrl_err_max = max over step points of |e − e₀|, e the eccentricity vector (the
// Laplace–Runge–Lenz vector over μm, a pure number; problems/structures/kepler_orbit.hpp).

// The action of a closed loop of initial states before and after one step of the method.
struct LoopAction {
  double initial = 0;  // ∮p·dq of the loop (π r_q r_p for the circle)
  double image = 0;    // ∮p·dq of its image under the computed one-step map
  double error = 0;    // |image − initial| / |initial|; NaN when a step failed
  int points = 0;      // M at convergence (the last M tried when it did not converge)
  bool converged = false;
  std::string failure;
};
// The loop is the ellipse x(θ) = x₀ + δ(cos θ S_q ξ, sin θ S_p ξ) (ξ a fixed unit vector that
// weights every degree of freedom differently, S_q = diag(max(|q_i|, |q|∞/10)) and S_p alike,
// δ = 1/32: a coordinate's radius follows its own size, so polar Kepler's angle of many turns
// does not swing the radius r through 0), sampled at M equally spaced θ; every sample is stepped
// by a fresh
// integrator (computed_step, harness/map_defect.hpp). ∮p·dq is ∫p·q′(θ)dθ by the trapezoidal
// rule with the spectral derivative (exact for trigonometric polynomials of degree < M/2, so
// spectrally accurate on the smooth image), M = 16, 32, … doubled until two successive values
// agree to 1e-14 relative or to a thousandth of the change they measure, or their difference
// stops shrinking (halving at least: the sum's round-off is reached), or M = 2048.
LoopAction loop_action(const MethodFactory& method, const Problem& problem, const State& state,
                       double h);
LoopAction loop_action(const std::string& method_spec, const Problem& problem, const State& state,
                       double h);
// Why loop_action_err does not apply, or "": the map defect's conditions
// (map_defect_not_applicable) and an unconstrained problem (the loop would leave the manifold).
std::string loop_action_not_applicable(const Integrator& method, const Problem& problem, double h);

}  // namespace geomint
