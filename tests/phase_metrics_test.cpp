// Phase metrics (harness/observers.cpp): phase_err, period_err and perihelion_err on trajectories
// with a known phase error: time-scaled and precessing exact Kepler orbits, and Störmer–Verlet
// on the harmonic oscillator, whose discrete frequency cos(ω̃h) = 1 − (ωh)²/2 is analytic.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include "harness/observers.hpp"
#include "harness/run.hpp"

namespace geomint {
namespace phase_metrics_test {
namespace {

constexpr double kPi = std::numbers::pi;

// Feeds the metric observers of `problem` the states exact((1 + speedup) t), rotated by
// precession · t/T, at `steps` equal steps to t_end.
std::map<std::string, double> observe_modified_orbit(const Problem& problem, double speedup,
                                                     double precession, double t_end, int steps) {
  auto observers = make_metric_observers(problem);
  const double period = problem.period();
  const auto state_at = [&](double t) {
    State state = problem.exact((1 + speedup) * t);
    state.t = t;
    if (precession != 0) {
      const double angle = precession * t / period;
      const Eigen::Matrix2d rotation{{std::cos(angle), -std::sin(angle)},
                                     {std::sin(angle), std::cos(angle)}};
      state.q = rotation * state.q;
      state.p = rotation * state.p;
    }
    return state;
  };
  for (auto& observer : observers) observer->begin(problem, state_at(0), t_end);
  for (int k = 1; k <= steps; ++k) {
    const State state = state_at(t_end * k / steps);
    for (auto& observer : observers) observer->observe(problem, state);
  }
  std::map<std::string, double> metrics;
  for (const auto& observer : observers) observer->finish(metrics);
  return metrics;
}

TEST(PhaseMetrics, ZeroOnTheExactFlow) {
  for (const char* spec : {"kepler:e=0.9", "kepler:e=0.99", "pendulum:theta0=3", "harmonic"}) {
    const auto problem = make_problem(spec);
    const auto metrics = observe_modified_orbit(*problem, 0, 0, 10.3 * problem->period(), 20000);
    ASSERT_TRUE(metrics.count("phase_err")) << spec;
    EXPECT_NEAR(metrics.at("phase_err"), 0, 1e-9) << spec;
    EXPECT_NEAR(metrics.at("period_err"), 0, 1e-10) << spec;
    if (problem->has(kAngularMomentum)) {
      EXPECT_NEAR(metrics.at("perihelion_err"), 0, 1e-6) << spec;
    }
  }
}

TEST(PhaseMetrics, GrowsLinearlyWithAPeriodError) {
  // Running 1e-3 fast: after t the phase is 2π·1e-3·t/T ahead (past half a period at t = 600T,
  // so this also checks the unwrapping), and T_computed = T/(1 + 1e-3).
  const auto problem = make_problem("kepler:e=0.9");
  for (double periods : {3.0, 60.0, 600.0}) {
    const double t_end = periods * problem->period();
    const auto metrics = observe_modified_orbit(*problem, 1e-3, 0, t_end, 400 * periods);
    EXPECT_NEAR(metrics.at("phase_err"), 2 * kPi * 1e-3 * periods, 1e-8 * periods) << periods;
    EXPECT_NEAR(metrics.at("period_err"), -1e-3 / (1 + 1e-3), 1e-10) << periods;
  }
}

TEST(PhaseMetrics, PerihelionPrecessionPerOrbit) {
  const auto problem = make_problem("kepler:e=0.6");
  const auto metrics = observe_modified_orbit(*problem, 0, 0.01, 20 * problem->period(), 40000);
  EXPECT_NEAR(metrics.at("perihelion_err"), 0.01, 1e-5);
  // A circular orbit has no pericentre, so no precession is reported.
  EXPECT_FALSE(make_metric_observers(*make_problem("kepler:e=0")).empty());
  const auto circular = make_problem("kepler:e=0");
  EXPECT_FALSE(
      observe_modified_orbit(*circular, 0, 0.01, 20 * 2 * kPi, 4000).count("perihelion_err"));
  // Only planar orbits with a period get it.
  EXPECT_FALSE(
      observe_modified_orbit(*make_problem("harmonic"), 0, 0, 20, 100).count("perihelion_err"));
}

TEST(PhaseMetrics, StormerVerletOnHarmonicMatchesDiscreteFrequency) {
  // q_n = cos(ω̃ t_n) exactly, with cos(ω̃h) = 1 − (ωh)²/2: the phase runs ahead by (ω̃ − ω)t.
  // The best-match shift also carries the O((ωh)²) bounded mismatch of the momentum amplitude.
  const double h = 0.1, t_end = 100 * 2 * kPi;
  const double discrete_omega = std::acos(1 - h * h / 2) / h;
  RunConfig config;
  config.dt = h;
  config.t_end = t_end;
  config.timing_repeats = 0;
  const RunResult result = run_one("harmonic", "stormer_verlet", config);
  ASSERT_TRUE(result.ok);
  const double expected_phase = (discrete_omega - 1) * result.final_state.t;
  EXPECT_NEAR(result.record.metrics.at("phase_err"), expected_phase, 1e-2 * expected_phase);
  EXPECT_NEAR(result.record.metrics.at("period_err"), 1 / discrete_omega - 1,
              1e-2 * (discrete_omega - 1));
  // Circular Kepler orbit: the phase error of a second-order method grows linearly in time and
  // as h² (the discrete orbit's radius changes too, so there is no one-line formula here).
  const auto kepler_phase = [&](double dt, double periods) {
    config.dt = dt;
    config.t_end = periods * 2 * kPi;
    const RunResult kepler = run_one("kepler:e=0", "stormer_verlet", config);
    EXPECT_TRUE(kepler.ok);
    return kepler.record.metrics.at("phase_err");
  };
  const double reference = kepler_phase(0.05, 50);
  EXPECT_NEAR(kepler_phase(0.05, 100) / reference, 2, 0.02);
  EXPECT_NEAR(kepler_phase(0.025, 50) / reference, 0.25, 0.01);
}

}  // namespace
}  // namespace phase_metrics_test
}  // namespace geomint
