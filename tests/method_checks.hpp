// Property checks of a method shared by the registry-driven suites (docs/DESIGN.md §7):
// tests/methods_test.cpp off constraints, tests/constraints_test.cpp on the constraint manifold.
#pragma once

#include <cmath>
#include <string>

#include "integrators/integrator.hpp"

namespace geomint::test {

// Symmetric: Φ_{−h} ∘ Φ_h = id, checked over 20 steps forward and back; the distance from the
// start relative to |(q₀, p₀)|, or +inf when a step fails.
inline double reversibility_defect(const std::string& method, const std::string& problem_spec,
                                   double h) {
  const auto problem = make_problem(problem_spec);
  auto integrator = make_integrator(method);
  const State start = problem->initial_state();
  State state = start;
  integrator->reset(*problem, state, h);
  for (int k = 0; k < 20; ++k) {
    if (!integrator->step(*problem, state, h).ok) return INFINITY;
  }
  integrator->reset(*problem, state, -h);
  for (int k = 0; k < 20; ++k) {
    if (!integrator->step(*problem, state, -h).ok) return INFINITY;
  }
  const double scale = std::sqrt(start.q.squaredNorm() + start.p.squaredNorm());
  return std::sqrt((state.q - start.q).squaredNorm() + (state.p - start.p).squaredNorm()) / scale;
}

}  // namespace geomint::test
