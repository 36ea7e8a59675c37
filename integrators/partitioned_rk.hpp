// Implicit partitioned Runge–Kutta step on (q, p) shared by the Gauss–Legendre and Lobatto
// IIIA–IIIB families (GNI §II.2.2): stage equations solved by Newton on the stage velocities with
// the problem's sparse Hessian (integrators/newton.hpp).
#pragma once

#include <memory>

#include "integrators/high_order_coefficients.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

// The method Q_i = q₀ + hΣ_j a_ij V_j, M V_i = P_i = p₀ + hΣ_j â_ij f(Q_j, V_j, t₀ + c_j h),
// q₁ = q₀ + hΣ_j b_j V_j, p₁ = p₀ + hΣ_j b_j f(Q_j, V_j, t₀ + c_j h), with the total force
// f = −∇V + F. `info` is returned by info() as given (name, order, flags, reference); the
// stage solve's options `tol` and `max_iter` are read from `params` (shared by every tableau).
std::unique_ptr<Integrator> make_partitioned_rk(const coefficients::PartitionedTableau& tableau,
                                                MethodInfo info, Params& params);

}  // namespace geomint
