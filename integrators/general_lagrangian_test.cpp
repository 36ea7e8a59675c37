// The integrators on the general Lagrangian kind (integrators/general_step.hpp,
// docs/MECHANICS_GENERAL.md): round-off agreement with the separable path where the scheme is the
// same, fitted orders on the double pendulum for every applicable method of the registry,
// discrete Noether for p_φ in polar Kepler, and polar against Cartesian error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "integrators/general_step.hpp"
#include "integrators/high_order_coefficients.hpp"
#include "integrators/integrator.hpp"
#include "problems/articulated.hpp"
#include "problems/lagrangian.hpp"

namespace geomint {
namespace general_lagrangian_test {
namespace {

double inf_norm(const Vec& x) { return x.size() == 0 ? 0.0 : x.cwiseAbs().maxCoeff(); }

// Runs `steps` fixed steps of h; the final state, or a failed test.
State run(Integrator& method, const Problem& problem, State state, double h, long steps) {
  method.reset(problem, state, h);
  for (long k = 0; k < steps; ++k) {
    const StepStatus status = method.step(problem, state, h);
    EXPECT_TRUE(status.ok) << method.spec() << " on " << problem.spec() << ": " << status.message;
    if (!status.ok) break;
  }
  return state;
}

// Least-squares slope of log(error) against log(h).
double fitted_order(const std::vector<double>& steps, const std::vector<double>& errors) {
  double mx = 0, my = 0;
  const double n = static_cast<double>(steps.size());
  for (size_t i = 0; i < steps.size(); ++i)
    mx += std::log(steps[i]) / n, my += std::log(errors[i]) / n;
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < steps.size(); ++i) {
    sxy += (std::log(steps[i]) - mx) * (std::log(errors[i]) - my);
    sxx += (std::log(steps[i]) - mx) * (std::log(steps[i]) - mx);
  }
  return sxy / sxx;
}

// Separable problems small enough for dense steps, with a Hessian, no force or constraints, at
// non-unit masses (the registry's variants). The stiff ones are left out: their condition number
// (1e8 for stiff_spring) multiplies the two solves' round-off differences to 5e-12 of p.
std::vector<std::string> separable_specs() {
  std::vector<std::string> specs;
  for (const auto& spec : problem_test_specs()) {
    const auto problem = make_problem(spec);
    if (problem->has(kHessian) && !problem->has(kForce) && !problem->has(kConstraints) &&
        !problem->has(kFirstOrderOnly) && problem->kind() != ProblemKind::kLagrangian &&
        problem->dof() <= 12 && problem->name() != "fpu_stiff" &&
        problem->name() != "stiff_spring") {
      specs.push_back(spec);
    }
  }
  return specs;
}

// Where the scheme is the same, the general step on the constant-mass adapter and the separable
// step give the same states to round-off: the DEL α-rule (α = ½ and ¼), today's hp (its minimiser
// and its Newton solver: the HP step is the α-rule DEL step in position–momentum form, so the
// general hp runs general_del_step) and the implicit midpoint rule (for constant M all are the
// same family, docs/METHOD.md §1).
TEST(GeneralStep, AgreesWithTheSeparablePathToRoundOff) {
  // The general step each separable method is compared with.
  enum class Step { kDel, kMidpoint, kLeapfrog, kGauss2, kLobatto3 };
  struct Pair {
    std::string method;
    Step step;
    double alpha;  // the DEL/HP rule's α
  };
  const std::vector<Pair> pairs = {{"del", Step::kDel, 0.5},
                                   {"del:rule=alpha,alpha=0.25", Step::kDel, 0.25},
                                   {"hp", Step::kDel, 0.5},
                                   {"hp:alpha=0.25,solver=newton", Step::kDel, 0.25},
                                   {"hp:alpha=0.75", Step::kDel, 0.75},
                                   {"implicit_midpoint", Step::kMidpoint, 0},
                                   {"stormer_verlet", Step::kLeapfrog, 0},
                                   {"gauss:s=2", Step::kGauss2, 0},
                                   {"lobatto3ab:s=3", Step::kLobatto3, 0}};
  const auto dense = [](const coefficients::PartitionedTableau& tableau, bool hat) {
    DenseMatrix a(tableau.stages, tableau.stages);
    for (int i = 0; i < tableau.stages; ++i)
      for (int j = 0; j < tableau.stages; ++j)
        a(i, j) = static_cast<double>(hat ? tableau.a_hat[i][j] : tableau.a[i][j]);
    return a;
  };
  const auto weights = [](const coefficients::PartitionedTableau& tableau) {
    Vec b(tableau.stages);
    for (int i = 0; i < tableau.stages; ++i) b[i] = static_cast<double>(tableau.b[i]);
    return b;
  };
  const DenseMatrix gauss_a = dense(coefficients::kGauss2, false);
  const DenseMatrix lobatto_a = dense(coefficients::kLobatto3, false);
  const DenseMatrix lobatto_a_hat = dense(coefficients::kLobatto3, true);
  const Vec gauss_b = weights(coefficients::kGauss2);
  const Vec lobatto_b = weights(coefficients::kLobatto3);
  const GeneralNewtonSettings newton{1e-12, 50};
  int compared = 0;
  for (const auto& spec : separable_specs()) {
    const auto problem = make_problem(spec);
    const SeparableLagrangian general(*problem);
    const State start = problem->initial_state();
    const double h = problem->default_dt() * 3;
    for (const auto& pair : pairs) {
      const auto method = make_integrator(pair.method);
      const State separable = run(*method, *problem, start, h, 20);
      State state = start;
      Counters counters;
      for (int k = 0; k < 20; ++k) {
        StepStatus status;
        switch (pair.step) {
          case Step::kDel:
            status = general_del_step(general, state, h, pair.alpha, newton, counters);
            break;
          case Step::kMidpoint:
            status = general_implicit_midpoint_step(general, state, h, newton, counters);
            break;
          case Step::kLeapfrog:
            status = general_leapfrog_step(general, state, h, newton, counters);
            break;
          case Step::kGauss2:
            status = general_partitioned_rk_step(general, state, h, gauss_a, gauss_a, gauss_b,
                                                 newton, counters);
            break;
          case Step::kLobatto3:
            status = general_partitioned_rk_step(general, state, h, lobatto_a, lobatto_a_hat,
                                                 lobatto_b, newton, counters);
            break;
        }
        ASSERT_TRUE(status.ok) << status.message;
      }
      const double q_scale = std::max(inf_norm(start.q), inf_norm(separable.q));
      const double p_scale = std::max(inf_norm(start.p), inf_norm(separable.p));
      EXPECT_LE(inf_norm(state.q - separable.q), 1e-12 * q_scale) << spec << " " << pair.method;
      EXPECT_LE(inf_norm(state.p - separable.p), 1e-12 * p_scale) << spec << " " << pair.method;
      ++compared;
    }
  }
  EXPECT_GE(compared, 27);
}

// Every fixed-step method of the registry that applies to the double pendulum (theta1 = 0.3,
// theta2 = −0.2) reaches its declared order in q and in p, within ±0.3: errors at t = 1 for
// h = 0.05 … 0.00625 (h·ω from 0.3 down, ω ≈ 5.8 the faster normal mode; without the finest
// level for order ≥ 5, whose error there is near round-off) against RK4 at h = 1/16384 (error
// ~ 1e-15).
TEST(GeneralStep, DoublePendulumOrdersMatchTheDeclaredOnes) {
  const auto problem = make_problem("double_pendulum:theta1=0.3,theta2=-0.2,omega2=0.5");
  const State start = problem->initial_state();
  const auto reference_method = make_integrator("rk4");
  const State reference = run(*reference_method, *problem, start, 1.0 / 16384, 16384);
  std::vector<std::string> fitted_specs;
  for (const auto& spec : integrator_test_specs()) {
    const auto method = make_integrator(spec);
    const MethodInfo info = method->info();
    if ((info.flags & kAdaptive) || !applicable(*method, *problem).ok) continue;
    // The engines' steps are fitted on this problem in engines/engines_test.cpp (MuJoCo's RK4 is
    // not yet asymptotic in p at h = 0.05: error ratio 3.8, then 11.6 and 14.1).
    if (method->provider().kind == MethodProvider::Kind::kEngine) continue;
    std::vector<double> steps, q_errors, p_errors;
    for (int level = 0; level < (info.order >= 5 ? 3 : 4); ++level) {
      const double h = 0.05 / (1 << level);
      const State end = run(*method, *problem, start, h, 20L << level);
      steps.push_back(h);
      q_errors.push_back(inf_norm(end.q - reference.q));
      p_errors.push_back(inf_norm(end.p - reference.p));
    }
    EXPECT_NEAR(fitted_order(steps, q_errors), info.order, 0.3)
        << spec << " q errors " << ::testing::PrintToString(q_errors);
    EXPECT_NEAR(fitted_order(steps, p_errors), info.order, 0.3)
        << spec << " p errors " << ::testing::PrintToString(p_errors);
    fitted_specs.push_back(spec);
  }
  // The methods whose orders docs/MECHANICS_GENERAL.md quotes (hp is hp:alpha=0.5, gauss is
  // gauss:s=2) must be among the fitted specs.
  for (const char* required : {"del", "hp", "implicit_midpoint", "gauss", "gauss:s=3",
                               "generalized_leapfrog", "tao", "tao:order=4,omega=5", "rk4"}) {
    EXPECT_NE(std::find(fitted_specs.begin(), fitted_specs.end(), required), fitted_specs.end())
        << required;
  }
}

// The adaptive library solvers flagged general_lagrangian (CVODE with the dense and the KLU
// solver, IDA, ARKODE ERK, GSL rk8pd, msbdf and rk4imp, odeint dopri5 and rosenbrock4) see only
// first_order_rhs and its Jacobian: on the double pendulum at non-unit masses and lengths they
// reach the accurate RK4 solution at t = 1 to their tolerance (defaults rtol 1e-8, atol 1e-10).
TEST(GeneralStep, AdaptiveLibrarySolversRunTheFirstOrderForm) {
  const auto problem =
      make_problem("double_pendulum:m1=1.3,m2=0.7,l1=0.9,l2=1.6,theta1=0.3,theta2=-0.2");
  const State start = problem->initial_state();
  const auto reference_method = make_integrator("rk4");
  const State reference = run(*reference_method, *problem, start, 1.0 / 16384, 16384);
  std::vector<std::string> checked;
  for (const auto& spec : integrator_test_specs()) {
    const auto method = make_integrator(spec);
    if (!(method->info().flags & kAdaptive) || !applicable(*method, *problem).ok) continue;
    State state = start;
    method->reset(*problem, state, 0.01);
    for (int k = 0; k < 100000 && state.t < 1.0; ++k) {
      const StepStatus status = method->adaptive_step(*problem, state, 1.0);
      ASSERT_TRUE(status.ok) << spec << ": " << status.message;
    }
    ASSERT_EQ(state.t, 1.0) << spec;
    EXPECT_LE(inf_norm(state.q - reference.q), 1e-5) << spec;
    EXPECT_LE(inf_norm(state.p - reference.p), 1e-5) << spec;
    checked.push_back(spec);
  }
  for (const char* required :
       {"cvode_bdf", "cvode_bdf:linear_solver=klu", "ida", "arkode_erk", "gsl_rk8pd", "gsl_msbdf",
        "gsl_rk4imp", "odeint_dopri5", "odeint_rosenbrock4"}) {
    EXPECT_NE(std::find(checked.begin(), checked.end(), required), checked.end()) << required;
  }
}

// The solvers that use the Jacobian of Hamilton's equations (analytic on the general kind,
// docs/MECHANICS_GENERAL.md §1) at tight tolerance (rtol 1e-10, atol 1e-12) on the double
// pendulum at non-unit masses and lengths: within 1e-8 of the RK4 solution at h = 1/16384 (error
// ~1e-15) at t = 1, and at least 10× closer than at the default tolerances (rtol 1e-8; measured
// 30–95×) — the error follows the tolerance, so the steps converge to this solution, not near it.
TEST(GeneralStep, JacobianLibrarySolversFollowTheirToleranceOnTheDoublePendulum) {
  const auto problem =
      make_problem("double_pendulum:m1=1.3,m2=0.7,l1=0.9,l2=1.6,g=2.5,theta1=0.3,theta2=-0.2");
  const State start = problem->initial_state();
  const auto reference_method = make_integrator("rk4");
  const State reference = run(*reference_method, *problem, start, 1.0 / 16384, 16384);
  const auto error_at_one = [&](const std::string& spec) {
    const auto method = make_integrator(spec);
    EXPECT_TRUE(applicable(*method, *problem).ok) << spec;
    State state = start;
    method->reset(*problem, state, 0.01);
    for (int k = 0; k < 100000 && state.t < 1.0; ++k) {
      const StepStatus status = method->adaptive_step(*problem, state, 1.0);
      EXPECT_TRUE(status.ok) << spec << ": " << status.message;
      if (!status.ok) return 1.0;
    }
    EXPECT_EQ(state.t, 1.0) << spec;
    // The analytic Jacobian was used (IDA and CVODE count none for a difference quotient).
    EXPECT_GT(method->counters().hessian_evals, 0) << spec;
    return std::max(inf_norm(state.q - reference.q), inf_norm(state.p - reference.p));
  };
  for (const std::string spec :
       {"ida", "gsl_msbdf", "gsl_rk4imp", "odeint_rosenbrock4", "cvode_bdf:linear_solver=klu"}) {
    const std::string tight =
        spec + (spec.find(':') == std::string::npos ? ":" : ",") + "rtol=1e-10,atol=1e-12";
    const double loose_error = error_at_one(spec);
    const double tight_error = error_at_one(tight);
    EXPECT_LE(tight_error, 1e-8) << tight;
    EXPECT_LE(tight_error, loose_error / 10)
        << spec << ": " << loose_error << " then " << tight_error;
  }
}

// Discrete Noether: φ is cyclic, so every variational step keeps p_φ to round-off.
TEST(GeneralStep, PolarKeplerKeepsAngularMomentumToRoundOff) {
  for (const char* spec : {"del", "hp", "hp:solver=newton", "implicit_midpoint"}) {
    const auto problem = make_problem("kepler:coordinates=polar,e=0.6");
    const auto method = make_integrator(spec);
    const State start = problem->initial_state();
    State state = start;
    method->reset(*problem, state, 0.02);
    double worst = 0;
    for (int k = 0; k < 315; ++k) {
      ASSERT_TRUE(method->step(*problem, state, 0.02).ok);
      worst = std::max(worst, std::abs(state.p[1] - start.p[1]));
    }
    EXPECT_LE(worst, 1e-13) << spec;
  }
}

// The same scheme and step in the two coordinate systems, position errors against the exact orbit
// after one period (e = 0.3, h = 2π/400). One might expect them within a factor 2 of each
// other; measured, polar is far more accurate (del and implicit_midpoint 4.3e-5 against 3.1e-3,
// rk4 2.1e-9 against 7.0e-8): the motion is nearly uniform in (r, φ). What holds, and is checked,
// is that the polar formulation is never worse than twice the Cartesian one.
TEST(GeneralStep, PolarAndCartesianKeplerErrorsAgreeWithinAFactorTwo) {
  const auto polar = make_problem("kepler:coordinates=polar,e=0.3");
  const auto cartesian = make_problem("kepler:e=0.3");
  const double t_end = 2 * std::acos(-1.0);
  const long steps = 400;
  const double h = t_end / steps;
  const State exact = cartesian->exact(t_end);
  for (const char* spec : {"del", "implicit_midpoint", "rk4"}) {
    const auto method = make_integrator(spec);
    const State in_polar = run(*method, *polar, polar->initial_state(), h, steps);
    const State in_cartesian = run(*method, *cartesian, cartesian->initial_state(), h, steps);
    Vec mapped(2);
    mapped << in_polar.q[0] * std::cos(in_polar.q[1]), in_polar.q[0] * std::sin(in_polar.q[1]);
    const double polar_error = inf_norm(mapped - exact.q);
    const double cartesian_error = inf_norm(in_cartesian.q - exact.q);
    EXPECT_LE(polar_error, 2 * cartesian_error)
        << spec << " polar " << polar_error << " cartesian " << cartesian_error;
  }
}

// The declared requirement, not a list of names: a method runs on a non-separable problem
// exactly when it is flagged general_lagrangian, and a refusal says why.
TEST(GeneralStep, ApplicabilityFollowsTheDeclaredFlag) {
  const auto problem = make_problem("double_pendulum");
  int refused = 0, admitted = 0;
  for (const auto& spec : integrator_test_specs()) {
    const auto method = make_integrator(spec);
    const Applicability verdict = applicable(*method, *problem);
    // A constraints-only method that runs the general kind (ida:index=2|3 on andrews) is refused
    // here for the constraints the double pendulum lacks, not for its kind.
    const unsigned flags = method->info().flags;
    const bool constraints_only = (flags & kGeneralLagrangian) && (flags & kConstraintsOnly);
    if (constraints_only) {
      EXPECT_FALSE(verdict.ok) << spec;
      EXPECT_NE(verdict.reason.find("holonomic constraints"), std::string::npos) << verdict.reason;
      continue;
    }
    const bool general = (flags & kGeneralLagrangian) != 0;
    EXPECT_EQ(verdict.ok, general) << spec << ": " << verdict.reason;
    // A free-rigid-body-only or charged-particle-only method is refused first for lacking the
    // structure it reads.
    const bool rigid_only =
        (method->info().flags & (kFreeRigidBodyOnly | kChargedParticleOnly)) != 0;
    if (general) {
      ++admitted;
    } else {
      if (!rigid_only) {
        EXPECT_NE(verdict.reason.find("separable"), std::string::npos) << spec << verdict.reason;
      }
      ++refused;
    }
  }
  EXPECT_GE(admitted, 5);
  EXPECT_GE(refused, 20);
}

// RK4 on an articulated problem runs on the O(n) recursions alone: per step, 4 evaluations of
// Hamilton's equations, each one mass solve (2 recursive passes) and one ∂T/∂θ (2 passes), and
// nothing else that walks the tree (the work counter of problems/articulated.hpp), at any n.
TEST(ArticulatedRk4, SixteenRecursivePassesPerStep) {
  for (const std::string spec : {"rope:n=256", "branching", "rod_chain:coordinates=joint,n=100"}) {
    const auto problem = make_problem(spec);
    const auto* tree =
        dynamic_cast<const articulated::PlanarTreeLagrangian*>(problem->as_lagrangian());
    ASSERT_NE(tree, nullptr) << spec;
    const auto method = make_integrator("rk4");
    State state = problem->initial_state();
    method->reset(*problem, state, problem->default_dt());
    const long before = tree->dynamics().passes();
    for (int k = 0; k < 10; ++k)
      ASSERT_TRUE(method->step(*problem, state, problem->default_dt()).ok);
    EXPECT_EQ(tree->dynamics().passes() - before, 160) << spec;
  }
}

}  // namespace
}  // namespace general_lagrangian_test
}  // namespace geomint
