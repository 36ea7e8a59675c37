// The run path evaluates the energy once per step point: the energy metric and the divergence rule
// share one problem.energy() call (harness/observers.cpp EnergyObserver). Registers a problem
// that counts its potential evaluations, so an executable of its own.
#include <gtest/gtest.h>

#include "harness/run.hpp"
#include "problems/oscillator_base.hpp"

namespace geomint {
namespace {

long potential_calls = 0;

// A harmonic oscillator (no exact solution, so only the energy observers evaluate V) that counts
// V(q): energy() = kinetic + potential() is the only way the harness reaches it.
class CountingOscillator final : public OscillatorBase {
 public:
  CountingOscillator(double omega, double mass) : OscillatorBase(omega, mass, 0.7, 0.2) {
    set_capabilities(kHessian);
  }
  double potential(const Vec& q) const override {
    ++potential_calls;
    return OscillatorBase::potential(q);
  }
};

std::unique_ptr<Problem> make_counting_oscillator(Params& params) {
  const double omega = params.real("omega", 3.0, "angular frequency");
  const double mass = params.real("mass", 2.5, "mass");
  return std::make_unique<CountingOscillator>(omega, mass);
}

const ProblemRegistrar kRegistrar(
    {"counting_oscillator", "harmonic oscillator counting V(q)", &make_counting_oscillator, {}});

// The energy evaluations of one run's metric pass that are the harness's own: all V(q) calls
// less the method's own (Counters::energy_evals), per step point including the initial one.
double harness_energy_evals_per_point(const std::string& method, double diverge_factor,
                                      RunResult* out = nullptr) {
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 0.3;
  config.timing_repeats = 0;
  config.reference_dir = "";
  config.diverge_factor = diverge_factor;
  potential_calls = 0;
  RunResult result = run_one("counting_oscillator", method, config);
  EXPECT_EQ(result.record.status, "ok") << method;
  const long method_calls = result.record.counters ? result.record.counters->energy_evals : 0;
  const long points = *result.record.steps + 1;
  if (out) *out = result;
  return static_cast<double>(potential_calls - method_calls) / static_cast<double>(points);
}

TEST(EnergyEvals, OncePerStepPointOnTheRunPathWithAndWithoutTheDivergenceRule) {
  for (const std::string method : {"stormer_verlet", "rk4", "gsl_rk8pd"}) {
    EXPECT_EQ(harness_energy_evals_per_point(method, kDefaultDivergeFactor), 1.0) << method;
    EXPECT_EQ(harness_energy_evals_per_point(method, 0), 1.0) << method;
  }
}

// The shared evaluation still stops a run: a rule so tight that the first step breaks it.
TEST(EnergyEvals, TheEnergyObserverStopsADivergingRun) {
  RunConfig config;
  config.dt = 0.2;
  config.t_end = 1;
  config.timing_repeats = 0;
  config.reference_dir = "";
  config.diverge_factor = 1e-12;
  const RunResult result = run_one("counting_oscillator", "explicit_euler", config);
  EXPECT_EQ(result.record.status, "diverged");
  EXPECT_EQ(result.record.t_reached, 0.0);
  ASSERT_TRUE(result.record.message);
  EXPECT_NE(result.record.message->find("relative energy error above 1e-12 at t=0.2"),
            std::string::npos)
      << *result.record.message;
  // The metrics end with the last admitted point, the initial state: no error yet.
  EXPECT_EQ(result.record.metrics.at("energy_err_max"), 0.0);
}

}  // namespace
}  // namespace geomint
