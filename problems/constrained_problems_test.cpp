// Constrained problems beyond the registry-driven derivative checks of constraints_test.cpp
// (docs/METHOD.md §3): the time terms of rheonomic constraints against finite differences, and
// the cartesian pendulum's exact motion and rod tension.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace constrained_problems_test {
namespace {

std::vector<std::string> constrained_specs() {
  std::vector<std::string> specs;
  for (const auto& spec : problem_test_specs()) {
    if (make_problem(spec)->has(kConstraints)) specs.push_back(spec);
  }
  return specs;
}

double inf_norm(const Vec& v) { return v.size() == 0 ? 0.0 : v.lpNorm<Eigen::Infinity>(); }

// Central difference of a vector function along direction w, with step h.
template <class F>
Vec directional_difference(F&& f, const Vec& q, const Vec& w, double h) {
  return (f(q + h * w) - f(q - h * w)) / (2 * h);
}

// Rheonomic constraints: along the path (q + sv, t + s), dg/ds = G v + g_t and d²g/ds² = c(q, v) +
// a_t, both against central differences at a few times.
TEST(ConstrainedProblems, TimeTermsMatchFiniteDifferences) {
  unsigned seed = 77;
  int checked = 0;
  for (const auto& spec : constrained_specs()) {
    const auto problem = make_problem(spec);
    if (!problem->has(kTimeDependentConstraints)) continue;
    SCOPED_TRACE(spec);
    ++checked;
    const int n = problem->dof();
    const Vec q0 = problem->initial_state().q;
    for (double t : {0.0, 0.37, 1.9}) {
      const Vec q = q0 + 0.05 * test::random_vector(n, ++seed);
      const Vec v = test::random_vector(n, ++seed);
      const auto g_at = [&](double s) {
        Vec g;
        constraints_of(*problem).constraint_at(t + s, q + s * v, g);
        return g;
      };
      SparseMatrix G;
      constraints_of(*problem).constraint_jacobian_at(t, q, G);
      Vec c, g_t, a_t;
      constraints_of(*problem).constraint_curvature(q, v, c);
      constraints_of(*problem).constraint_time_terms(t, q, v, g_t, a_t);
      const double h = 1e-4;
      const Vec rate = G * v + g_t;
      const Vec rate_fd = (g_at(h) - g_at(-h)) / (2 * h);
      EXPECT_LE(inf_norm(rate - rate_fd), 1e-7 * (inf_norm(rate) + 1)) << "t = " << t;
      const Vec second = c + a_t;
      const Vec second_fd = (g_at(h) - 2 * g_at(0) + g_at(-h)) / (h * h);
      EXPECT_LE(inf_norm(second - second_fd), 1e-5 * (inf_norm(second) + 1)) << "t = " << t;
      // G(q, t) is the q-derivative of g(q, t) at that t.
      const Vec w = test::random_vector(n, ++seed);
      const auto g_q = [&](const Vec& x) {
        Vec g;
        constraints_of(*problem).constraint_at(t, x, g);
        return g;
      };
      EXPECT_LE(inf_norm(G * w - directional_difference(g_q, q, w, 1e-5)), 1e-7) << "t = " << t;
    }
  }
  EXPECT_GT(checked, 0) << "no problem with time-dependent constraints in the registry";
}

// The exact motion stays on the rod at position and velocity level, to round-off.
TEST(ConstrainedProblems, ExactMotionIsConsistent) {
  for (const auto& spec : constrained_specs()) {
    const auto problem = make_problem(spec);
    if (!problem->has(kExact)) continue;  // (and rheonomic problems have none)
    SCOPED_TRACE(spec);
    for (double t : {0.0, 0.7, 3.1, 41.0}) {
      const State at = problem->exact(t);
      EXPECT_NO_THROW(problem->check_consistent(at, "exact state")) << "t = " << t;
    }
  }
}

// The multiplier is the rod tension m g cos θ + m L θ̇² (force units, the constraint is scaled
// by 1/L), checked along the exact motion where θ = atan2(x, −y).
TEST(CartesianPendulum, MultiplierIsRodTension) {
  const double length = 2.5, mass = 0.7, gravity = 9.81;
  const auto problem =
      make_problem("cartesian_pendulum:theta0=1.2,length=2.5,mass=0.7,gravity=9.81");
  for (double t : {0.0, 0.3, 1.1, 2.9}) {
    const State at = problem->exact(t);
    const double theta = std::atan2(at.q[0], -at.q[1]);
    const double speed = at.p.norm() / mass;
    const double tension = mass * gravity * std::cos(theta) + mass * speed * speed / length;
    EXPECT_NEAR(problem->multipliers(t, at.q, at.p)[0], tension, 1e-12 * mass * gravity)
        << "t = " << t;
  }
  EXPECT_EQ(constraints_of(*problem).multiplier_names(), std::vector<std::string>{"tension"});
}

// The Cartesian motion is the angle pendulum's: x = L sin θ(t) with θ from `pendulum`.
TEST(CartesianPendulum, FollowsTheAnglePendulum) {
  const auto cartesian = make_problem("cartesian_pendulum:theta0=2.0,v0=0.3,length=4,gravity=9");
  const auto angle = make_problem("pendulum:theta0=2.0,v0=0.3,omega0=1.5");
  EXPECT_NEAR(cartesian->period(), angle->period(), 1e-14 * angle->period());
  for (double t : {0.4, 5.0, 17.3}) {
    const double theta = angle->exact(t).q[0];
    EXPECT_NEAR(cartesian->exact(t).q[0], 4 * std::sin(theta), 1e-13) << t;
    EXPECT_NEAR(cartesian->exact(t).q[1], -4 * std::cos(theta), 1e-13) << t;
  }
}

}  // namespace
}  // namespace constrained_problems_test
}  // namespace geomint
