// Modified energies of backward error analysis (Hairer, Lubich & Wanner, GNI §IX.3; docs/METHOD.md
// §10 "Modified energies"): H̃ = H + h²H₂ + O(h⁴) on separable H = ½pᵀM⁻¹p + V(q), with H₂ =
// a·pᵀM⁻¹∇²V M⁻¹p + b·∇VᵀM⁻¹∇V and (a, b) per method.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "harness/observers.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

class MethodFactory;  // harness/run_spec.hpp

// The coefficients of H₂ = curvature·vᵀ∇²V v + force·∇VᵀM⁻¹∇V (v = M⁻¹p) for one method.
struct ModifiedEnergyCorrection {
  double curvature = 0;  // a, the coefficient of pᵀM⁻¹∇²V M⁻¹p
  double force = 0;      // b, the coefficient of ∇VᵀM⁻¹∇V
};

// The correction of a registry method, when it is known: stormer_verlet (kick–drift–kick:
// a = 1/12, b = −1/24), position_verlet (drift–kick–drift: a = −1/24, b = 1/12) and
// implicit_midpoint (a = b = −1/24). std::nullopt for every other method.
std::optional<ModifiedEnergyCorrection> modified_energy_correction(const std::string& method_name);

// Why modified_energy_err_max does not apply to `method` on `problem` with step h, or "": it needs
// a known correction, a fixed step h > 0, and a separable, unforced, unconstrained problem with
// a Hessian.
std::string modified_energy_not_applicable(const Integrator& method, const Problem& problem,
                                           double h);

// H̃(q, p) = H(q, p) + h²H₂(q, p).
double modified_energy(const ModifiedEnergyCorrection& correction, const Problem& problem,
                       const Vec& q, const Vec& p, double h);

// The run's observer for `modified_energy_err_max` = max_k |H̃(q_k, p_k) − H̃(q_0, p_0)| / |H(q_0,
// p_0)| (the normalisation of energy_err_max; 1 when H₀ = 0), with modified_energy_err_slope and
// energy_err_slope, the least-squares slopes of log max|H̃ − H̃₀| and log max|H − H₀| against log h
// over h, h/2, h/4 (the run itself and two reruns of the same span in finish(); absent when a
// rerun fails or an error is exactly 0). nullptr when the metric is not asked for or does not
// apply: the columns then stay empty.
std::unique_ptr<Observer> make_modified_energy_observer(const MethodFactory& method,
                                                        const Problem& problem, double h,
                                                        const std::vector<std::string>& names);

}  // namespace geomint
