// High-order methods (composition, lobatto3ab, gauss): the equivalences that pin them to known
// schemes (Lobatto IIIA–IIIB s = 2 is Störmer–Verlet, Gauss s = 1 the implicit midpoint rule, a
// composition is its base's substeps), forces, counters and input validation. Orders, energy and
// symplecticity are checked by the registry suites (tests/methods_test.cpp, variational_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "integrators/high_order_coefficients.hpp"
#include "integrators/integrator.hpp"

namespace geomint {
namespace high_order_test {
namespace {

// Largest relative distance in (q, p) between two methods' trajectories over `steps` steps.
double trajectory_distance(const std::string& method_a, const std::string& method_b,
                           const std::string& problem_spec, double h, int steps) {
  const auto problem = make_problem(problem_spec);
  auto a = make_integrator(method_a);
  auto b = make_integrator(method_b);
  State state_a = problem->initial_state();
  State state_b = state_a;
  a->reset(*problem, state_a, h);
  b->reset(*problem, state_b, h);
  const double scale = std::sqrt(state_a.q.squaredNorm() + state_a.p.squaredNorm());
  double worst = 0;
  for (int k = 0; k < steps; ++k) {
    if (!a->step(*problem, state_a, h).ok || !b->step(*problem, state_b, h).ok) return INFINITY;
    const double distance =
        std::sqrt((state_a.q - state_b.q).squaredNorm() + (state_a.p - state_b.p).squaredNorm());
    worst = std::max(worst, distance / scale);
  }
  return worst;
}

// Round-off only: the two schemes are the same map evaluated in a different order (and, for the
// implicit ones, solved to the round-off floor by the polished Newton iteration). Over 100 steps
// the difference random-walks at ~1e-16 a step, amplified by the flow's Lyapunov growth.
TEST(HighOrderEquivalence, Lobatto2IsStormerVerlet) {
  EXPECT_LE(
      trajectory_distance("lobatto3ab:s=2", "stormer_verlet", "pendulum:theta0=1.5", 0.1, 100),
      1e-13);
  EXPECT_LE(trajectory_distance("lobatto3ab:s=2", "stormer_verlet", "kepler:e=0.6", 0.01, 100),
            1e-13);
  EXPECT_LE(
      trajectory_distance("lobatto3ab:s=2", "stormer_verlet", "spring_net:nx=3,ny=3", 0.01, 100),
      1e-13);
}

TEST(HighOrderEquivalence, Gauss1IsImplicitMidpoint) {
  EXPECT_LE(trajectory_distance("gauss:s=1", "implicit_midpoint", "pendulum:theta0=1.5", 0.1, 100),
            1e-13);
  EXPECT_LE(trajectory_distance("gauss:s=1", "implicit_midpoint", "kepler:e=0.6", 0.01, 100),
            1e-13);
  // With a damping force: the same residual, force at the midpoint velocity.
  EXPECT_LE(
      trajectory_distance("gauss:s=1", "implicit_midpoint", "damped_oscillator:zeta=0.2", 0.1, 100),
      1e-13);
}

TEST(HighOrderEquivalence, NegativeControlHigherStagesDiffer) {
  EXPECT_GT(trajectory_distance("lobatto3ab:s=3", "stormer_verlet", "pendulum:theta0=1.5", 0.1, 10),
            1e-6);
  EXPECT_GT(trajectory_distance("gauss:s=2", "implicit_midpoint", "pendulum:theta0=1.5", 0.1, 10),
            1e-6);
}

// A composition step is its base's substeps γ_i h, bit for bit (the base is the registry's
// method, hp_midpoint = hp:alpha=0.5, not a copy).
TEST(Composition, IsTheBaseMethodsSubsteps) {
  for (const char* base : {"stormer_verlet", "hp_midpoint", "position_verlet", "del"}) {
    SCOPED_TRACE(base);
    const auto problem = make_problem("kepler:e=0.6");
    auto composition = make_integrator(std::string("composition:scheme=suzuki4,base=") + base);
    auto step = make_integrator(std::string(base) == "hp_midpoint" ? "hp:alpha=0.5" : base);
    const double h = 0.05;
    State composed = problem->initial_state();
    State by_hand = composed;
    composition->reset(*problem, composed, h);
    step->reset(*problem, by_hand, h);
    for (int k = 0; k < 10; ++k) {
      ASSERT_TRUE(composition->step(*problem, composed, h).ok);
      const double t0 = by_hand.t;
      for (const long double gamma : coefficients::kSuzuki4) {
        ASSERT_TRUE(step->step(*problem, by_hand, static_cast<double>(gamma) * h).ok);
      }
      by_hand.t = t0 + h;
    }
    EXPECT_EQ(composed.q, by_hand.q);
    EXPECT_EQ(composed.p, by_hand.p);
    EXPECT_EQ(composed.t, by_hand.t);
    // One composite step is counted once; the base's evaluations are all counted.
    EXPECT_EQ(composition->counters().steps, 10);
    EXPECT_EQ(composition->counters().force_evals, step->counters().force_evals);
    EXPECT_EQ(composition->counters().newton_iters, step->counters().newton_iters);
  }
}

TEST(Composition, StormerVerletBaseCostsOneGradientPerSubstep) {
  const auto problem = make_problem("pendulum:theta0=1.5");
  auto method = make_integrator("composition:scheme=kahan_li8");
  State state = problem->initial_state();
  method->reset(*problem, state, 0.1);
  for (int k = 0; k < 5; ++k) ASSERT_TRUE(method->step(*problem, state, 0.1).ok);
  EXPECT_EQ(method->counters().force_evals, 1 + 5 * 17);  // first same as last across substeps
  EXPECT_DOUBLE_EQ(state.t, 0.5);
}

TEST(Composition, FlagsAndOrderFollowSchemeAndBase) {
  const MethodInfo sv = make_integrator("composition:scheme=mclachlan8")->info();
  EXPECT_EQ(sv.order, 8);
  EXPECT_EQ(sv.flags, make_integrator("stormer_verlet")->info().flags);
  const MethodInfo hp = make_integrator("composition:base=hp_midpoint,scheme=kahan_li6")->info();
  EXPECT_EQ(hp.order, 6);
  EXPECT_EQ(hp.flags, make_integrator("hp:alpha=0.5")->info().flags);
  EXPECT_EQ(make_integrator("composition")->spec(),
            "composition:base=stormer_verlet,scheme=yoshida4");
}

// With linear damping the stage equations stay the collocation equations of a linear ODE, so the
// declared order holds for the forced problem too (global error ratio between h and h/2).
TEST(HighOrderForces, DeclaredOrderOnTheDampedOscillator) {
  for (const std::string method : {"gauss:s=2", "gauss:s=3", "lobatto3ab:s=3", "lobatto3ab:s=4"}) {
    SCOPED_TRACE(method);
    const auto problem = make_problem("damped_oscillator:zeta=0.2");
    const int order = make_integrator(method)->info().order;
    double errors[2];
    for (int level = 0; level < 2; ++level) {
      const double h = 0.2 / (1 << level);
      auto integrator = make_integrator(method);
      State state = problem->initial_state();
      integrator->reset(*problem, state, h);
      const int steps = static_cast<int>(std::lround(4.0 / h));
      for (int k = 0; k < steps; ++k) ASSERT_TRUE(integrator->step(*problem, state, h).ok);
      const State exact = problem->exact(state.t);
      errors[level] =
          std::sqrt((state.q - exact.q).squaredNorm() + (state.p - exact.p).squaredNorm());
    }
    EXPECT_NEAR(std::log2(errors[0] / errors[1]), order, 0.3) << errors[0] << " " << errors[1];
  }
}

// The starting guess extrapolated from the previous step saves Newton iterations (measured on
// this run: 108 against 175 for Gauss s = 3) but does not change the converged step: a run that
// forgets its history (reset every step, cold start from the explicit-Euler guess) lands on the
// same trajectory to round-off.
TEST(HighOrderStartingGuess, ExtrapolationSavesIterationsNotAccuracy) {
  for (const std::string method : {"gauss:s=3", "lobatto3ab:s=4"}) {
    SCOPED_TRACE(method);
    const auto problem = make_problem("pendulum:theta0=1.5");
    const double h = 0.1;
    auto warm = make_integrator(method);
    auto cold = make_integrator(method);
    State warm_state = problem->initial_state();
    State cold_state = warm_state;
    warm->reset(*problem, warm_state, h);
    long cold_iterations = 0;
    for (int k = 0; k < 100; ++k) {
      ASSERT_TRUE(warm->step(*problem, warm_state, h).ok);
      cold->reset(*problem, cold_state, h);
      ASSERT_TRUE(cold->step(*problem, cold_state, h).ok);
      cold_iterations += cold->counters().newton_iters;
    }
    EXPECT_LT(warm->counters().newton_iters, cold_iterations);
    EXPECT_LE(std::abs(warm_state.q[0] - cold_state.q[0]), 1e-14);
    EXPECT_LE(std::abs(warm_state.p[0] - cold_state.p[0]), 1e-14);
  }
}

TEST(HighOrderInput, BadParametersNameTheKeyAndTheChoices) {
  try {
    make_integrator("composition:scheme=yoshida8");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("scheme"), std::string::npos) << what;
    EXPECT_NE(what.find("kahan_li8"), std::string::npos) << what;
  }
  // Bases: fixed-step symmetric methods of order 2 only, named without parameters.
  for (const char* bad :
       {"composition:base=rk4", "composition:base=gauss", "composition:base=symplectic_euler_a",
        "composition:base=odeint_dopri5", "composition:base=composition"}) {
    try {
      make_integrator(bad);
      ADD_FAILURE() << bad << ": no InputError";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("base"), std::string::npos) << what;
      EXPECT_NE(what.find("position_verlet"), std::string::npos) << what;
    }
  }
  EXPECT_THROW(make_integrator("gauss:s=4"), InputError);
  EXPECT_THROW(make_integrator("gauss:s=0"), InputError);
  EXPECT_THROW(make_integrator("lobatto3ab:s=1"), InputError);
  EXPECT_THROW(make_integrator("lobatto3ab:s=5"), InputError);
  EXPECT_THROW(make_integrator("gauss:tol=2"), InputError);
}

// A Newton failure is a failed step with the solver's reason, never a crash.
TEST(HighOrderFailure, NewtonFailureIsAStatus) {
  const auto problem = make_problem("kepler:e=0.6");
  for (const std::string method : {"gauss:s=3,max_iter=1", "lobatto3ab:s=4,max_iter=1"}) {
    SCOPED_TRACE(method);
    auto integrator = make_integrator(method);
    State state = problem->initial_state();
    integrator->reset(*problem, state, 0.5);
    const StepStatus status = integrator->step(*problem, state, 0.5);
    EXPECT_FALSE(status.ok);
    EXPECT_EQ(status.reason, "newton_max_iter") << status.message;
  }
}

}  // namespace
}  // namespace high_order_test
}  // namespace geomint
