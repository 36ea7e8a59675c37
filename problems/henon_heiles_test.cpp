// Checks of the Hénon–Heiles problem beyond the registry suite: the initial state has the
// requested energy, the potential's known values, and energies that admit no real p₂.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <string>

#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace henon_heiles_test {
namespace {

TEST(HenonHeiles, InitialStateHasTheRequestedEnergy) {
  for (const char* spec : {"henon_heiles", "henon_heiles:energy=0.125,q1=0.2,q2=-0.1,p1=-0.05",
                           "henon_heiles:energy=0.125,q2=0,p1=0"}) {
    const auto problem = make_problem(spec);
    const State start = problem->initial_state();
    // The canonical spec records the energy, also when it is the default 1/12.
    const double requested = std::stod(Spec::parse(problem->spec()).values.at("energy"));
    EXPECT_NEAR(problem->energy(start.q, start.p), requested, 4 * DBL_EPSILON) << spec;
    EXPECT_GE(start.p[1], 0.0) << spec;
  }
}

TEST(HenonHeiles, PotentialAtTheSaddles) {
  // The three saddles of energy 1/6: (0, 1) and (±√3/2, −1/2).
  const auto problem = make_problem("henon_heiles");
  Vec q(2);
  q << 0, 1;
  EXPECT_NEAR(problem->potential(q), 1.0 / 6, 1e-15);
  q << std::sqrt(3.0) / 2, -0.5;
  EXPECT_NEAR(problem->potential(q), 1.0 / 6, 1e-15);
  Vec g;
  problem->gradient(q, g);
  EXPECT_NEAR(g.norm(), 0.0, 1e-15);
}

TEST(HenonHeiles, EnergyBelowThePotentialNamesTheKey) {
  // An energy below V(q) is refused.
  EXPECT_TRUE(
      test::input_error_names(make_problem, "henon_heiles:energy=0.001,q2=0.2", "energy=0.001"));
}

}  // namespace
}  // namespace henon_heiles_test
}  // namespace geomint
