// Modified energies (harness/modified_energy.hpp; docs/METHOD.md §10): the error of
// H̃ = H + h²H₂ falls like h⁴ where the error of H falls like h², for both Verlet orderings and the
// implicit midpoint rule, and the Verlet correction does not help RK4 (a negative control).
#include "harness/modified_energy.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "harness/run.hpp"

namespace geomint {
namespace modified_energy_test {
namespace {

// Non-unit scales: a pendulum with ω₀ = 1.7 at a large amplitude, Kepler at e = 0.5, and an FPU-β
// chain with mass 2.5 (M ≠ I), each over about one period. The steps are small enough for the
// h⁴ term to dominate and large enough for it to stand far above round-off.
struct Case {
  std::string problem;
  double h;  // the coarsest of the three steps h, h/2, h/4
  double t_end;
};
const std::vector<Case> kCases = {
    {"pendulum:theta0=1.2,omega0=1.7", 0.08, 4.0},
    {"kepler:e=0.5", 0.02, 4.0},
    {"spring_chain:init=node,node=1,ends=fixed,n=4,mass=2.5,model=fpu_beta,amplitude=0.4,"
     "velocity=0.1",
     0.1, 5.0},
};
const std::vector<std::string> kMethods = {"stormer_verlet", "position_verlet",
                                           "implicit_midpoint"};

// One run at h: the observer fits both slopes over h, h/2, h/4 (harness/modified_energy.hpp).
TEST(ModifiedEnergy, ErrorFallsLikeHFourWhileTheEnergyErrorFallsLikeHSquared) {
  for (const std::string& method : kMethods) {
    for (const Case& c : kCases) {
      RunConfig config;
      config.dt = c.h;
      config.t_end = c.t_end;
      config.timing_repeats = 0;
      config.extra_metrics = {"modified_energy_err_max"};
      const RunResult result = run_one(c.problem, method, config);
      ASSERT_TRUE(result.ok) << method << " on " << c.problem;
      const auto& metrics = result.record.metrics;
      const double energy = metrics.at("energy_err_max");
      const double modified = metrics.at("modified_energy_err_max");
      const double energy_slope = metrics.at("energy_err_slope");
      const double modified_slope = metrics.at("modified_energy_err_slope");
      std::printf("%-18s %-14.14s energy %.3g slope %.2f  modified %.3g slope %.2f\n",
                  method.c_str(), c.problem.c_str(), energy, energy_slope, modified,
                  modified_slope);
      EXPECT_NEAR(energy_slope, 2.0, 0.3) << method << " on " << c.problem;
      EXPECT_NEAR(modified_slope, 4.0, 0.3) << method << " on " << c.problem;
      // H̃ is the better invariant already at the coarsest step.
      EXPECT_LT(modified, 0.1 * energy) << method << " on " << c.problem;
    }
  }
}

// Negative control: RK4 conserves nothing, and its energy error is O(h⁴) already; adding the
// Verlet correction h²H₂ to it adds an O(h²) oscillation instead of cancelling anything.
TEST(ModifiedEnergy, VerletCorrectionDoesNotImproveRk4) {
  const auto correction = *modified_energy_correction("stormer_verlet");
  for (const Case& c : kCases) {
    const auto problem = make_problem(c.problem);
    auto rk4 = make_integrator("rk4");
    const double h = c.h / 2;
    State state = problem->initial_state();
    rk4->reset(*problem, state, h);
    const double energy0 = problem->energy(state.q, state.p);
    const double modified0 = modified_energy(correction, *problem, state.q, state.p, h);
    double energy_err = 0, modified_err = 0;
    const long steps = std::lround(c.t_end / h);
    for (long k = 0; k < steps; ++k) {
      ASSERT_TRUE(rk4->step(*problem, state, h).ok);
      energy_err = std::max(energy_err, std::abs(problem->energy(state.q, state.p) - energy0));
      modified_err = std::max(
          modified_err,
          std::abs(modified_energy(correction, *problem, state.q, state.p, h) - modified0));
    }
    std::printf("rk4 %-14.14s energy err %.3g, with the Verlet correction %.3g\n",
                c.problem.c_str(), energy_err, modified_err);
    EXPECT_GT(modified_err, 2 * energy_err) << c.problem;
  }
}

// Applicability: the known corrections only, on separable unforced problems with a Hessian.
TEST(ModifiedEnergy, AppliesOnlyWhereTheCorrectionIsKnown) {
  const auto kepler = make_problem("kepler:e=0.5");
  EXPECT_EQ(modified_energy_not_applicable(*make_integrator("stormer_verlet"), *kepler, 0.01), "");
  EXPECT_NE(modified_energy_not_applicable(*make_integrator("rk4"), *kepler, 0.01), "");
  EXPECT_NE(modified_energy_not_applicable(*make_integrator("stormer_verlet"),
                                           *make_problem("damped_oscillator"), 0.01),
            "");
  EXPECT_NE(modified_energy_not_applicable(*make_integrator("implicit_midpoint"),
                                           *make_problem("double_pendulum"), 0.01),
            "");
  // An inapplicable method gets no column (empty in the tables), not a number.
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 0.1;
  config.timing_repeats = 0;
  config.extra_metrics = {"modified_energy_err_max"};
  EXPECT_EQ(run_one("kepler:e=0.5", "rk4", config).record.metrics.count("modified_energy_err_max"),
            0u);
}

}  // namespace
}  // namespace modified_energy_test
}  // namespace geomint
