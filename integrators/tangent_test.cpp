// The linearised step Integrator::step_tangent (integrators/tangent.hpp; docs/USAGE.md "Optional
// structure metrics") against a central difference of step(), for every method that implements it,
// on small nonlinear problems with unit and non-unit masses. The difference is only a cross-check
// here; the metric itself never differences.
#include "integrators/tangent.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace geomint {
namespace tangent_test {
namespace {

// One step of a fresh, reset integrator from `start`, as (q, p).
Vec one_step(const std::string& spec, const Problem& problem, const State& start, double h) {
  const auto method = make_integrator(spec);
  State state = start;
  method->reset(problem, state, h);
  EXPECT_TRUE(method->step(problem, state, h).ok) << spec;
  Vec out(2 * state.q.size());
  out << state.q, state.p;
  return out;
}

// Central difference with steps ε^{1/3}·max(|y_j|, 1): errors ~1e-10 relative.
Eigen::MatrixXd difference_tangent(const std::string& spec, const Problem& problem, State state,
                                   double h) {
  const long n = state.q.size();
  Eigen::MatrixXd jacobian(2 * n, 2 * n);
  for (long j = 0; j < 2 * n; ++j) {
    double& entry = j < n ? state.q[j] : state.p[j - n];
    const double original = entry;
    const double delta =
        std::cbrt(std::numeric_limits<double>::epsilon()) * std::max(1.0, std::abs(original));
    entry = original + delta;
    const double plus_value = entry;
    const Vec plus = one_step(spec, problem, state, h);
    entry = original - delta;
    const double minus_value = entry;
    const Vec minus = one_step(spec, problem, state, h);
    entry = original;
    jacobian.col(j) = (plus - minus) / (plus_value - minus_value);
  }
  return jacobian;
}

// Small nonlinear problems, two with non-unit masses (a FPU-β chain of 0.7 masses, a 3D
// three-body problem with masses 2, 0.5, 1.5).
const std::vector<std::string>& tangent_problems() {
  static const std::vector<std::string> specs = {
      "kepler:e=0.5", "henon_heiles",
      "spring_chain:n=3,mass=0.7,model=fpu_beta,init=node,node=2,amplitude=0.4,velocity=0.3",
      "nbody:preset=custom,dim=3,masses=2/0.5/1.5,positions=1/0/0/-1/0.5/0/0/-1/0.3,"
      "velocities=0/0.4/0.1/0.2/-0.6/0/-0.3/0.1/0.2,G=1.3"};
  return specs;
}

TEST(StepTangent, MatchesACentralDifferenceOfTheStepForEveryMethodThatHasOne) {
  int methods = 0;
  double worst = 0;
  for (const auto& spec : integrator_test_specs()) {
    bool counted = false;
    for (const auto& problem_spec : tangent_problems()) {
      const auto problem = make_problem(problem_spec);
      const auto method = make_integrator(spec);
      if (!applicable(*method, *problem).ok || !method->has_step_tangent(*problem)) continue;
      const double h = 0.05;
      State state = problem->initial_state();
      const State start = state;
      method->reset(*problem, state, h);
      Eigen::MatrixXd tangent;
      ASSERT_TRUE(method->step_tangent(*problem, state, h, tangent).ok) << spec;
      // The step it takes is step()'s.
      Vec end(2 * state.q.size());
      end << state.q, state.p;
      EXPECT_LE((end - one_step(spec, *problem, start, h)).cwiseAbs().maxCoeff(),
                1e-12 * std::max(1.0, end.cwiseAbs().maxCoeff()))
          << spec << " on " << problem_spec;
      const Eigen::MatrixXd difference = difference_tangent(spec, *problem, start, h);
      const double error = (tangent - difference).cwiseAbs().maxCoeff() /
                           std::max(1.0, tangent.cwiseAbs().maxCoeff());
      EXPECT_LE(error, 1e-7) << spec << " on " << problem_spec;
      worst = std::max(worst, error);
      if (!counted) ++methods, counted = true;
    }
  }
  std::printf("%d methods, largest relative difference %.2g\n", methods, worst);
  // explicit and implicit Euler, both symplectic Eulers, both Verlets, RK4, midpoint, del, hp,
  // Newmark, HHT, generalized-α, Gauss, Lobatto, compositions.
  EXPECT_GE(methods, 30);
}

// Where the exact tangent is not derived the hook says so instead of differencing: forces,
// constraints, library and adaptive solvers.
TEST(StepTangent, IsNotOfferedWhereItIsNotDerived) {
  EXPECT_FALSE(
      make_integrator("stormer_verlet")->has_step_tangent(*make_problem("damped_oscillator")));
  EXPECT_FALSE(make_integrator("rattle")->has_step_tangent(*make_problem("cartesian_pendulum")));
  EXPECT_FALSE(make_integrator("odeint_dopri5")->has_step_tangent(*make_problem("kepler")));
  EXPECT_FALSE(make_integrator("adaptive_verlet")->has_step_tangent(*make_problem("kepler")));
  EXPECT_TRUE(make_integrator("gauss")->has_step_tangent(*make_problem("kepler")));
}

}  // namespace
}  // namespace tangent_test
}  // namespace geomint
