// geomint::verify: the registry-driven property checks of docs/DESIGN.md §7 as plain functions
// that any test framework can call (docs/VERIFY.md "Verify your own integrator"). Each returns a
// CheckResult with the measured figure and the bound it was held to; the in-tree suites
// (tests/methods_test.cpp, tests/constraints_test.cpp, integrators/variational_test.cpp) use them.
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "harness/run_spec.hpp"
#include "integrators/integrator.hpp"

namespace geomint::verify {

// Each check takes the method and the problem as objects (parsed once by the caller: a
// MethodFactory, a problem from parse_problem or a user's own) or as spec strings, a thin wrapper
// that parses them and reports them as given.
using ProblemPtr = std::shared_ptr<const Problem>;

struct CheckResult {
  std::string check;    // "declared_order", "energy_without_drift", "reversible", ...
  std::string method;   // method spec
  std::string problem;  // problem spec the check ran on
  bool applies = true;  // false: the method does not declare the property (then passed = true)
  bool passed = false;
  double measured = std::numeric_limits<double>::quiet_NaN();  // the figure compared
  double bound = std::numeric_limits<double>::quiet_NaN();     // limit, or the declared order
  std::string detail;                                          // what was measured, or why not
};
// One line: "PASS declared_order user_verlet on pendulum:theta0=1.5: measured 2.01 (bound ...)".
std::string describe(const CheckResult& result);

// A dt ladder dt0·2⁻ᵏ, k < levels, over [0, t_end] on a nonlinear problem (harness/order.hpp).
struct Ladder {
  std::string problem;
  double dt0 = 0.1;
  int levels = 7;
  double t_end = 5.0;
};
Ladder pendulum_ladder();  // pendulum:theta0=1.5, dt0 0.1, 7 levels, t_end 5
Ladder kepler_ladder();    // kepler:e=0.6, dt0 0.02, 7 levels, t_end 5

// The fitted order is the declared one ± tolerance (±0.3: DESIGN.md §7 for a least-squares slope
// over >= 3 asymptotic points). High orders reach the round-off plateau sooner, so the ladder
// starts ×4 larger from order 4 and ×16 from order 8, and orders >= 6 use two levels fewer.
CheckResult declared_order(const std::string& method, const Ladder& ladder, double tolerance = 0.3);
CheckResult declared_order(const MethodFactory& method, const Ladder& ladder,
                           double tolerance = 0.3);

// Symplectic ⇒ bounded energy error without drift: over `steps` (1e5) steps on `problem` (dt 0.05,
// or 0.2 from order 6 where round-off would look like drift), |trend of the per-window maxima| × T
// must stay below 10% of the maximum error, and that below 0.1. A drifting method (RK4, explicit
// Euler, a non-symplectic "Verlet") has trend × T ≈ err_max. measured = drift·T / err_max.
CheckResult energy_without_drift(const std::string& method,
                                 const std::string& problem = "pendulum:theta0=1.5",
                                 double steps = 1e5);
CheckResult energy_without_drift(const MethodFactory& method, const ProblemPtr& problem,
                                 double steps = 1e5);

// Symplectic ⇒ the map the method computes is symplectic: the black-box defect ‖JᵀΩJ − Ω‖_F/‖Ω‖_F
// of the finite-difference Jacobian of one computed step (harness/map_defect.hpp) stays under its
// own finite-difference error estimate (the floor) at the start of `problem` and after 10 and 20
// steps of h, and that floor under 1e-7. Judges what step() computes, not the declared flag: a
// "Verlet" with a stale force has a defect O(h²) far above the floor. measured = the largest
// defect / floor ratio (bound 1).
CheckResult symplectic_map(const std::string& method, const std::string& problem, double h);
CheckResult symplectic_map(const MethodFactory& method, const ProblemPtr& problem, double h);

// Symmetric ⇒ reversible: `steps` steps of h, then as many of −h, must return to the start
// (distance relative to |(q₀, p₀)|; +inf when a step fails).
double reversibility_defect(const std::string& method, const std::string& problem, double h,
                            int steps = 20);
double reversibility_defect(const MethodFactory& method, const ProblemPtr& problem, double h,
                            int steps = 20);
CheckResult reversible(const std::string& method, const std::string& problem, double h,
                       double bound);
CheckResult reversible(const MethodFactory& method, const ProblemPtr& problem, double h,
                       double bound);

// Variational (with an invariant discrete Lagrangian) ⇒ discrete Noether: the linear and angular
// momentum of a free spring network kept to round-off, max |ΔL|/|L₀| and |ΔJ|/|J₀| over the run.
struct MomentumErrors {
  bool ok = false;
  double linear = std::numeric_limits<double>::infinity();
  double angular = std::numeric_limits<double>::infinity();
  Vec angular_final;  // J_N − J₀
};
MomentumErrors momentum_errors(const std::string& method, const std::string& problem, double h,
                               int steps);
MomentumErrors momentum_errors(const MethodFactory& method, const ProblemPtr& problem, double h,
                               int steps);
CheckResult momentum_maps_kept(const std::string& method,
                               const std::string& problem = "spring_net:nx=4,ny=4", double h = 0.01,
                               int steps = 10000, double bound = 1e-12);
CheckResult momentum_maps_kept(const MethodFactory& method, const ProblemPtr& problem, double h,
                               int steps, double bound);

// Constrained ⇒ the position and velocity constraint residuals (constraint_err_max,
// constraint_vel_err_max of a run) stay below bound × the start's largest |q| and |v| (or
// |q|/(100 default steps) when released from rest). measured = the larger relative residual.
CheckResult constraint_kept(const std::string& method, const std::string& problem,
                            double steps_per_unit = 20, double units = 50, double bound = 1e-13);
CheckResult constraint_kept(const MethodFactory& method, const ProblemPtr& problem,
                            double steps_per_unit = 20, double units = 50, double bound = 1e-13);

// max_k |J(q_k, p_k) − J₀| / |J₀| over the conserved momentum maps `problem` offers (linear
// and/or angular; p_φ of polar Kepler, the canonical angular momentum of a charged particle about
// B), over `steps` steps of h; +inf when a step fails.
double conserved_momentum_error(const std::string& method, const std::string& problem, double h,
                                int steps);
double conserved_momentum_error(const MethodFactory& method, const ProblemPtr& problem, double h,
                                int steps);

// The general Lagrangian kind (docs/MECHANICS_GENERAL.md): for a method flagged
// kGeneralLagrangian the same properties on problems whose mass depends on q or whose Lagrangian
// has a term linear in v, kept cheap (a few 1e4 steps each):
//   declared_order_general       the Kepler ladder in polar coordinates (kepler:e=0.6,
//                                coordinates=polar, exact solution), fixed-step methods;
//   energy_without_drift_general double_pendulum (theta1 0.3, theta2 −0.2), 1e4 steps of 0.05,
//                                if symplectic;
//   reversible_general           double_pendulum (h 0.05) and charged_particle (h 0.1), bound
//                                1e-11, if symmetric;
//   momentum_maps_kept_general   p_φ of kepler:e=0.6,coordinates=polar (a cyclic coordinate) and
//                                the canonical angular momentum of charged_particle about B, 1e4
//                                steps, bound 1e-12, if variational.
// A method without the flag is not run there (applies = false: "not declared general-Lagrangian").
CheckResult general_check(const std::string& method, const std::string& name);

// The checks verify_method runs, by name: declared_order_pendulum, declared_order_kepler
// (fixed-step methods), energy_without_drift and symplectic_map (pendulum:theta0=1.5 at h 0.1,
// then kepler:e=0.6 at h 0.01; the first failure is reported) if symplectic, reversible_pendulum
// (h 0.1) and
// reversible_kepler (h 0.01, both bound 1e-11; if symmetric), momentum_maps_kept (if variational),
// constraint_kept on `constrained_problem` (constraints-only methods, which get no other check),
// then the four *_general checks of general_check().
std::vector<std::string> check_names();
// One named check, or applies = false when the method's flags do not call for it. InputError for
// an unknown name.
CheckResult run_check(const std::string& method, const std::string& name,
                      const std::string& constrained_problem = "cartesian_pendulum");
// Every check of check_names() in that order.
std::vector<CheckResult> verify_method(
    const std::string& method, const std::string& constrained_problem = "cartesian_pendulum");

}  // namespace geomint::verify
