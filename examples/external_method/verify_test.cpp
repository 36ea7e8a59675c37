// The user's methods through geomint::verify (docs/VERIFY.md "Verify your own integrator"): the
// correct position Verlet passes every check its flags call for; the stale-force Verlet must be
// flagged by the order, energy and symplectic-map checks — those tests expect the check to FAIL and
// pass when it does.
#include <verify/gtest.hpp>

#include "user_extensions.hpp"

namespace {

using geomint::verify::CheckResult;
using geomint::verify::describe;

// Registered before any test body runs (dynamic initialisation of this translation unit).
const bool kRegistered = (user::register_all(), true);

// Every check for the correct method: order on the pendulum and Kepler ladders, no energy drift,
// reversibility, momentum maps of a spring network.
GEOMINT_VERIFY_METHOD(UserPositionVerlet, "user_position_verlet");

// A method that claims the general Lagrangian kind: every check, the four *_general ones on polar
// Kepler, the double pendulum and the charged particle included.
GEOMINT_VERIFY_METHOD(UserGeneralMidpoint, "user_general_midpoint");

TEST(UserPositionVerlet, SecondOrderOnTheUserProblem) {
  ASSERT_TRUE(kRegistered);
  GEOMINT_VERIFY_EXPECT_PASSED(
      geomint::verify::declared_order("user_position_verlet", {"user_quartic", 0.1, 6, 5.0}));
}

// The broken method declares order 2, symplectic and symmetric; the kit must refuse the claims.
TEST(UserStaleVerletIsFlagged, DeclaredOrderCheckFails) {
  const CheckResult result =
      geomint::verify::declared_order("user_stale_verlet", geomint::verify::pendulum_ladder());
  EXPECT_FALSE(result.passed) << "the stale force was not caught: " << describe(result);
  EXPECT_NEAR(result.measured, 1.0, 0.3) << describe(result);  // first order, not the claimed 2
}

TEST(UserStaleVerletIsFlagged, EnergyCheckFails) {
  const CheckResult result = geomint::verify::energy_without_drift("user_stale_verlet");
  EXPECT_FALSE(result.passed) << "the energy drift was not caught: " << describe(result);
}

// The black-box check: the Jacobian of the map step() computes is not symplectic, whatever the
// flags say (defect ~5e-3 against a finite-difference floor ~4e-13 on the pendulum at h = 0.1).
TEST(UserStaleVerletIsFlagged, SymplecticMapCheckFails) {
  const CheckResult result = geomint::verify::run_check("user_stale_verlet", "symplectic_map");
  EXPECT_TRUE(result.applies) << describe(result);
  EXPECT_FALSE(result.passed) << "the non-symplectic map was not caught: " << describe(result);
}

TEST(UserStaleVerletIsFlagged, EveryCheckOfTheKitThatApplies) {
  int failed = 0;
  for (const CheckResult& result : geomint::verify::verify_method("user_stale_verlet")) {
    std::printf("%s\n", describe(result).c_str());
    if (result.applies && !result.passed) ++failed;
  }
  EXPECT_GE(failed, 4);  // both order ladders, the energy check and the map check at least
}

}  // namespace
