// The verify kit judges what a method computes, not the flags it declares (verify/verify.hpp;
// issue 27, item 6): a "velocity Verlet" with a stale force that claims symplectic fails the
// black-box symplectic_map check, stormer_verlet passes it. Its own executable: registering a
// method changes the process-wide registry the other suites iterate.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "integrators/integrator.hpp"
#include "verify/verify.hpp"

namespace geomint {
namespace {

// The example project's broken method (examples/external_method/user_methods.cpp): the second
// kick reuses ∇V of the old position. Its map's Jacobian determinant is 1 + h²V''/(2m) ≠ 1.
class StaleVerlet final : public Integrator {
 public:
  MethodInfo info() const override {
    return {"stale_verlet", 2, kExplicit | kSymplectic | kSymmetric,
            "velocity Verlet with a stale second kick (broken on purpose)"};
  }
  StepStatus step(const Problem& problem, State& state, double h) override {
    eval_gradient(problem, state.q, gradient_);
    state.p -= 0.5 * h * gradient_;
    state.q += h * problem.inverse_mass().cwiseProduct(state.p);
    state.p -= 0.5 * h * gradient_;  // should be ∇V at the new q
    return StepStatus::success();
  }

 private:
  Vec gradient_;
};

const MethodRegistrar kStale({"stale_verlet",
                              "velocity Verlet with a stale force (test only)",
                              [](Params&) -> std::unique_ptr<Integrator> {
                                return std::make_unique<StaleVerlet>();
                              },
                              {}});

TEST(SymplecticMapCheck, StormerVerletPasses) {
  for (const char* problem : {"pendulum:theta0=1.5", "kepler:e=0.6"}) {
    const verify::CheckResult result =
        verify::symplectic_map("stormer_verlet", problem, problem[0] == 'p' ? 0.1 : 0.01);
    std::printf("%s\n", verify::describe(result).c_str());
    EXPECT_TRUE(result.applies && result.passed) << verify::describe(result);
  }
  const verify::CheckResult named = verify::run_check("stormer_verlet", "symplectic_map");
  EXPECT_TRUE(named.applies && named.passed) << verify::describe(named);
}

TEST(SymplecticMapCheck, StaleForceVerletThatClaimsSymplecticFails) {
  for (const char* problem : {"pendulum:theta0=1.5", "kepler:e=0.6"}) {
    const verify::CheckResult result =
        verify::symplectic_map("stale_verlet", problem, problem[0] == 'p' ? 0.1 : 0.01);
    std::printf("%s\n", verify::describe(result).c_str());
    EXPECT_TRUE(result.applies) << verify::describe(result);
    EXPECT_FALSE(result.passed) << "the stale force was not caught: " << verify::describe(result);
  }
  const verify::CheckResult named = verify::run_check("stale_verlet", "symplectic_map");
  EXPECT_TRUE(named.applies && !named.passed) << verify::describe(named);
}

// A method that does not claim symplectic is not judged by this check.
TEST(SymplecticMapCheck, SkippedWhenNotDeclared) {
  EXPECT_FALSE(verify::run_check("rk4", "symplectic_map").applies);
}

}  // namespace
}  // namespace geomint
