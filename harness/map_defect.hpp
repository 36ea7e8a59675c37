// The black-box symplecticity defect of the computed one-step map (GNI §VI.2,
// Def. 2.2): ‖JᵀΩJ − Ω‖_F/‖Ω‖_F with J the Richardson-extrapolated central-difference Jacobian of
// Φ_h: (q, p) ↦ (q', p') as the method's real steps (and nonlinear solves) compute it.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "harness/observers.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

class MethodFactory;  // harness/run_spec.hpp

// The defect of one map at one state, with the estimated error of the finite differences.
struct MapDefect {
  double defect = 0;         // ‖JᵀΩJ − Ω‖_F/‖Ω‖_F; NaN when a step failed
  double fd_error = 0;       // estimated error of `defect` from the finite-difference J
  double jacobian_norm = 0;  // ‖J‖_F
  std::string failure;       // why the defect is NaN when a step or a projection failed
};

// Relative sizes δ tried for the coarsest of three central-difference steps (δ, δ/2, δ/4 times
// the scale of q or of p), halving: two Richardson extrapolations, each with a truncation error
// O(δ⁴) against the map's noise η amplified as η/δ, balance near δ ~ η^{1/5}: 1e-3 for round-off
// (η ~ 1e-16), 3e-2 for an adaptive solver at rtol 1e-8. The δ with the smallest error estimate
// is kept (tests/map_defect_test.cpp measures the floor).
inline constexpr std::array<double, 6> kMapDefectRelativeSteps = {1.0 / 16,  1.0 / 32,  1.0 / 64,
                                                                  1.0 / 128, 1.0 / 256, 1.0 / 512};

// Why the black-box defect does not apply to `method` on `problem` with step h, or "": it needs
// a canonical unforced problem (a (q, p) pair and a Hamiltonian map; constrained ones are
// measured on their constraint manifold, computed_manifold_map) of at most
// kMaxMapDefectDof degrees of freedom, and h > 0 (an adaptive solver's map is its integration
// over h, so a run of one needs --dt).
std::string map_defect_not_applicable(const Integrator& method, const Problem& problem, double h);
// 32n steps per state: more than this many degrees of freedom costs more than a run.
inline constexpr int kMaxMapDefectDof = 100;

// The one-step map as the harness takes it: a fresh `method` reset at `state`, then one step()
// (fixed-step methods) or adaptive_step()s up to state.t + h (adaptive ones). False on failure.
bool computed_step(Integrator& method, const Problem& problem, State& state, double h);
// The same with the failed step's status.
StepStatus computed_step_status(Integrator& method, const Problem& problem, State& state, double h);

// J at `state` with the estimate ‖E‖_F of its error (empty J when a step fails), for the δ of
// kMapDefectRelativeSteps with the smallest estimate: 2n(|steps| + 2) pairs of steps.
struct MapJacobian {
  Eigen::MatrixXd jacobian;
  double error = 0;
  double relative_step = 0;  // the δ kept
};
MapJacobian computed_map_jacobian(Integrator& method, const Problem& problem, const State& state,
                                  double h);

// On a constrained problem (kConstraints) the map acts on T*Q_c = {g(q) = 0, G(q)M⁻¹p = 0} (GNI
// §VII.1; Leimkuhler & Reich 2004 §7): the chart directions v_j (2k of them, k = n − m: an
// orthonormal basis T of ker G(q) for q, M T (TᵀMT)⁻¹ for p) are moved off the state by ±ε,
// projected back onto the manifold (Newton along M⁻¹Gᵀ, then the M⁻¹-orthogonal momentum
// projection) and stepped; central differences of the projected starts give a tangent basis U of
// the manifold, those of the images JU, Richardson-extrapolated like computed_map_jacobian (with
// the δ of the smallest first-order effect on the defect). 2k(|steps| + 2) pairs of steps.
struct ManifoldMap {
  Eigen::MatrixXd tangent_basis;  // U, 2n × 2k; empty when a step or a projection fails
  Eigen::MatrixXd image;          // J U, 2n × 2k
  double basis_error = 0;         // ‖E_U‖_F, ‖E_JU‖_F: the extrapolations' difference
  double image_error = 0;
  double relative_step = 0;
  double weight = 0;    // ‖U‖‖E_U‖ + ‖JU‖‖E_JU‖, what the δ kept minimises
  std::string failure;  // why U is empty: the failed step's reason and message, or the projection
};
ManifoldMap computed_manifold_map(Integrator& method, const Problem& problem, const State& state,
                                  double h);

// The defect at `state` from computed_map_jacobian: central differences of computed_step at steps
// s·δ·2^-m (m = 0, 1, 2; s the scale of the q or p block: its max norm, or the step's change of
// it, or 1), extrapolated pairwise (R = (4D(δ/2) − D(δ))/3); J is the finer extrapolation and the
// difference of the two extrapolations, ‖E‖_F, bounds its error (truncation and the map's noise
// alike), so that fd_error = (2‖J‖_F‖E‖_F + 4ε‖J‖²_F)/‖Ω‖_F (first order in E: JᵀΩJ changes by
// EᵀΩJ + JᵀΩE). NaN defect when a step fails. On a constrained problem, from
// computed_manifold_map: ‖(JU)ᵀΩ(JU) − UᵀΩU‖_F/‖UᵀΩU‖_F (the symplectic form restricted to
// T*Q_c, GNI Theorem VII.1.5), with fd_error = (2‖U‖‖E_U‖ + 2‖JU‖‖E_JU‖ + 4ε(‖U‖² +
// ‖JU‖²))/‖UᵀΩU‖_F; on an unconstrained problem (U = I) both are the formulas above.
MapDefect symplecticity_defect_map(const MethodFactory& method, const Problem& problem,
                                   const State& state, double h);
// The same for a given integrator (reset at every perturbed start).
MapDefect symplecticity_defect_map(Integrator& method, const Problem& problem, const State& state,
                                   double h);

// The same from a given J (2n×2n, (q₁…qₙ, p₁…pₙ)).
double map_defect_of_jacobian(const Eigen::MatrixXd& jacobian);

// The run's observer for `symplecticity_defect_map` (nullptr when not asked for or not
// applicable): the defect at the initial state, the first step point at or after t_end/2 and the
// last step point, reported as the max over them (symplecticity_defect_map) with the largest
// finite-difference error estimate (symplecticity_defect_map_fd_err), and the slope
// log₂(max defect at h / max defect at h/2) at the same states (symplecticity_defect_map_slope:
// p + 1 for a non-symplectic map of order p) when both stand above ten times their error
// estimate and the method is not adaptive.
std::unique_ptr<Observer> make_map_defect_observer(const MethodFactory& method,
                                                   const Problem& problem, double h,
                                                   const std::vector<std::string>& names);

}  // namespace geomint
