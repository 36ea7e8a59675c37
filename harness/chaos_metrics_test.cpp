// Chaos indicators (harness/chaos_metrics.hpp): the MEGNO sums on known growth laws, the Lyapunov
// exponent √(k/m) of the inverted oscillator V = −½kq², MEGNO 0 on the isochronous oscillator and
// 2 on Kepler, the finite-difference tangent against the exact one, the valid time's scale.
#include "harness/chaos_metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "harness/run.hpp"
#include "harness/run_spec.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace chaos_metrics_test {
namespace {

// H = p²/2m − ½kq²: every tangent vector grows like e^{λt}, λ = √(k/m), on every orbit.
class InvertedOscillator final : public Problem {
 public:
  InvertedOscillator(double mass, double stiffness) : stiffness_(stiffness) {
    set_mass(Vec::Constant(1, mass));
    set_capabilities(kHessian);
    set_defaults(0.01, 10.0);
  }
  State initial_state() const override {
    return {0.0, Vec::Constant(1, 0.3), Vec::Constant(1, -0.2)};
  }
  double potential(const Vec& q) const override { return -0.5 * stiffness_ * q.squaredNorm(); }
  void gradient(const Vec& q, Vec& g) const override { g = -stiffness_ * q; }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    H.resize(q.size(), q.size());
    H.setZero();
    H.insert(0, 0) = -stiffness_;
    H.makeCompressed();
  }

 private:
  double stiffness_;
};

// The observer driven by a plain fixed-step loop, as run_one drives it.
std::map<std::string, double> observe_run(const Problem& problem, const std::string& method_spec,
                                          double h, long steps, ChaosTangent kind) {
  auto observer =
      make_chaos_observer(MethodFactory(method_spec), problem, {"lyapunov_max", "megno"}, kind);
  EXPECT_NE(observer, nullptr);
  std::map<std::string, double> metrics;
  if (!observer) return metrics;
  auto method = make_integrator(method_spec);
  State state = problem.initial_state();
  observer->begin(problem, state, h * static_cast<double>(steps));
  method->reset(problem, state, h);
  for (long k = 0; k < steps; ++k) {
    EXPECT_TRUE(method->step(problem, state, h).ok);
    observer->observe(problem, state);
  }
  observer->finish(metrics);
  return metrics;
}

std::map<std::string, double> chaos_run(const std::string& problem, const std::string& method,
                                        double dt, double t_end,
                                        const std::vector<std::string>& metrics) {
  RunConfig config;
  config.dt = dt;
  config.t_end = t_end;
  config.timing_repeats = 0;
  config.extra_metrics = metrics;
  const RunResult result = run_one(problem, method, config);
  EXPECT_TRUE(result.ok) << problem << " " << method;
  return result.record.metrics;
}

// |w| = e^{λt} gives ℓ_k = λh: Λ = λ, Y(t) = λt and <Y> = λt/2 exactly (the midpoint and
// trapezoidal rules are exact on these linear integrands); |w| = 1 + t gives Y → 2.
TEST(ChaosSums, ExactOnExponentialAndLinearGrowth) {
  const double lambda = 0.37, h = 0.05, t0 = 3.0;
  ChaosSums sums;
  sums.start(t0);
  const int steps = 4000;
  for (int k = 1; k <= steps; ++k) sums.add_step(t0 + (k - 1) * h, t0 + k * h, lambda * h);
  const double t = steps * h;
  EXPECT_NEAR(sums.lyapunov(), lambda, 1e-12);
  EXPECT_NEAR(sums.megno_instant(), lambda * t, 1e-9 * lambda * t);
  EXPECT_NEAR(sums.megno_mean(), lambda * t / 2, 1e-9 * lambda * t);

  ChaosSums linear;
  linear.start(0);
  for (int k = 1; k <= 100000; ++k) {
    linear.add_step((k - 1) * h, k * h, std::log((1 + k * h) / (1 + (k - 1) * h)));
  }
  // Y(t) = 2(1 − ln(1 + t)/t): 1.998 at t = 5000, <Y> = 2 − O(ln² t / t).
  EXPECT_NEAR(linear.megno_instant(), 2.0, 0.01);
  EXPECT_NEAR(linear.megno_mean(), 2.0, 0.02);
}

// λ = √(k/m) = 0.6 at m = 2.5, k = 0.9, from the exact linearised step of three methods and from
// finite differences of the computed map; the finite-time offset ln|w₀ component|/t is < 3%.
TEST(ChaosIndicators, InvertedOscillatorExponentIsRootKOverM) {
  const InvertedOscillator problem(2.5, 0.9);
  const double lambda = std::sqrt(0.9 / 2.5);
  for (const std::string method : {"stormer_verlet", "rk4", "implicit_midpoint"}) {
    for (const ChaosTangent kind :
         {ChaosTangent::kLinearisedStep, ChaosTangent::kFiniteDifference}) {
      const auto metrics = observe_run(problem, method, 0.02, 2500, kind);
      EXPECT_NEAR(metrics.at("lyapunov_max"), lambda, 0.03 * lambda)
          << method << " tangent " << static_cast<int>(kind);
      EXPECT_EQ(metrics.at("chaos_tangent_fd"), kind == ChaosTangent::kFiniteDifference ? 1 : 0);
      // Exponential growth: <Y> ≈ λt/2 = 15 at t = 50.
      EXPECT_GT(metrics.at("megno"), 10) << method;
    }
  }
}

