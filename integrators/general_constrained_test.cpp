// RATTLE and the constrained hp/del steps on a position-dependent mass (general_constrained_step):
// Andrews' squeezing mechanism against the IVP Test Set's reference (order 2, constraints at
// round-off, energy balance with the torque's work), and the general path equal to the separable
// one on constant-mass constrained problems given their general view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "integrators/general_constrained_step.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"

namespace geomint {
namespace general_constrained_test {
namespace {

// The methods that constrain the general kind through general_constrained_step.
const std::vector<std::string> kGeneralConstrainedSpecs = {"rattle", "hp", "del:rule=midpoint"};

struct AndrewsRun {
  StepStatus status;
  State state;
  double position_drift = 0;  // max_k ‖g(q_k)‖∞ (m)
  double velocity_drift = 0;  // max_k ‖G(q_k)M(q_k)⁻¹p_k‖∞ (m/s)
};

AndrewsRun run_andrews(const std::string& spec, const Problem& problem, double h) {
  const auto method = make_integrator(spec);
  AndrewsRun out;
  out.state = problem.initial_state();
  method->reset(problem, out.state, h);
  const long steps = std::lround(problem.end_reference_time() / h);
  for (long k = 0; k < steps; ++k) {
    out.status = method->step(problem, out.state, h);
    if (!out.status.ok) return out;
    const State& at = out.state;
    out.position_drift = std::max(out.position_drift, problem.constraint_residual(at.t, at.q));
    out.velocity_drift =
        std::max(out.velocity_drift, problem.constraint_velocity_residual(at.t, at.q, at.p));
  }
  return out;
}

// On Andrews (a mass M(q), six loop closures, the driving torque, the spring) every method
// converges to the Test Set's positions at t = 0.03 with a fitted order of 2, keeps the
// positions on the constraint manifold at round-off and the momenta on its tangent space, and
// balances the energy against the torque's work, H(t) − H(0) = mom·(β(t) − β(0)), to O(h²).
TEST(GeneralConstrainedStep, AndrewsConvergesToTheTestSetWithOrderTwo) {
  const auto problem = make_problem("andrews");
  const State reference = problem->end_reference();
  const State start = problem->initial_state();
  const double torque = 0.033;
  const std::vector<double> steps = {4e-5, 2e-5, 1e-5};
  for (const std::string& spec : kGeneralConstrainedSpecs) {
    SCOPED_TRACE(spec);
    ASSERT_TRUE(applicable(*make_integrator(spec), *problem).ok);
    std::vector<double> position_errors, balance_errors;
    for (double h : steps) {
      const AndrewsRun out = run_andrews(spec, *problem, h);
      ASSERT_TRUE(out.status.ok) << out.status.message;
      const double position_error = (out.state.q - reference.q).lpNorm<Eigen::Infinity>();
      const double work = torque * (out.state.q[0] - start.q[0]);
      const double balance =
          problem->energy(out.state.q, out.state.p) - problem->energy(start.q, start.p) - work;
      position_errors.push_back(position_error);
      balance_errors.push_back(std::abs(balance) / work);
      std::printf(
          "andrews %s h=%g: |q - q_ref|inf %.3e, energy balance %.3e of the work, "
          "max|g| %.2e m, max|Gv| %.2e m/s\n",
          spec.c_str(), h, position_error, balance_errors.back(), out.position_drift,
          out.velocity_drift);
      EXPECT_LT(out.position_drift, 1e-15);  // the loops are ~0.03 m
      EXPECT_LT(out.velocity_drift, 1e-11);  // the velocities reach ~1e3 rad/s × 0.03 m
    }
    for (size_t k = 1; k < steps.size(); ++k) {
      const double order = std::log2(position_errors[k - 1] / position_errors[k]);
      const double balance_order = std::log2(balance_errors[k - 1] / balance_errors[k]);
      std::printf("andrews %s: fitted order %.3f (positions), %.3f (energy balance)\n",
                  spec.c_str(), order, balance_order);
      EXPECT_NEAR(order, 2.0, 0.1);
      EXPECT_NEAR(balance_order, 2.0, 0.3);
    }
    EXPECT_LT(position_errors.back(), 1e-2);
  }
}

// The general path on a constant-mass problem's general view (SeparableLagrangian) solves the
// same map as the separable steps: the same (q, p) and impulses to round-off after ten steps,
// also with time-dependent constraints and a force (car_axis) and with damping (the pinned bar).
TEST(GeneralConstrainedStep, GeneralViewOfAConstantMassMatchesTheSeparableStep) {
  const std::vector<std::string> problems = {"cartesian_pendulum", "spherical_pendulum",
                                             "rod_chain:n=3", "car_axis",
                                             "elastic_bar:clamp=pin,nx=2,ny=1,nz=1,damping=0.01"};
  struct Case {
    std::string spec;
    GeneralConstrainedScheme scheme;
  };
  const std::vector<Case> cases = {
      {"rattle", {.nodes = {{0.0, 0.5}, {1.0, 0.5}}, .forcing = Forcing{}, .rattle_kicks = true}},
      {"hp", {.nodes = {{0.5, 1.0}}, .forcing = Forcing{}}},
      {"del:rule=midpoint", {.nodes = {{0.5, 1.0}}, .forcing = Forcing{}}},
      {"del:rule=midpoint,force_slot=minus,force_at=node",
       {.nodes = {{0.5, 1.0}}, .forcing = {ForceSlot::kMinus, ForceAt::kNode}}},
  };
  for (const std::string& problem_spec : problems) {
    const auto problem = make_problem(problem_spec);
    ASSERT_TRUE(problem->has(kConstraints)) << problem_spec;
    ASSERT_EQ(problem->kind(), ProblemKind::kSeparable) << problem_spec;
    const SeparableLagrangian general_view(*problem);
    const double h = problem->default_dt();
    for (const Case& c : cases) {
      SCOPED_TRACE(problem_spec + " " + c.spec);
      const auto method = make_integrator(c.spec);
      State separable = problem->initial_state();
      State general = separable;
      method->reset(*problem, separable, h);
      Counters counters;
      std::optional<ConstraintImpulses> impulses;
      double impulse_difference = 0, impulse_size = 0;
      for (int k = 0; k < 10; ++k) {
        ASSERT_TRUE(method->step(*problem, separable, h).ok);
        const StepStatus status = general_constrained_step(
            *problem, general_view, c.scheme, general, h, {1e-14, 50}, counters, impulses, "test");
        ASSERT_TRUE(status.ok) << status.message;
        const ConstraintImpulses& old_impulses = *method->last_constraint_impulses();
        impulse_difference = std::max(
            {impulse_difference, (impulses->start - old_impulses.start).lpNorm<Eigen::Infinity>(),
             (impulses->end - old_impulses.end).lpNorm<Eigen::Infinity>()});
        impulse_size = std::max({impulse_size, old_impulses.start.lpNorm<Eigen::Infinity>(),
                                 old_impulses.end.lpNorm<Eigen::Infinity>()});
      }
      const double q_scale = separable.q.lpNorm<Eigen::Infinity>();
      const double p_scale = separable.p.lpNorm<Eigen::Infinity>();
      EXPECT_LE((general.q - separable.q).lpNorm<Eigen::Infinity>(), 1e-13 * q_scale);
      EXPECT_LE((general.p - separable.p).lpNorm<Eigen::Infinity>(), 1e-12 * p_scale);
      // The impulses are momenta: their round-off is that of the momentum balance they close.
      EXPECT_LE(impulse_difference, 1e-10 * std::max(impulse_size, p_scale));  // measured 2.6e-11
      EXPECT_EQ(general.t, separable.t);
    }
  }
}

// Registry-driven: on Andrews a constrained method runs exactly when it declares the general kind
// (its steps keep the loops closed), and the others are refused naming the mass M(q).
TEST(GeneralConstrainedStep, EveryConstrainedMethodRunsAndrewsOrSaysWhyNot) {
  const auto problem = make_problem("andrews");
  int runs = 0;
  for (const auto& spec : constrained_methods()) {
    SCOPED_TRACE(spec);
    const auto method = make_integrator(spec);
    const Applicability verdict = applicable(*method, *problem);
    const bool general = (method->info().flags & kGeneralLagrangian) != 0;
    EXPECT_EQ(verdict.ok, general) << verdict.reason;
    if (!verdict.ok) {
      EXPECT_NE(verdict.reason.find("M(q)"), std::string::npos) << verdict.reason;
      continue;
    }
    if (method->info().flags & kAdaptive) continue;  // IDA: constrained_methods_test.cpp
    State state = problem->initial_state();
    const double h = 1e-5;
    method->reset(*problem, state, h);
    for (int k = 0; k < 50; ++k) {
      const StepStatus status = method->step(*problem, state, h);
      ASSERT_TRUE(status.ok) << status.message;
    }
    EXPECT_LT(problem->constraint_residual(state.t, state.q), 1e-15);
    ++runs;
  }
  EXPECT_GE(runs, 3);  // rattle, hp, del:rule=midpoint and the compositions over them
}

}  // namespace
}  // namespace general_constrained_test
}  // namespace geomint
