// Chaos indicators of a run (docs/CHAOS.md): the finite-time maximal Lyapunov
// exponent and MEGNO (Cincotta & Simó 2000, A&AS 147, 205, eqs. 2–3) from a tangent vector
// propagated along the computed trajectory, and the valid time against the reference.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "harness/observers.hpp"
#include "harness/reference.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

class MethodFactory;  // harness/run_spec.hpp

// How the tangent vector w is carried from step point y_k to y_{k+1}.
enum class ChaosTangent {
  kNone,              // not applicable (chaos_tangent_not_applicable says why)
  kLinearisedStep,    // w ← DΦ_h(y_k) w, DΦ the method's exact linearised step (step_tangent)
  kFiniteDifference,  // w ← (Φ_h(y_k + εw) − Φ_h(y_k − εw))/(2ε), Φ_h the computed map
};

// The exact linearised step where the method has one on `problem` (and the dense 2n×2n DΦ is
// affordable), else central differences of the computed map where the black-box map defect
// applies (canonical, unconstrained, unforced, at most kMaxMapDefectDof), else kNone.
ChaosTangent chaos_tangent(const Integrator& method, const Problem& problem);
// Why no tangent can be propagated, or "" when one can.
std::string chaos_tangent_not_applicable(const Integrator& method, const Problem& problem);

// The relative size ε/‖(q, p)‖₂ of the finite-difference tangent's perturbation: central
// differences have a truncation error O(ε²) against a round-off error O(u/ε); both are ~1e-11
// near ε ~ u^{1/3} ~ 5e-6.
inline constexpr double kChaosFiniteDifferenceStep = 5e-6;

// The running sums of the indicators over steps k = 1 … n of a run that starts at t₀, each step
// [t_{k−1}, t_k] with the log growth ℓ_k = ln(|w_k|/|w_{k−1}|) of the renormalised tangent:
//   lyapunov_max = Σ ℓ_k / (t_n − t₀),
//   Y(t_n)       = (2/(t_n − t₀)) Σ s_k ℓ_k, s_k = ½(t_{k−1} + t_k) − t₀ (the midpoint rule for
//                  ∫ s d ln|w|, exact when ln|w| is linear over the step: Y(t) = (2/t)∫ s
//                  (ẇ·w)/|w|²),
//   megno        = <Y>(t_n) = (1/(t_n − t₀)) ∫ Y ds (trapezoidal over the step points, Y(t₀) = 0).
// Y → 0 for an isochronous linear oscillator (|w| bounded), 2 on a KAM torus (|w| ~ t), ~λt
// and <Y> ~ λt/2 on a chaotic orbit.
class ChaosSums {
 public:
  void start(double t0);
  void add_step(double t_prev, double t, double log_growth);
  double lyapunov() const;
  double megno_instant() const;  // Y(t_n)
  double megno_mean() const;     // <Y>(t_n)
  long steps() const { return steps_; }

 private:
  double t0_ = 0, t_ = 0, log_sum_ = 0, weighted_sum_ = 0, y_ = 0, y_integral_ = 0;
  long steps_ = 0;
};

// The run's observer for `lyapunov_max` and `megno` (nullptr when neither is asked for or no
// tangent applies): both metrics, megno_final (Y at the last step point) and chaos_tangent_fd
// (0: the linearised step, 1: finite differences of the computed map). The tangent is taken from
// a fresh reset at every step point, as symplecticity_defect does, so the run is not disturbed.
// A tangent step that fails or overflows ends the sums: the metrics are NaN.
// The integrator that takes the tangents is made from `method`.
std::unique_ptr<Observer> make_chaos_observer(const MethodFactory& method, const Problem& problem,
                                              const std::vector<std::string>& names);

// The same with the tangent chosen (tests compare the two; nullptr where `kind` cannot be used).
std::unique_ptr<Observer> make_chaos_observer(const MethodFactory& method, const Problem& problem,
                                              const std::vector<std::string>& names,
                                              ChaosTangent kind);

// The relative error at which a chaotic run stops being a trajectory.
inline constexpr double kValidTimeErrorThreshold = 1e-2;

// The run's observer for `valid_time` (nullptr when not asked for, or when the problem has
// neither an exact solution nor `reference`): the first step-point time − t₀ at which the
// relative error ‖(q, p) − (q, p)_ref‖₂/‖(q, p)_ref‖₂ reaches kValidTimeErrorThreshold (against
// the exact solution, or the reference at the step points that land on its rows); the time
// reached when it never does (a lower bound: valid_time_reached = 0, else 1).
std::unique_ptr<Observer> make_valid_time_observer(
    const Problem& problem, std::shared_ptr<const ReferenceSolution> reference,
    const std::vector<std::string>& names);

}  // namespace geomint
