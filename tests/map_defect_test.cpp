// The black-box symplecticity defect of the computed map (harness/map_defect.hpp; issue 27): at
// the finite-difference floor for every declared-symplectic method, O(h^{p+1}) above it for the
// non-symplectic ones, and an error estimate that bounds the difference to the exact DΦ.
#include "harness/map_defect.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "harness/structure_metrics.hpp"

namespace geomint {
namespace {

// A nonlinear problem with unit masses (Kepler, e = 0.5) and one with non-unit masses and
// non-unit scale (an FPU-β chain, m = 2.5, free ends so that a translation mode is present).
const std::vector<std::string> kProblems = {
    "kepler:e=0.5",
    "spring_chain:init=node,node=1,ends=free,n=4,mass=2.5,model=fpu_beta,amplitude=0.4,"
    "velocity=0.1"};

MapDefect defect_at_start(const std::string& method, const std::string& problem_spec, double h) {
  const auto problem = make_problem(problem_spec);
  return symplecticity_defect_map(method, *problem, problem->initial_state(), h);
}

// Every declared-symplectic method in the registry (fixed-step, unconstrained) on both problems:
// the defect is no larger than its own finite-difference error estimate (the floor), and that
// floor is small (bound 1e-7; floors measured ≤ 3.5e-12, defects ≤ 1.7e-12 at h = 0.05).
TEST(MapDefect, DeclaredSymplecticMethodsSitAtTheFiniteDifferenceFloor) {
  int checked = 0;
  for (const std::string& problem_spec : kProblems) {
    const auto problem = make_problem(problem_spec);
    for (const auto& spec : integrator_test_specs()) {
      const auto method = make_integrator(spec);
      if (!(method->info().flags & kSymplectic) || !applicable(*method, *problem).ok ||
          !map_defect_not_applicable(*method, *problem, 0.05).empty()) {
        continue;
      }
      const MapDefect value = defect_at_start(spec, problem_spec, 0.05);
      std::printf("%-44s %-10.10s defect %.3g fd_err %.3g\n", spec.c_str(), problem_spec.c_str(),
                  value.defect, value.fd_error);
      EXPECT_LE(value.defect, value.fd_error) << spec << " on " << problem_spec;
      EXPECT_LE(value.fd_error, 1e-7) << spec << " on " << problem_spec;
      ++checked;
    }
  }
  EXPECT_GE(checked, 20);
}

// The black-box measurement agrees with every fixed-step method's declared flag: a method without
// the symplectic flag computes a map standing 100x above the floor, one with it sits under it
// (Kepler e = 0.5, h = 0.05). A method that declared `symplectic` wrongly, or lost it to a bug
// in step(), fails here whatever its step_tangent says.
TEST(MapDefect, DeclaredFlagAgreesWithTheComputedMapForEveryFixedStepMethod) {
  const auto problem = make_problem("kepler:e=0.5");
  int symplectic = 0, not_symplectic = 0;
  for (const auto& spec : integrator_test_specs()) {
    const auto method = make_integrator(spec);
    if ((method->info().flags & kAdaptive) || !applicable(*method, *problem).ok ||
        !map_defect_not_applicable(*method, *problem, 0.05).empty()) {
      continue;
    }
    const MapDefect value =
        symplecticity_defect_map(spec, *problem, problem->initial_state(), 0.05);
    if (method->info().flags & kSymplectic) {
      EXPECT_LE(value.defect, value.fd_error) << spec;
      ++symplectic;
    } else {
      EXPECT_GT(value.defect, 100 * value.fd_error) << spec << " defect " << value.defect;
      ++not_symplectic;
    }
  }
  EXPECT_GE(symplectic, 20);
  EXPECT_GE(not_symplectic, 5);
}

// Non-symplectic maps of order p differ from the exact flow by O(h^{p+1}): far above the floor,
// and shrinking at that rate between h and h/2 (measured slopes in results/symplecticity).
TEST(MapDefect, NonSymplecticMethodsAreAboveTheFloorAndScaleWithTheOrder) {
  struct Case {
    std::string spec;
    double h;
    double slope;  // least power of h expected: p + 1
  };
  for (const std::string& problem_spec : kProblems) {
    for (const Case& c : std::vector<Case>{{"explicit_euler", 0.02, 2},
                                           {"implicit_euler", 0.02, 2},
                                           {"newmark:beta=0.25,gamma=0.6", 0.02, 2},
                                           {"newmark", 0.04, 3},
                                           {"rk4", 0.08, 5}}) {
      const MapDefect coarse = defect_at_start(c.spec, problem_spec, c.h);
      const MapDefect fine = defect_at_start(c.spec, problem_spec, c.h / 2);
      const double slope = std::log2(coarse.defect / fine.defect);
      std::printf("%-30s %-10.10s defect(h=%g) %.3g defect(h=%g) %.3g (fd_err %.2g) slope %.2f\n",
                  c.spec.c_str(), problem_spec.c_str(), c.h, coarse.defect, c.h / 2, fine.defect,
                  fine.fd_error, slope);
      EXPECT_GT(fine.defect, 100 * fine.fd_error) << c.spec << " on " << problem_spec;
      EXPECT_GT(slope, c.slope - 0.25) << c.spec << " on " << problem_spec;
    }
  }
}

// Adaptive solvers are measured through their integration over h: adaptive Verlet (a
// reparametrised Verlet whose step size depends on the state) stands 25x above its floor on
// Kepler; no slope is reported for them (their map is governed by the tolerance, not by h).
TEST(MapDefect, AdaptiveVerletIsResolvedAsNotSymplectic) {
  RunConfig config;
  config.dt = 0.05;
  config.t_end = 0.2;
  config.timing_repeats = 0;
  config.extra_metrics = {"symplecticity_defect_map"};
  const RunRecord record = run_one("kepler:e=0.5", "adaptive_verlet", config).record;
  ASSERT_TRUE(record.metrics.count("symplecticity_defect_map"));
  const double defect = record.metrics.at("symplecticity_defect_map");
  const double floor = record.metrics.at("symplecticity_defect_map_fd_err");
  std::printf("adaptive_verlet defect %.3g fd_err %.3g\n", defect, floor);
  EXPECT_GT(defect, 10 * floor);
  EXPECT_FALSE(record.metrics.count("symplecticity_defect_map_slope"));
}

// The error estimate is honest: where the method has an exact linearised step (step_tangent),
// the difference Jacobian is within its estimate of it, for explicit and implicit methods alike.
TEST(MapDefect, ErrorEstimateBoundsTheDistanceToTheLinearisedStep) {
  for (const std::string& problem_spec : kProblems) {
    const auto problem = make_problem(problem_spec);
    for (const std::string spec : {"stormer_verlet", "rk4", "implicit_midpoint", "hp", "newmark"}) {
      const auto method = make_integrator(spec);
      ASSERT_TRUE(method->has_step_tangent(*problem)) << spec;
      const MapJacobian map =
          computed_map_jacobian(*method, *problem, problem->initial_state(), 0.05);
      ASSERT_EQ(map.jacobian.rows(), 2 * problem->dof()) << spec;
      State state = problem->initial_state();
      method->reset(*problem, state, 0.05);
      Eigen::MatrixXd tangent;
      ASSERT_TRUE(method->step_tangent(*problem, state, 0.05, tangent).ok) << spec;
      const double distance = (map.jacobian - tangent).norm();
      std::printf("%-20s %-10.10s |J_fd - DPhi| %.3g estimate %.3g |J| %.3g\n", spec.c_str(),
                  problem_spec.c_str(), distance, map.error, tangent.norm());
      EXPECT_LE(distance, map.error + 1e-14 * tangent.norm()) << spec << " on " << problem_spec;
      EXPECT_LE(map.error, 1e-8 * tangent.norm()) << spec << " on " << problem_spec;
    }
  }
}

// The defect of a given J: zero for a symplectic shear and a rotation, the exact value for a
// scaling (det = s², JᵀΩJ = s²Ω: defect |s² − 1|).
TEST(MapDefect, DefectOfAGivenJacobian) {
  Eigen::MatrixXd shear = Eigen::MatrixXd::Identity(4, 4);
  shear.topRightCorner(2, 2) << 0.3, 0.1, 0.1, 2.0;  // symmetric block: symplectic
  EXPECT_LE(map_defect_of_jacobian(shear), 1e-16);
  EXPECT_NEAR(map_defect_of_jacobian(1.1 * Eigen::MatrixXd::Identity(4, 4)), 0.21, 1e-14);
  shear(0, 3) = 0.2;  // non-symmetric block: not symplectic
  EXPECT_GT(map_defect_of_jacobian(shear), 0.01);
}

// Where it does not apply the column is absent, with a reason: forced, constrained, first-order
// problems, an adaptive run without dt; an adaptive solver with dt is measured.
TEST(MapDefect, AppliesOnlyToCanonicalUnconstrainedMaps) {
  const auto verlet = make_integrator("stormer_verlet");
  EXPECT_NE(map_defect_not_applicable(*verlet, *make_problem("damped_oscillator"), 0.1), "");
  EXPECT_NE(map_defect_not_applicable(*verlet, *make_problem("cartesian_pendulum"), 0.1), "");
  EXPECT_NE(map_defect_not_applicable(*make_integrator("rk4"), *make_problem("van_der_pol"), 0.1),
            "");
  EXPECT_NE(map_defect_not_applicable(*make_integrator("cvode_bdf"), *make_problem("kepler"), 0),
            "");
  EXPECT_EQ(map_defect_not_applicable(*make_integrator("cvode_bdf"), *make_problem("kepler"), 0.1),
            "");
  RunConfig config;
  config.dt = 0.1;
  config.t_end = 0.5;
  config.timing_repeats = 0;
  config.extra_metrics = {"symplecticity_defect_map"};
  EXPECT_FALSE(run_one("damped_oscillator", "stormer_verlet", config)
                   .record.metrics.count("symplecticity_defect_map"));
  const RunRecord kepler = run_one("kepler:e=0.5", "rk4", config).record;
  ASSERT_TRUE(kepler.metrics.count("symplecticity_defect_map"));
  ASSERT_TRUE(kepler.metrics.count("symplecticity_defect_map_fd_err"));
  ASSERT_TRUE(kepler.metrics.count("symplecticity_defect_map_slope"));
  EXPECT_GT(kepler.metrics.at("symplecticity_defect_map_slope"), 4.5);
}

}  // namespace
}  // namespace geomint
