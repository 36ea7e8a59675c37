// Checks of the damped oscillator beyond the registry suite: the exact energy-decay law
// dH/dt = −2ζω v², the equation of motion for strong damping, and parameter validation.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <string>
#include <vector>

#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace {

struct Case {
  std::string spec;
  double omega;
  double zeta;
};

const std::vector<Case>& cases() {
  static const std::vector<Case> list = {
      {"damped_oscillator", 1.0, 0.05},
      {"damped_oscillator:omega=2.5,zeta=0.3,q0=-0.4,v0=1.2", 2.5, 0.3},
      {"damped_oscillator:omega=0.7,zeta=0.9,q0=0,v0=-2", 0.7, 0.9},
  };
  return list;
}

TEST(DampedOscillator, ExactEnergyDecaysAtPhysicalRate) {
  for (const Case& c : cases()) {
    const auto problem = make_problem(c.spec);
    const auto energy = [&](double t) {
      const State s = problem->exact(t);
      return problem->energy(s.q, s.p);
    };
    // Central differences with h = 1e-4/ω: truncation ~ (hω)²H ~ 1e-8 H and rounding
    // ~ ε H/h ~ 1e-12 ωH, both far inside 1e-6 ωH(t).
    const double h = 1e-4 / c.omega;
    for (double t : {0.0, 0.3, 1.7, 4.2, 11.0, 23.5}) {
      const double rate = (energy(t + h) - energy(t - h)) / (2 * h);
      const double v = problem->exact(t).p[0];  // unit mass
      const double law = -2 * c.zeta * c.omega * v * v;
      EXPECT_NEAR(rate, law, 1e-6 * c.omega * energy(t)) << c.spec << " t = " << t;
    }
  }
}

TEST(DampedOscillator, ExactSolvesEquationOfMotion) {
  for (const Case& c : cases()) {
    const auto problem = make_problem(c.spec);
    const double h = 1e-4 / c.omega;
    for (double t : {0.1, 2.3, 7.9, 19.0}) {
      const State at = problem->exact(t);
      const State before = problem->exact(t - h);
      const State after = problem->exact(t + h);
      const double q_rate = (after.q[0] - before.q[0]) / (2 * h);
      const double p_rate = (after.p[0] - before.p[0]) / (2 * h);
      // Amplitude of the solution at t sets the scale of both residuals.
      const double scale = std::hypot(c.omega * at.q[0], at.p[0]);
      EXPECT_NEAR(q_rate, at.p[0], 1e-7 * scale) << c.spec << " t = " << t;
      const double acceleration = -2 * c.zeta * c.omega * at.p[0] - c.omega * c.omega * at.q[0];
      EXPECT_NEAR(p_rate, acceleration, 1e-7 * c.omega * scale) << c.spec << " t = " << t;
    }
  }
}

TEST(DampedOscillator, ForceAndDampingMatrixAgree) {
  const auto problem = make_problem("damped_oscillator:omega=2,zeta=0.25");
  ASSERT_TRUE(problem->has(kForce));
  ASSERT_TRUE(problem->has(kForceJacobian));
  const Vec q = Vec::Constant(1, 0.3);
  Vec f;
  problem->force(q, Vec::Constant(1, -1.5), 0.0, f);
  EXPECT_NEAR(f[0], 2 * 0.25 * 2 * 1.5, 4 * DBL_EPSILON);
  SparseMatrix C;
  problem->force_jacobian_v(q, Vec::Constant(1, -1.5), 0.0, C);
  EXPECT_NEAR(C.coeff(0, 0), 2 * 0.25 * 2, 4 * DBL_EPSILON);
}

TEST(DampedOscillator, UndampedIsConservativeHarmonic) {
  const auto damped = make_problem("damped_oscillator:omega=3,zeta=0,q0=0.5,v0=-1");
  const auto harmonic = make_problem("harmonic:omega=3,q0=0.5,v0=-1");
  EXPECT_FALSE(damped->has(kForce));
  for (double t : {0.4, 5.0, 33.0}) {
    const State a = damped->exact(t);
    const State b = harmonic->exact(t);
    EXPECT_NEAR(a.q[0], b.q[0], 1e-14) << t;
    EXPECT_NEAR(a.p[0], b.p[0], 4e-14) << t;
  }
}

TEST(DampedOscillator, RejectsOverdampingAndBadFrequency) {
  for (const auto& [spec, key] : std::vector<std::pair<std::string, std::string>>{
           {"damped_oscillator:zeta=1", "zeta=1"},
           {"damped_oscillator:zeta=-0.1", "zeta=-0.1"},
           {"damped_oscillator:omega=0", "omega=0"},
       }) {
    EXPECT_TRUE(test::input_error_names(make_problem, spec, key));
  }
}

}  // namespace
}  // namespace geomint
