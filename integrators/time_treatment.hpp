// How a method treats the time of a time-dependent Hamiltonian H(q, p, t)
// (problems/structures/time_dependent.hpp): the `time` column of `geomint list methods` and
// docs/METHODS.md, and the rule applicable() uses to refuse such a problem.
#pragma once

#include <string>
#include <vector>

namespace geomint {

class Integrator;

enum class TimeTreatment {
  // The step never reads t (it calls M⁻¹p and ∇V(q) only): refused on H(q, p, t).
  kNone,
  // Each stage evaluates the field at its own stage time t_n + c_i h (Runge–Kutta stages, the
  // SPRKStep stage times of the splitting methods).
  kStageTimes,
  // t is a coordinate with conjugate momentum −H: the step is the method's map of the
  // autonomous extended system (no method in the catalogue does it yet).
  kExtendedPhaseSpace,
  // The whole step uses H(q, p, t_n) of its start time: consistent, but at most first order.
  kFrozenPerStep,
};

// "none", "stage_times", "extended_phase_space", "frozen_per_step".
const char* time_treatment_name(TimeTreatment treatment);

// A method whose time treatment is not the one derived from its flags (sprk's stage times or
// frozen time) derives from this too: time_treatment() asks it first.
class TreatsTime {
 public:
  virtual ~TreatsTime() = default;
  virtual TimeTreatment time_treatment() const = 0;
};

// The method's treatment: its TreatsTime answer, else stage times for the methods that see the
// problem only through Problem::first_order_rhs(t, y) (the flags first_order and
// general_lagrangian together: the library solvers, rk4), else none.
TimeTreatment time_treatment(const Integrator& method);

// The registry test specs whose treatment is not kNone (for messages and tests).
std::vector<std::string> time_dependent_methods();

}  // namespace geomint
