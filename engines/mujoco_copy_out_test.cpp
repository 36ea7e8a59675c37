// The MuJoCo adapter's copy out (docs/ENGINES.md "Adapter overhead"): after an Euler or implicit
// step, p = M(θ)θ̇ comes from MuJoCo's own mass matrix at the new state, which must be the
// problem's momentum (the pendulum identification tests check the trajectory to round-off).
#include <gtest/gtest.h>

#include "engines/mujoco.hpp"
#include "engines/planar_chain.hpp"
#include "integrators/integrator.hpp"

namespace geomint::engines {
namespace {

TEST(MujocoCopyOut, MomentumFromMujocosMassMatrixIsTheProblemsAfterEveryStep) {
  for (const std::string spec :
       {"pendulum:omega0=2.5,theta0=1.2,v0=0.3",
        "double_pendulum:m1=1.3,m2=0.7,l1=0.9,l2=1.6,g=2.5,theta1=0.3,theta2=-0.2,omega1=0.4",
        "rod_chain:coordinates=joint,n=10,mass_ratio=0.9,length_ratio=1.1,theta=0.3"}) {
    for (const std::string integrator : {"euler", "implicit", "rk4"}) {
      SCOPED_TRACE(spec + " " + integrator);
      const auto problem = make_problem(spec);
      std::string why;
      const auto chain = planar_chain_of(*problem, why);
      ASSERT_TRUE(chain) << why;
      MujocoChain engine(*chain, {integrator, false});
      const State start = problem->initial_state();
      engine.set_state(start.q, chain_velocity(*problem, start.q, start.p));
      Vec theta, rate, p;
      for (int k = 0; k < 50; ++k) {
        ASSERT_TRUE(engine.step(0.01).ok);
        engine.get_state(theta, rate);
        const Vec expected = chain_momentum(*problem, theta, rate);
        // RK4 leaves MuJoCo's mass matrix at the step's start: the adapter must not use it.
        ASSERT_EQ(engine.momentum_absolute(p), integrator != "rk4");
        if (integrator == "rk4") continue;
        EXPECT_LE((p - expected).norm(), 1e-12 * expected.norm() + 1e-300);
      }
    }
  }
}

}  // namespace
}  // namespace geomint::engines
