// The verify kit judges what a method computes, not the flags it declares (verify/verify.hpp):
// a "velocity Verlet" with a stale force that claims symplectic fails the
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

// A method flagged kGeneralLagrangian is also checked on the general kind
// (polar Kepler, the double pendulum, the charged particle); one without the flag is not run there.
TEST(GeneralChecks, ImplicitMidpointPassesEveryGeneralCheck) {
  for (const char* name : {"declared_order_general", "energy_without_drift_general",
                           "reversible_general", "momentum_maps_kept_general"}) {
    const verify::CheckResult result = verify::run_check("implicit_midpoint", name);
    std::printf("%s\n", verify::describe(result).c_str());
    EXPECT_TRUE(result.applies && result.passed) << verify::describe(result);
  }
}

TEST(GeneralChecks, Rk4HasItsOrderAndNoMoreThere) {
  const verify::CheckResult order = verify::run_check("rk4", "declared_order_general");
  std::printf("%s\n", verify::describe(order).c_str());
  EXPECT_TRUE(order.applies && order.passed) << verify::describe(order);
  EXPECT_FALSE(verify::run_check("rk4", "energy_without_drift_general").applies);
  EXPECT_FALSE(verify::general_check("rk4", "momentum_maps_kept_general").applies);
  // Negative control of the momentum check: RK4 does not keep the charged particle's canonical
  // angular momentum (measured 2.2e-6 where implicit_midpoint keeps 6.8e-15), so a method that
  // claimed variational with RK4's step would fail the 1e-12 bound.
  EXPECT_GT(verify::conserved_momentum_error("rk4", "charged_particle", 0.05, 10000), 1e-9);
  // Negative control of the reversibility check on the general kind: RK4 is not symmetric, and
  // on the double pendulum 20 steps forth and back miss the start by far more than the bound.
  EXPECT_GT(verify::reversibility_defect("rk4", "double_pendulum:theta1=0.3,theta2=-0.2", 0.05),
            1e-9);
}

TEST(GeneralChecks, SeparableOnlyMethodsAreNotRunOnTheGeneralKind) {
  for (const char* name : {"declared_order_general", "reversible_general"}) {
    const verify::CheckResult result = verify::run_check("stormer_verlet", name);
    EXPECT_FALSE(result.applies) << verify::describe(result);
    EXPECT_NE(result.detail.find("general"), std::string::npos) << result.detail;
  }
}

}  // namespace
}  // namespace geomint
