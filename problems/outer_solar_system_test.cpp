// The outer solar system's initial invariants against an independent long-double evaluation of
// GNI Table 2.1 (typed in again here), and the planet-count parameter.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "problems/problem.hpp"

namespace geomint {
namespace outer_solar_system_test {
namespace {

struct BodyData {
  long double m, x, y, z, vx, vy, vz;
};

// GNI Table 2.1 (masses relative to the Sun, AU, AU/day), G = 2.95912208286e-4.
constexpr long double kG = 2.95912208286e-4L;
constexpr std::array<BodyData, 6> kTable = {{
    {1.00000597682L, 0, 0, 0, 0, 0, 0},
    {0.000954786104043L, -3.5023653L, -3.8169847L, -1.5507963L, 0.00565429L, -0.00412490L,
     -0.00190589L},
    {0.000285583733151L, 9.0755314L, -3.0458353L, -1.6483708L, 0.00168318L, 0.00483525L,
     0.00192462L},
    {0.0000437273164546L, 8.3101420L, -16.2901086L, -7.2521278L, 0.00354178L, 0.00137102L,
     0.00055029L},
    {0.0000517759138449L, 11.4707666L, -25.7294829L, -10.8169456L, 0.00288930L, 0.00114527L,
     0.00039677L},
    {1.0L / 1.3e8L, -15.5387357L, -25.2225594L, -3.1902382L, 0.00276725L, -0.00170702L,
     -0.00136504L},
}};

TEST(OuterSolarSystem, InitialInvariantsMatchLongDoubleEvaluation) {
  long double kinetic = 0, potential = 0;
  std::array<long double, 3> momentum{}, angular{};
  for (size_t i = 0; i < kTable.size(); ++i) {
    const BodyData& a = kTable[i];
    kinetic += a.m * (a.vx * a.vx + a.vy * a.vy + a.vz * a.vz) / 2;
    momentum[0] += a.m * a.vx, momentum[1] += a.m * a.vy, momentum[2] += a.m * a.vz;
    angular[0] += a.m * (a.y * a.vz - a.z * a.vy);
    angular[1] += a.m * (a.z * a.vx - a.x * a.vz);
    angular[2] += a.m * (a.x * a.vy - a.y * a.vx);
    for (size_t j = i + 1; j < kTable.size(); ++j) {
      const BodyData& b = kTable[j];
      const long double r = std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) +
                                      (a.z - b.z) * (a.z - b.z));
      potential -= kG * a.m * b.m / r;
    }
  }
  const auto problem = make_problem("outer_solar_system");
  ASSERT_EQ(problem->dof(), 18);
  const State start = problem->initial_state();
  const double energy = static_cast<double>(kinetic + potential);
  // The energy is a sum of same-sign pairs and a kinetic part of similar size: a few ulps.
  EXPECT_NEAR(problem->energy(start.q, start.p), energy, 1e-14 * std::abs(energy));
  EXPECT_LT(energy, 0.0);  // bound system
  const Vec p = problem->linear_momentum(start.q, start.p);
  const Vec l = problem->angular_momentum(start.q, start.p);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(p[k], static_cast<double>(momentum[k]), 1e-14 * std::abs(momentum[k])) << k;
    EXPECT_NEAR(l[k], static_cast<double>(angular[k]), 1e-13 * std::abs(angular[k])) << k;
  }
}

TEST(OuterSolarSystem, PlanetCountSelectsTheInnermostBodies) {
  // planets=1 is the Sun–Jupiter two-body problem: its energy from the table directly.
  const auto problem = make_problem("outer_solar_system:planets=1");
  ASSERT_EQ(problem->dof(), 6);
  const BodyData& sun = kTable[0];
  const BodyData& jupiter = kTable[1];
  const long double r =
      std::sqrt(jupiter.x * jupiter.x + jupiter.y * jupiter.y + jupiter.z * jupiter.z);
  const long double energy =
      jupiter.m * (jupiter.vx * jupiter.vx + jupiter.vy * jupiter.vy + jupiter.vz * jupiter.vz) /
          2 -
      kG * sun.m * jupiter.m / r;
  const State start = problem->initial_state();
  EXPECT_NEAR(problem->energy(start.q, start.p), static_cast<double>(energy),
              1e-14 * std::abs(static_cast<double>(energy)));
  // Jupiter's linearised frequency about the Sun is √(2GM/r³) at most (radial direction): the
  // Gershgorin bound may exceed it, but not by more than a small factor.
  const double radial = std::sqrt(2 * 2.95912208286e-4 * 1.00000597682 / std::pow(double(r), 3));
  EXPECT_GE(problem->omega_max(start.q), radial);
  EXPECT_LE(problem->omega_max(start.q), 3 * radial);
  EXPECT_THROW(make_problem("outer_solar_system:planets=6"), InputError);
  EXPECT_THROW(make_problem("outer_solar_system:planets=0"), InputError);
}

}  // namespace
}  // namespace outer_solar_system_test
}  // namespace geomint
