// One step implementation per method (docs/DESIGN.md §2, "The mass operator"): every registered
// method that runs both the separable and the general Lagrangian kind is stepped once on each,
// and a method that marks its step (integrators/step_implementation.hpp) must reach the same
// marked line on both — a second, kind-specific step fails here. The methods listed in
// kOneStepMethods must mark theirs.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"
#include "integrators/step_implementation.hpp"

namespace geomint {
namespace one_step_test {
namespace {

// The methods whose separable and general steps are one function today. generalized_leapfrog
// still carries a second step for the general kind (integrators/general_step.hpp); it joins this
// list when its steps are merged.
constexpr std::string_view kOneStepMethods[] = {"del",        "gauss", "hp", "implicit_midpoint",
                                                "lobatto3ab", "rk4",   "tao"};

// A problem of each kind with the same physics: Kepler in Cartesian and in polar coordinates.
constexpr const char* kSeparableSpec = "kepler:e=0.5";
constexpr const char* kGeneralSpec = "kepler:coordinates=polar,e=0.5";

struct Marked {
  bool ok = false;
  StepLocation where;
};

// One step of `method_spec` on `problem_spec` from its initial state, and the step it marked.
Marked step_once(const std::string& method_spec, const std::string& problem_spec) {
  const auto problem = make_problem(problem_spec);
  const auto method = make_integrator(method_spec);
  State state = problem->initial_state();
  const double h = problem->default_dt();
  method->reset(*problem, state, h);
  last_step_implementation = StepLocation{};
  Marked marked;
  marked.ok = method->step(*problem, state, h).ok;
  marked.where = last_step_implementation;
  return marked;
}

TEST(OneStepPerMethod, SeparableAndGeneralKindsRunTheSameStep) {
  const auto separable = make_problem(kSeparableSpec);
  const auto general = make_problem(kGeneralSpec);
  ASSERT_EQ(separable->kind(), ProblemKind::kSeparable);
  ASSERT_EQ(general->kind(), ProblemKind::kLagrangian);
  int both_kinds = 0;
  std::vector<std::string> marked_methods;
  for (const std::string& spec : integrator_test_specs()) {
    const auto method = make_integrator(spec);
    // Adaptive solvers take no fixed step(); they have no step of their own to compare.
    if (method->info().flags & kAdaptive) continue;
    if (!applicable(*method, *separable).ok || !applicable(*method, *general).ok) continue;
    ++both_kinds;
    SCOPED_TRACE(spec);
    const Marked on_separable = step_once(spec, kSeparableSpec);
    const Marked on_general = step_once(spec, kGeneralSpec);
    ASSERT_TRUE(on_separable.ok && on_general.ok);
    const bool marks = on_separable.where.line != 0 || on_general.where.line != 0;
    if (!marks) continue;
    marked_methods.push_back(method->info().name);
    EXPECT_EQ(
        std::string(on_separable.where.file_name) + ":" + std::to_string(on_separable.where.line),
        std::string(on_general.where.file_name) + ":" + std::to_string(on_general.where.line))
        << "the separable and the general kind ran different step implementations";
    EXPECT_STREQ(on_separable.where.function_name, on_general.where.function_name);
  }
  EXPECT_GE(both_kinds, 6);  // the kGeneralLagrangian family
  for (std::string_view name : kOneStepMethods) {
    EXPECT_NE(std::find(marked_methods.begin(), marked_methods.end(), name), marked_methods.end())
        << name << " marks no step implementation on both kinds";
  }
}

}  // namespace
}  // namespace one_step_test
}  // namespace geomint
