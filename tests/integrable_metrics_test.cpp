// The optional metrics of harness/integrable_metrics.hpp: Flaschka's Toda invariants, the Kepler
// eccentricity (Laplace–Runge–Lenz) vector and the loop action ∮p·dq of the computed one-step map.
#include "harness/integrable_metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "harness/observers.hpp"
#include "harness/run.hpp"
#include "problems/problem.hpp"
#include "problems/structures/kepler_orbit.hpp"

namespace geomint {
namespace integrable_metrics_test {
namespace {

RunRecord run_with(const std::string& problem, const std::string& method, double dt, double t_end,
                   const std::vector<std::string>& metrics) {
  RunConfig config;
  config.dt = dt;
  config.t_end = t_end;
  config.timing_repeats = 0;
  config.extra_metrics = metrics;
  return run_one(problem, method, config).record;
}

double metric_of(const RunRecord& record, const std::string& name) {
  const auto found = record.metrics.find(name);
  EXPECT_NE(found, record.metrics.end()) << name << " missing";
  return found == record.metrics.end() ? NAN : found->second;
}

// Störmer–Verlet keeps every trace tr Lᵏ near its initial value (bounded, O(h²)), RK4 with the
// same step lets them drift; the metric is asked for and found only on Toda lattices.
TEST(TodaInvariantsMetric, BoundedForVerletAndDriftingForExplicitEuler) {
  const std::vector<std::string> asked = {"toda_invariants_err_max"};
  for (const std::string problem : {"toda", "toda:ends=open,n=5,alpha=2,displacement=-0.3"}) {
    const double verlet =
        metric_of(run_with(problem, "stormer_verlet", 0.05, 200, asked), "toda_invariants_err_max");
    const double verlet_half = metric_of(run_with(problem, "stormer_verlet", 0.025, 200, asked),
                                         "toda_invariants_err_max");
    EXPECT_LT(verlet, 1e-2) << problem;
    EXPECT_NEAR(verlet / verlet_half, 4.0, 1.0) << problem;  // O(h²), not growing
    const double euler =
        metric_of(run_with(problem, "explicit_euler", 0.05, 200, asked), "toda_invariants_err_max");
    EXPECT_GT(euler, 10 * verlet) << problem;
  }
  const RunRecord kepler = run_with("kepler", "stormer_verlet", 0.05, 1, asked);
  EXPECT_EQ(kepler.metrics.count("toda_invariants_err_max"), 0u);
}

// The exact Kepler solution keeps e to round-off (problems/toda_test.cpp); a method's run drifts:
// Störmer–Verlet's e precesses (the perihelion advances), explicit Euler's grows, and halving the
// step divides Verlet's drift by about 4. Cartesian, polar and the two-body nbody.
TEST(LrlMetric, NonzeroUnderAMethodAndShrinkingWithTheStep) {
  const std::vector<std::string> asked = {"lrl_err_max"};
  for (const std::string problem :
       {"kepler:e=0.6",
        "nbody:preset=custom,masses=3/0.25,positions=0/0/1.5/0,velocities=0/-0.1/0/1.3,G=1.3"}) {
    const double coarse =
        metric_of(run_with(problem, "stormer_verlet", 0.01, 20, asked), "lrl_err_max");
    const double fine =
        metric_of(run_with(problem, "stormer_verlet", 0.005, 20, asked), "lrl_err_max");
    EXPECT_GT(coarse, 1e-6) << problem;
    EXPECT_NEAR(coarse / fine, 4.0, 0.6) << problem;
  }
  const double polar =
      metric_of(run_with("kepler:e=0.6,coordinates=polar", "implicit_midpoint", 0.01, 20, asked),
                "lrl_err_max");
  EXPECT_GT(polar, 1e-7);
  EXPECT_LT(polar, 1e-2);
  // The exact flow itself: e is constant to round-off at every step point.
  const auto kepler = make_problem("kepler:e=0.6");
  auto observers = make_observers({*kepler, asked});
  ASSERT_EQ(observers.size() - make_metric_observers(*kepler).size(), 1u);
  for (auto& observer : observers) observer->begin(*kepler, kepler->initial_state(), 20);
  for (double t = 0.1; t <= 20; t += 0.1) {
    for (auto& observer : observers) observer->observe(*kepler, kepler->exact(t));
  }
  std::map<std::string, double> metrics;
  for (auto& observer : observers) observer->finish(metrics);
  EXPECT_LE(metrics.at("lrl_err_max"), 1e-14);
  EXPECT_EQ(make_problem("henon_heiles")->as<KeplerOrbitStructure>(), nullptr);
}

// The loop action is kept to round-off by the symplectic methods and changed at O(h^{p+1}) by
// RK4 and by an adaptive library solver (CVODE's Adams method at its default tolerances), on Kepler
// and on Hénon–Heiles; the initial circle's action is π r_q r_p exactly.
TEST(LoopActionMetric, RoundOffForSymplecticMethodsAndNotForRk4) {
  for (const std::string problem :
       {"kepler:e=0.5", "henon_heiles:energy=0.125,q1=0.2,q2=-0.1,p1=-0.05"}) {
    const auto instance = make_problem(problem);
    const State start = instance->initial_state();
    for (const std::string method : {"stormer_verlet", "implicit_midpoint", "gauss:s=2"}) {
      const LoopAction action = loop_action(method, *instance, start, 0.05);
      ASSERT_TRUE(action.converged) << problem << " " << method;
      EXPECT_LE(action.error, 1e-13) << problem << " " << method;
    }
    const LoopAction rk4 = loop_action("rk4", *instance, start, 0.05);
    ASSERT_TRUE(rk4.converged);
    EXPECT_GT(rk4.error, 1e-10) << problem;
    const LoopAction rk4_half = loop_action("rk4", *instance, start, 0.025);
    EXPECT_GT(rk4.error / rk4_half.error, 8.0) << problem;  // O(h⁵) per step, at least O(h³)
    const LoopAction adaptive = loop_action("cvode_adams", *instance, start, 0.05);
    ASSERT_TRUE(adaptive.converged) << adaptive.failure;
    EXPECT_GT(adaptive.error, 1e-10) << problem;
  }
  // Polar Kepler after ten orbits: φ ≈ 20π must not set the loop's radius in r (r ≈ 0.4 at
  // perihelion), or the loop crosses r = 0 and the action is meaningless (it was 0.25 with one
  // radius per block).
  const auto polar = make_problem("kepler:e=0.6,coordinates=polar");
  const State late = polar->exact(20 * std::numbers::pi);
  ASSERT_GT(late.q[1], 60.0);
  const LoopAction midpoint = loop_action("implicit_midpoint", *polar, late, 0.02);
  ASSERT_TRUE(midpoint.converged) << midpoint.failure;
  EXPECT_LE(midpoint.error, 1e-13);
  EXPECT_GT(loop_action("rk4", *polar, late, 0.02).error, 1e-8);
  // As a run's metric: present where it applies, with the points it took.
  const RunRecord run = run_with("kepler:e=0.5", "rk4", 0.05, 1, {"loop_action_err"});
  EXPECT_GT(metric_of(run, "loop_action_err"), 1e-10);
  EXPECT_GE(metric_of(run, "loop_action_points"), 32);
  EXPECT_EQ(run_with("cartesian_pendulum", "rattle", 0.05, 0.2, {"loop_action_err"})
                .metrics.count("loop_action_err"),
            0u);
}

}  // namespace
}  // namespace integrable_metrics_test
}  // namespace geomint
