// The step loop explicit methods run inside Integrator::advance (docs/DESIGN.md
// §2): the grid of harness/run.cpp with a step body that the compiler can inline, no status
// object per step, and the visitor called only when there is one.
#pragma once

#include <type_traits>
#include <variant>

#include "integrators/integrator.hpp"

namespace geomint {

// Runs `step(h)`, which advances `state` by h, over the grid from state.t.
template <class Step>
AdvanceOutcome run_grid(State& state, const StepGrid& grid, StepVisitor visit, Step&& step) {
  AdvanceOutcome outcome;
  double t = state.t;
  for (long k = 1; k <= grid.n; ++k) {
    const double t_next = grid.time(k);
    // A body that can fail returns its StepStatus; the run then ends as that failure after the
    // last good step (outcome.steps).
    if constexpr (std::is_same_v<std::invoke_result_t<Step&, double>, StepStatus>) {
      StepStatus status = step(t_next - t);
      if (!status.ok) {
        outcome.status = std::move(status);
        return outcome;
      }
    } else {
      step(t_next - t);
    }
    t = t_next;
    state.t = t;  // the grid time, as the per-step path sets it, for bodies that read state.t
    if (visit && !visit(state, k)) return outcome;
    outcome.steps = k;
  }
  return outcome;
}

// Base of explicit methods whose step is one body `Derived::advance_by(problem, state, h)`:
// step() and advance() both run it, so the two paths cannot drift apart. The body returns void
// (it cannot fail) or a StepStatus (position Verlet's implicit force kick can).
template <class Derived>
class ExplicitStepper : public Integrator {
 public:
  StepStatus step(const Problem& problem, State& state, double h) final {
    if constexpr (std::is_same_v<decltype(derived().advance_by(problem, state, h)), StepStatus>) {
      return derived().advance_by(problem, state, h);
    } else {
      derived().advance_by(problem, state, h);
      return StepStatus::success();
    }
  }
  AdvanceOutcome advance(const Problem& problem, State& state, const StepGrid& grid,
                         StepVisitor visit) final {
    // The body's own return type reaches run_grid, so a body that can fail ends the run there.
    return run_grid(state, grid, visit,
                    [&](double h) { return derived().advance_by(problem, state, h); });
  }

 private:
  Derived& derived() { return static_cast<Derived&>(*this); }
};

// Dispatches once per run on the problem's fixed gradient (problems/fixed_gradient.hpp): calls
// `fixed(gradient)` with the concrete functor, or returns false when the problem offers none.
template <class Fixed>
bool with_fixed_gradient(const Problem& problem, Fixed&& fixed) {
  return std::visit(
      [&](const auto& gradient) {
        if constexpr (std::is_same_v<std::decay_t<decltype(gradient)>, std::monostate>) {
          return false;
        } else {
          fixed(gradient);
          return true;
        }
      },
      problem.fixed_gradient());
}

}  // namespace geomint
