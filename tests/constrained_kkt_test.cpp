// The constrained hp / del:rule=midpoint step (docs/METHOD.md §3): the KKT solve with
// the multiplier force at q_k and the momentum projection, checked against RATTLE, across its two
// solvers, for order 2 (4 composed) on the cartesian pendulum, and for its iteration budget.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "harness/order.hpp"
#include "harness/run.hpp"
#include "integrators/integrator.hpp"

namespace geomint {
namespace constrained_kkt_test {
namespace {

// A bead of unit mass on the unit circle in the concave potential V = −(c/4)(x⁴ + y⁴) (four
// wells at the diagonals on the circle): ∇²V = −3c·diag(x², y²) makes the step's Hessian
// M + ¼h²∇²V indefinite at large h, the regime where the minimiser's safeguard and line search
// act — the catalogue's constrained problems all have linear potentials. A test fixture only.
class BeadInConcaveWells final : public Problem, public HolonomicConstraints {
 public:
  BeadInConcaveWells(double c, double theta0, double speed)
      : c_(c), theta0_(theta0), speed_(speed) {
    set_mass(Vec::Ones(2));
    set_capabilities(kHessian);
    set_defaults(0.01, 10.0);
  }
  State initial_state() const override {
    State s;
    s.q = Vec(2);
    s.q << std::cos(theta0_), std::sin(theta0_);
    s.p = Vec(2);
    s.p << -speed_ * std::sin(theta0_), speed_ * std::cos(theta0_);
    return s;
  }
  double potential(const Vec& q) const override {
    return -0.25 * c_ * (std::pow(q[0], 4) + std::pow(q[1], 4));
  }
  void gradient(const Vec& q, Vec& g) const override {
    g = Vec(2);
    g << -c_ * std::pow(q[0], 3), -c_ * std::pow(q[1], 3);
  }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    diagonal(-3 * c_ * q.cwiseAbs2(), H);
  }
  const HolonomicConstraints* as_constrained() const override { return this; }
  int constraint_count() const override { return 1; }
  void constraint(const Vec& q, Vec& g) const override {
    g = Vec::Constant(1, 0.5 * (q.squaredNorm() - 1));
  }
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override {
    G.resize(1, 2);
    G.setZero();
    G.insert(0, 0) = q[0];
    G.insert(0, 1) = q[1];
    G.makeCompressed();
  }
  void constraint_curvature(const Vec&, const Vec& v, Vec& c) const override {
    c = Vec::Constant(1, v.squaredNorm());
  }
  void constraint_hessian(const Vec&, const Vec& lambda, SparseMatrix& K) const override {
    diagonal(Vec::Constant(2, lambda[0]), K);
  }

