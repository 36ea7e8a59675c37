// Kahan's compensated summation in stormer_verlet and the compositions over it (GNI §VIII.5):
// the same method to round-off, and round-off that no longer random-walks (Brouwer's law).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "integrators/integrator.hpp"

namespace geomint {
namespace compensated_summation_test {
namespace {

struct RunResult {
  State state;
  double energy_err_max = 0;
};

RunResult run_fixed(const std::string& method_spec, const Problem& problem, double h, long steps) {
  const auto method = make_integrator(method_spec);
  RunResult out{problem.initial_state(), 0.0};
  const double energy0 = problem.energy(out.state.q, out.state.p);
  method->reset(problem, out.state, h);
  for (long k = 0; k < steps; ++k) {
    EXPECT_TRUE(method->step(problem, out.state, h).ok);
    out.energy_err_max =
        std::max(out.energy_err_max, std::abs(problem.energy(out.state.q, out.state.p) - energy0));
  }
  return out;
}

// Compensation changes only the rounding: after 100 steps the two runs agree to a few ulps of the
// state's size, on a forced problem too (the force path is compensated as well).
TEST(CompensatedSummation, IsTheSameMethodUpToRoundOff) {
  for (const char* problem_spec : {"kepler:e=0.6", "damped_oscillator", "spring_net"}) {
    SCOPED_TRACE(problem_spec);
    const auto problem = make_problem(problem_spec);
    const RunResult plain = run_fixed("stormer_verlet", *problem, 0.01, 100);
    const RunResult compensated = run_fixed("stormer_verlet:compensated=true", *problem, 0.01, 100);
    const double scale = plain.state.q.norm() + plain.state.p.norm();
    EXPECT_LE((plain.state.q - compensated.state.q).norm(), 1e-12 * scale);
    EXPECT_LE((plain.state.p - compensated.state.p).norm(), 1e-12 * scale);
    EXPECT_NE(plain.state.q, compensated.state.q) << "the option changed nothing";
  }
}

// Brouwer's law: with the truncation error below round-off (8th-order composition, h = 0.01 on
// Kepler e = 0.6), plain summation's energy error grows like √N (measured 4.2e-14 after 3·10³
// steps, 1.5e-13 after 3·10⁴); compensated it stays at a few ulps (2.2e-15, 2.7e-15).
TEST(CompensatedSummation, StopsTheRoundOffRandomWalk) {
  const auto problem = make_problem("kepler:e=0.6");
  const RunResult plain = run_fixed("composition:scheme=kahan_li8", *problem, 0.01, 30000);
  const RunResult compensated =
      run_fixed("composition:scheme=kahan_li8,compensated=true", *problem, 0.01, 30000);
  EXPECT_LT(compensated.energy_err_max, 1e-14);
  EXPECT_GT(plain.energy_err_max, 10 * compensated.energy_err_max)
      << plain.energy_err_max << " vs " << compensated.energy_err_max;
}

TEST(CompensatedSummation, OnlyTheVerletBaseImplementsIt) {
  EXPECT_THROW(make_integrator("composition:base=implicit_midpoint,compensated=true"), InputError);
}

}  // namespace
}  // namespace compensated_summation_test
}  // namespace geomint
