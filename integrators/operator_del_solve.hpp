// The velocity equation of del and hp solved matrix-free (method option solve=), for a problem
// whose mass is an O(n) operator (LagrangianSystem::mass_is_recursive: articulated trees,
// rod_chain's joint form): every iteration costs a fixed number of O(n) recursions and no n × n
// object is ever formed.
#pragma once

#include <functional>

#include "integrators/newton.hpp"
#include "problems/problem.hpp"

namespace geomint {

class Params;

// How del and hp solve R(v) = 0 on an unconstrained problem (docs/METHODS.md "Articulated bodies"):
//  - kDense: NewtonSolver on the assembled Jacobian (SparseLU / LDLT);
//  - kMatrixFree: quasi-Newton v ← v − P⁻¹R(v) with P = M(q̄) + h²α(1−α)K₊(q̄) applied by the
//    problem's O(n) solve (LagrangianSystem::solve_mass_with_stiffness), after Lee, Liu, Park &
//    Srinivasa (WAFR 2016, §5), who take P = M; from the first update that contracts ‖R‖ by
//    less than kQuasiNewtonContraction, Newton–Krylov (below) for the rest of the solve;
//  - kNewtonKrylov: Newton with each update by GMRES on J·z directional differences of R,
//    right-preconditioned by the same P (measured slower here: docs/PERF.md);
//  - kAuto: kMatrixFree where the problem's mass is recursive, kDense elsewhere.
// Constrained problems always solve dense (their KKT form).
enum class VelocitySolve { kAuto, kDense, kMatrixFree, kNewtonKrylov };

// Reads `solve=` (InputError naming the allowed values; omitted from the canonical spec at its
// default, auto).
VelocitySolve read_velocity_solve_option(Params& params);

// The solve `choice` resolves to on `problem` (never kAuto).
VelocitySolve resolve_velocity_solve(VelocitySolve choice, const Problem& problem);

// x = P(v)⁻¹r, the preconditioner at iterate v.
using VelocityPreconditioner = std::function<void(const Vec& v, const Vec& r, Vec& x)>;

// P(v) = M(q̄) + h²α(1−α)K₊(q̄), q̄ = q₀ + αhv, for the α-rule velocity equation on `problem`
// (its LagrangianSystem's solve_mass_with_stiffness; the constant diagonal M on the separable
// kind). Counts nothing: matrix_free_velocity_solve counts its applications.
VelocityPreconditioner velocity_equation_preconditioner(const Problem& problem, const Vec& q0,
                                                        double h, double alpha);

// Solves system.residual(v) = 0 from v (overwritten by the last accepted iterate) without a
// Jacobian: `newton_krylov` false is the quasi-Newton iteration, true Newton–Krylov. The stopping
// test is NewtonSolver's: ‖R‖₂ ≤ max(tolerance, kRoundoffFloor)·residual_scale (no inner-term
// relaxation, so never looser), or a correction below kRoundoffFloor·‖v‖₂; with options.polish,
// corrections are then kept while they lower ‖R‖, down to kRoundoffFloor·residual_scale (the
// momentum maps are exact only for the exact solve; a linear rate needs more than one). Budget:
// options.max_iterations updates (quasi-Newton steps, or Newton updates of at most
// kMaxKrylovVectors products each), after which the result says "newton_max_iter"; a non-finite
// residual says "nan". NewtonResult counts updates (iterations), preconditioner applications
// (linear_solves) and residuals (residual_evals); factorizations stays 0.
NewtonResult matrix_free_velocity_solve(const NewtonSystem& system,
                                        const VelocityPreconditioner& precondition, Vec& v,
                                        double residual_scale, const NewtonOptions& options,
                                        bool newton_krylov);

// Krylov vectors per Newton–Krylov update (GMRES without restart).
inline constexpr int kMaxKrylovVectors = 20;
// Largest ‖R_{k+1}‖/‖R_k‖ of a quasi-Newton update before the solve turns to Newton–Krylov.
inline constexpr double kQuasiNewtonContraction = 0.5;

}  // namespace geomint