// The harmonic oscillator is isochronous: |w| stays bounded, so Y oscillates about 0 and
// <Y> → 0 (not 2: there is no shear between neighbouring orbits), at non-unit ω and m.
TEST(ChaosIndicators, MegnoZeroOnIsochronousOscillatorTwoOnKepler) {
  for (const std::string method : {"stormer_verlet", "rk4"}) {
    const auto harmonic = chaos_run("harmonic:omega=3,mass=2,q0=0.5,v0=-1", method, 0.01, 100,
                                    {"lyapunov_max", "megno"});
    EXPECT_NEAR(harmonic.at("megno"), 0.0, 0.05) << method;
    // ln|w(t)|/t with |w| between 1/(mω) and mω (the Euclidean norm mixes q and p = mq̇).
    EXPECT_LE(std::abs(harmonic.at("lyapunov_max")), std::log(6.0) / 100) << method;
    // Kepler's period depends on the energy: neighbouring orbits shear apart linearly.
    const auto kepler = chaos_run("kepler:e=0.6", method, 0.02, 200, {"lyapunov_max", "megno"});
    EXPECT_NEAR(kepler.at("megno"), 2.0, 0.05) << method;
    EXPECT_LT(kepler.at("lyapunov_max"), 0.05) << method;
  }
}

// The double pendulum has no linearised step (non-separable): the finite-difference tangent is
// used and says so; at large angles it is chaotic.
TEST(ChaosIndicators, DoublePendulumFallsBackToFiniteDifferences) {
  const auto metrics =
      chaos_run("double_pendulum:theta1=2.5,theta2=-1,omega2=3", "rk4", 0.01, 40, {"megno"});
  EXPECT_EQ(metrics.at("chaos_tangent_fd"), 1);
  EXPECT_GT(metrics.at("lyapunov_max"), 0.5);
  EXPECT_GT(metrics.at("megno"), 5);
}

// valid_time is relative: scaling the state by 1000 (the harmonic oscillator is linear) leaves
// it unchanged; explicit Euler's growing error reaches 1e-2, a fine Verlet run does not.
TEST(ValidTime, RelativeErrorThresholdAtAnyScale) {
  const auto small =
      chaos_run("harmonic:omega=3,mass=2,q0=0.5,v0=-1", "explicit_euler", 0.001, 5, {"valid_time"});
  const auto large = chaos_run("harmonic:omega=3,mass=2,q0=500,v0=-1000", "explicit_euler", 0.001,
                               5, {"valid_time"});
  EXPECT_EQ(small.at("valid_time_reached"), 1);
  EXPECT_GT(small.at("valid_time"), 0.1);
  EXPECT_LT(small.at("valid_time"), 5);
  EXPECT_NEAR(large.at("valid_time"), small.at("valid_time"), 1e-9);
  const auto fine =
      chaos_run("harmonic:omega=3,mass=2,q0=0.5,v0=-1", "stormer_verlet", 0.001, 5, {"valid_time"});
  EXPECT_EQ(fine.at("valid_time_reached"), 0);
  EXPECT_NEAR(fine.at("valid_time"), 5, 1e-9);
}

// The Poincaré section series (RunConfig::series_section): on the harmonic oscillator
// q(t) = A cos(ωt − φ) the upward crossings of q = 0 fall at ωt − φ = 3π/2 + 2πk, and at
// h = 0.05 (ωh = 0.15) the cubic Hermite interpolation puts them there to 1e-4 of a period.
TEST(PoincareSection, CrossingsLieOnTheSectionAtTheExactTimes) {
  const double omega = 3, q0 = 0.5, v0 = -1;
  const std::string path =
      (std::filesystem::temp_directory_path() / "geomint_chaos_section_test.csv").string();
  RunConfig config;
  config.dt = 0.05;
  config.t_end = 20;
  config.timing_repeats = 0;
  config.series_path = path;
  config.series_section = 0;
  const RunResult result = run_one("harmonic:omega=3,mass=2,q0=0.5,v0=-1", "rk4", config);
  ASSERT_TRUE(result.ok);
  std::ifstream in(path);
  std::string line;
  const double phase = std::atan2(v0 / omega, q0);  // q = A cos(ωt − phase)
  int crossings = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    std::vector<double> values;
    std::stringstream fields(line);
    for (std::string field; std::getline(fields, field, ',');) values.push_back(std::stod(field));
    ASSERT_EQ(values.size(), 4u);  // t, energy, q_0, p_0
    const double t = values[0];
    double angle = std::fmod(omega * t - phase - 1.5 * std::numbers::pi, 2 * std::numbers::pi);
    if (angle > std::numbers::pi) angle -= 2 * std::numbers::pi;
    if (angle < -std::numbers::pi) angle += 2 * std::numbers::pi;
    EXPECT_LT(std::abs(angle), 2 * std::numbers::pi * 1e-4) << "t = " << t;
    EXPECT_LT(std::abs(values[2]), 1e-12);
    EXPECT_GT(values[3], 0);
    ++crossings;
  }
  // ωT/2π = 9.5 periods.
  EXPECT_GE(crossings, 9);
  EXPECT_LE(crossings, 10);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace chaos_metrics_test
}  // namespace geomint