 private:
  static void diagonal(const Vec& d, SparseMatrix& A) {
    A.resize(d.size(), d.size());
    A.setZero();
    for (int i = 0; i < d.size(); ++i) A.insert(i, i) = d[i];
    A.makeCompressed();
  }
  double c_, theta0_, speed_;
};

// Fixed steps of h from the problem's initial state; the worst |q − q_ref|, |p − p_ref| is taken
// by the caller.
State integrate(const std::string& method_spec, const Problem& problem, double h, long steps) {
  const auto method = make_integrator(method_spec);
  State state = problem.initial_state();
  method->reset(problem, state, h);
  for (long k = 0; k < steps; ++k) {
    const StepStatus status = method->step(problem, state, h);
    EXPECT_TRUE(status.ok) << method_spec << ": " << status.message;
    if (!status.ok) break;
  }
  return state;
}

double distance(const State& a, const State& b) {
  return std::max((a.q - b.q).lpNorm<Eigen::Infinity>(), (a.p - b.p).lpNorm<Eigen::Infinity>());
}

// Every catalogue constraint problem has a potential linear in q (uniform gravity), on which the
// midpoint and trapezoid quadratures of V coincide: the constrained midpoint step is then RATTLE
// (the constrained Störmer–Verlet DEL map) exactly, and must reproduce it to round-off. This pins
// the multiplier force at q_k (at q_{k+1} the map is a dissipative projection, far apart after
// 2000 steps) and the momentum projection (without it p leaves the tangent space at O(h)).
TEST(ConstrainedKkt, MidpointStepIsRattleOnALinearPotential) {
  for (const char* problem_spec :
       {"cartesian_pendulum:theta0=2.6",
        "spherical_pendulum:theta0=2.2,theta_dot0=0.4,"
        "phi_dot0=-0.9,mass=3",
        "rod_chain:n=3,mass=2,mass_ratio=0.5,length=0.7,length_ratio=1.5,gravity=2.5,theta1=0.3,"
        "theta2=-1.1,theta3=2.5,omega=0.4"}) {
    const auto problem = make_problem(problem_spec);
    const double h = problem->default_dt() * 5;
    // The chain is chaotic: round-off differences grow, so it is compared over fewer steps.
    const long steps = problem->as_constrained()->constraint_count() > 1 ? 100 : 2000;
    const State reference = integrate("rattle", *problem, h, steps);
    const double size =
        reference.q.lpNorm<Eigen::Infinity>() + reference.p.lpNorm<Eigen::Infinity>();
    for (const char* method : {"hp", "hp:solver=newton", "del:rule=midpoint"}) {
      SCOPED_TRACE(std::string(method) + " on " + problem_spec);
      EXPECT_LT(distance(integrate(method, *problem, h, steps), reference), 1e-9 * size);
    }
  }
}

// The same KKT equations: the minimiser and plain Newton land on the same root at moderate steps.
TEST(ConstrainedKkt, MinimiseAndNewtonSolversAgree) {
  const auto problem = make_problem("rod_chain:n=2");
  const double h = problem->default_dt() * 10;
  const State minimise = integrate("hp:solver=minimize", *problem, h, 500);
  const State newton = integrate("hp:solver=newton", *problem, h, 500);
  EXPECT_LT(distance(minimise, newton), 1e-9);
}

// Order 2 (±0.15) for the constrained HP midpoint under both solvers
// and for del:rule=midpoint, 4 (±0.3) for its Suzuki composition, on the cartesian pendulum.
TEST(ConstrainedKkt, OrderOnTheCartesianPendulum) {
  const std::string problem = "cartesian_pendulum:theta0=1.2";
  for (const auto& [method, order] : std::initializer_list<std::pair<const char*, double>>{
           {"hp", 2.0},
           {"hp:solver=newton", 2.0},
           {"del:rule=midpoint", 2.0},
           {"composition:base=hp_midpoint", 4.0}}) {
    const OrderStudy study =
        order_study(parse_problem(problem), MethodFactory(method), 0.1, 6, 10.0);
    ASSERT_TRUE(std::isfinite(study.fit.order)) << method << ": " << study.fit.note;
    EXPECT_NEAR(study.fit.order, order, order == 2.0 ? 0.15 : 0.3) << method;
  }
}

// The KKT iteration has a budget: exhausted, the run is a failure row naming both residuals.
TEST(ConstrainedKkt, IterationBudgetEndsTheRunAsAFailureRow) {
  RunConfig config;
  config.dt = 0.05;
  config.t_end = 1;
  config.timing_repeats = 0;
  for (const char* method : {"hp:max_iter=1", "hp:max_iter=1,solver=newton", "del:max_iter=1"}) {
    const RunResult result = run_one("rod_chain", method, config);
    EXPECT_FALSE(result.ok) << method;
    EXPECT_EQ(result.record.status, "newton_max_iter") << method;
    const std::string message = result.record.message.value_or("");
    EXPECT_NE(message.find("KKT Newton stopped after 1 iterations"), std::string::npos) << message;
    EXPECT_NE(message.find("max|g|"), std::string::npos) << message;
  }
}

// Only the midpoint variants take constraints, time-dependent ones (car_axis) included.
TEST(ConstrainedKkt, ApplicabilityOfTheVariants) {
  const auto pendulum = make_problem("cartesian_pendulum");
  for (const char* spec : {"hp", "hp:solver=newton", "del", "composition:base=hp_midpoint"}) {
    EXPECT_TRUE(applicable(*make_integrator(spec), *pendulum).ok) << spec;
    EXPECT_TRUE(applicable(*make_integrator(spec), *make_problem("kepler")).ok) << spec;
    EXPECT_TRUE(applicable(*make_integrator(spec), *make_problem("car_axis")).ok) << spec;
  }
  for (const char* spec : {"hp:alpha=0.25", "del:rule=trapezoid", "del:rule=left"}) {
    EXPECT_FALSE(applicable(*make_integrator(spec), *pendulum).ok) << spec;
  }
}

// Rheonomic constraints (car_axis: g1 moves with the driven point B(t)): g(q_{k+1}, t_{k+1}) = 0
// and G M⁻¹p + ∂g/∂t = 0 are kept at round-off, and the step converges at order 2 against the
// 6th-order composition over rattle (itself checked against the Test Set reference in the
// constraints scene). Short horizon (t = 0.2, about 1.5 wheel oscillations) to stay cheap.
// Measured: order 2.00 for hp and del, constraint residuals ≤ 1e-15.
TEST(ConstrainedKkt, RheonomicCarAxisKeepsTheMovingConstraintAtOrderTwo) {
  const std::string problem = "car_axis";
  RunConfig config;
  config.t_end = 0.2;
  config.timing_repeats = 0;
  config.dt = 2.5e-4;
  const RunResult fine = run_one(problem, "composition:base=rattle,scheme=kahan_li6", config);
  ASSERT_TRUE(fine.ok) << fine.record.message.value_or("");
  for (const char* method : {"hp", "del:rule=midpoint"}) {
    SCOPED_TRACE(method);
    std::vector<double> dts, errors;
    for (double dt : {0.004, 0.002, 0.001}) {
      config.dt = dt;
      const RunResult run = run_one(problem, method, config);
      ASSERT_TRUE(run.ok) << run.record.message.value_or("");
      EXPECT_LE(run.record.metrics.at("constraint_err_max"), 1e-13);
      EXPECT_LE(run.record.metrics.at("constraint_vel_err_max"), 1e-13);
      dts.push_back(dt);
      errors.push_back(std::sqrt((run.final_state.q - fine.final_state.q).squaredNorm() +
                                 (run.final_state.p - fine.final_state.p).squaredNorm()));
    }
    EXPECT_NEAR(fit_order(dts, errors).order, 2.0, 0.15)
        << "errors " << errors[0] << " " << errors[1] << " " << errors[2];
  }
}

// On a nonlinear potential, where the constrained midpoint step is not RATTLE: both solvers keep
// g and G M⁻¹p at round-off and agree, the energy error does not grow over 10⁴ steps, the step
// is reversible (h → −h) and of order 2 by self-convergence. Measured (h = 0.05, c = 10):
// energy error 3.6e-3 over the first and the last 2000 of 20000 steps alike.
TEST(ConstrainedKkt, BeadInConcaveWellsIsKeptSymmetricAndSecondOrder) {
  const BeadInConcaveWells problem(10.0, 0.3, 2.0);
  const double h = 0.05;
  const State start = problem.initial_state();
  const double energy = problem.energy(start.q, start.p);
  State reference;
  for (const char* spec : {"hp", "hp:solver=newton", "del:rule=midpoint"}) {
    SCOPED_TRACE(spec);
    const auto method = make_integrator(spec);
    State state = start;
    method->reset(problem, state, h);
    double early = 0, late = 0, g_max = 0, gv_max = 0;
    const long steps = 20000;
    for (long k = 0; k < steps; ++k) {
      const StepStatus status = method->step(problem, state, h);
      ASSERT_TRUE(status.ok) << status.message;
      const double error = std::abs(problem.energy(state.q, state.p) - energy);
      if (k < 2000) early = std::max(early, error);
      if (k >= steps - 2000) late = std::max(late, error);
      g_max = std::max(g_max, problem.constraint_residual(state.q));
      gv_max = std::max(gv_max, problem.constraint_velocity_residual(state.q, state.p));
    }
    std::printf("%s on the bead: energy error %.3g (first 2000 steps), %.3g (last 2000)\n", spec,
                early, late);
    EXPECT_LE(g_max, 1e-14);
    EXPECT_LE(gv_max, 1e-14 * 2.0);
    EXPECT_LT(late, 1.5 * early) << early;
    EXPECT_GT(early, 1e-4);  // the step is not exact: the comparison above means something
    if (reference.q.size() == 0) {
      reference = state;
    } else {
      EXPECT_LT(distance(state, reference), 1e-8);
    }
    // Reversibility: 50 steps forward, 50 with −h.
    State there = start;
    method->reset(problem, there, h);
    for (int k = 0; k < 50; ++k) ASSERT_TRUE(method->step(problem, there, h).ok);
    method->reset(problem, there, -h);
    for (int k = 0; k < 50; ++k) ASSERT_TRUE(method->step(problem, there, -h).ok);
    EXPECT_LT(distance(there, start), 1e-12);
    // Self-convergence at t = 2: |x_h − x_{h/2}| / |x_{h/2} − x_{h/4}| = 4.
    double differences[2];
    State previous;
    for (int level = 0; level < 3; ++level) {
      const double step = 0.02 / (1 << level);
      State at = start;
      method->reset(problem, at, step);
      for (long k = 0; k < std::lround(2.0 / step); ++k)
        ASSERT_TRUE(method->step(problem, at, step).ok);
      if (level > 0) differences[level - 1] = distance(at, previous);
      previous = at;
    }
    EXPECT_NEAR(std::log2(differences[0] / differences[1]), 2.0, 0.15);
  }
}

}  // namespace
}  // namespace constrained_kkt_test
}  // namespace geomint
