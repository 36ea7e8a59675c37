// Unit tests for the Newton solver and the basic one-step methods (Euler family, symplectic Euler,
// Störmer–Verlet, RK4): hand-computed steps and the exact discrete invariants of docs/METHOD.md §7
// on local test problems, work counters, failure statuses and factory validation.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>

#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "problems/mass_operator.hpp"
#include "problems/structures/charged_particle.hpp"
#include "problems/structures/free_rigid_body.hpp"

namespace geomint {
namespace integrators_test {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

SparseMatrix sparse_from(const Eigen::MatrixXd& dense) { return dense.sparseView(); }

// ---------------------------------------------------------------------------------------------
// Local test problems (independent of problems/ so these tests pin the methods alone).

// H = p²/2m + k q²/2 with an optional linear damping force F = −c v.
class Oscillator final : public Problem, public NonConservativeForce {
 public:
  struct Options {
    double mass = 1.0;
    double stiffness = 1.0;
    double damping = 0.0;
    bool damping_jacobian = true;  // offer force_jacobian_v (kForceJacobian) when damped
    double q0 = 1.0;
    double p0 = 0.5;
  };
  explicit Oscillator(const Options& options) : options_(options) {
    set_mass(Vec::Constant(1, options.mass));
    set_capabilities(kHessian);
  }
  State initial_state() const override {
    return {0.0, Vec::Constant(1, options_.q0), Vec::Constant(1, options_.p0)};
  }
  double potential(const Vec& q) const override {
    return 0.5 * options_.stiffness * q.squaredNorm();
  }
  void gradient(const Vec& q, Vec& g) const override { g = options_.stiffness * q; }
  void hessian(const Vec&, SparseMatrix& H) const override {
    H = sparse_from(Eigen::MatrixXd::Constant(1, 1, options_.stiffness));
  }
  const NonConservativeForce* as_forced() const override {
    return options_.damping != 0.0 ? this : nullptr;
  }
  bool has_force_jacobian() const override { return options_.damping_jacobian; }
  void force(const Vec&, const Vec& v, double, Vec& f) const override { f = -options_.damping * v; }
  void force_jacobian_v(const Vec&, const Vec&, double, SparseMatrix& C) const override {
    C = sparse_from(Eigen::MatrixXd::Constant(1, 1, options_.damping));
  }

 private:
  Options options_;
};

// Two unequal masses in quartic wells joined by a linear spring:
// V = (k/4)(q₀⁴ + q₁⁴) + ½(q₀ − q₁)², M = diag(2, 0.5). Nonlinear, non-unit masses.
class QuarticPair final : public Problem {
 public:
  explicit QuarticPair(double k, Vec q0 = Vec::Zero(0)) : k_(k), q0_(std::move(q0)) {
    Vec mass(2);
    mass << 2.0, 0.5;
    set_mass(mass);
    set_capabilities(kHessian);
    if (q0_.size() == 0) {
      q0_.resize(2);
      q0_ << 1.0, -0.5;
    }
  }
  State initial_state() const override {
    Vec p(2);
    p << 0.3, -0.2;
    return {0.0, q0_, p};
  }
  double potential(const Vec& q) const override {
    return 0.25 * k_ * q.array().pow(4).sum() + 0.5 * std::pow(q[0] - q[1], 2);
  }
  void gradient(const Vec& q, Vec& g) const override {
    g = k_ * q.array().cube().matrix();
    g[0] += q[0] - q[1];
    g[1] -= q[0] - q[1];
  }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    Eigen::Matrix2d dense;
    dense << 3 * k_ * q[0] * q[0] + 1, -1, -1, 3 * k_ * q[1] * q[1] + 1;
    H = sparse_from(dense);
  }

 private:
  double k_;
  Vec q0_;
};

double oscillator_energy(const State& s, double omega) {
  return 0.5 * s.p[0] * s.p[0] + 0.5 * omega * omega * s.q[0] * s.q[0];
}

// Runs `steps` steps from the problem's initial state, asserting each succeeds.
State run(Integrator& integrator, const Problem& problem, double h, int steps) {
  State state = problem.initial_state();
  integrator.reset(problem, state, h);
  for (int k = 0; k < steps; ++k) {
    const StepStatus status = integrator.step(problem, state, h);
    EXPECT_TRUE(status.ok) << status.reason << ": " << status.message;
    if (!status.ok) break;
  }
  return state;
}

// ---------------------------------------------------------------------------------------------
// NewtonSolver

// R(x) = (x₀² + x₁² − 4, eˣ⁰ + x₁ − 1): a circle meeting an exponential; Jacobian not symmetric.
NewtonSystem circle_exponential() {
  NewtonSystem system;
  system.residual = [](const Vec& x, Vec& r) {
    r.resize(2);
    r << x[0] * x[0] + x[1] * x[1] - 4, std::exp(x[0]) + x[1] - 1;
  };
  system.jacobian = [](const Vec& x, SparseMatrix& J) {
    Eigen::Matrix2d dense;
    dense << 2 * x[0], 2 * x[1], std::exp(x[0]), 1;
    J = sparse_from(dense);
  };
  return system;
}

// ∇E for the convex E(x) = Σ cosh(xᵢ) + ½ xᵀ A x − bᵀx (A tridiagonal): symmetric Jacobian.
NewtonSystem convex_gradient(int n) {
  NewtonSystem system;
  system.symmetric = true;
  auto tridiagonal = [n](Vec& out, const Vec& x) {
    out = 2 * x;
    out.head(n - 1) -= x.tail(n - 1);
    out.tail(n - 1) -= x.head(n - 1);
  };
  system.residual = [=](const Vec& x, Vec& r) {
    tridiagonal(r, x);
    r += x.array().sinh().matrix() - Vec::LinSpaced(n, 1.0, 3.0);
  };
  system.jacobian = [=](const Vec& x, SparseMatrix& J) {
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < n; ++i) {
      t.emplace_back(i, i, 2 + std::cosh(x[i]));
      if (i + 1 < n) {
        t.emplace_back(i, i + 1, -1.0);
        t.emplace_back(i + 1, i, -1.0);
      }
    }
    J.resize(n, n);
    J.setFromTriplets(t.begin(), t.end());
  };
  return system;
}

// robust_norm: the same bits as Eigen's norm() where squaring stays in range, the right value
// (to a few ulps) where it does not, and finite for subnormal entries.
TEST(RobustNorm, MatchesNormInRangeAndStaysRightOutsideIt) {
  Vec v(5);
  v << 0.3, -1.7, 2.5e-3, 4.0, -0.01;
  for (double scale : {1.0, 3e-7, 1e12, 1e-140, 1e140}) {
    const Vec scaled = scale * v;
    EXPECT_EQ(robust_norm(scaled), scaled.norm()) << scale;  // bit for bit
  }
  const double exact = v.norm();
  for (double scale : {1e-170, 1e-250, 1e-300, 1e170, 1e250, 1e300}) {
    const double norm = robust_norm(scale * v);
    EXPECT_NEAR(norm / scale, exact, 4 * std::numeric_limits<double>::epsilon() * exact) << scale;
  }
  EXPECT_EQ((1e-170 * v).norm(), 0.0);  // why robust_norm exists
  EXPECT_TRUE(std::isinf((1e170 * v).norm()));
  const double tiny = std::numeric_limits<double>::denorm_min();
  Vec subnormal(2);
  subnormal << 3 * tiny, 4 * tiny;
  EXPECT_EQ(robust_norm(subnormal), 5 * tiny);
  EXPECT_EQ(robust_norm(Vec::Zero(3)), 0.0);
  EXPECT_EQ(robust_norm(Vec()), 0.0);
  Vec with_nan = v;
  with_nan[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(robust_norm(with_nan)));
  EXPECT_EQ(power_of_two_unit(3.0), 0.5);
  EXPECT_EQ(power_of_two_unit(0.0), 1.0);
  EXPECT_TRUE(std::isfinite(power_of_two_unit(tiny)));
}

TEST(NewtonSolver, ConvergesQuadraticallyWithSparseLU) {
  NewtonOptions options;
  options.record_history = true;
  NewtonSolver solver(options);
  Vec x(2);
  x << 1.0, -1.0;
  const NewtonResult result = solver.solve(circle_exponential(), x, 4.0);
  ASSERT_TRUE(result.converged) << describe(result);
  EXPECT_EQ(result.reason, "");
  EXPECT_LE(result.iterations, 8);
  EXPECT_EQ(result.linear_solves, result.iterations);
  Vec r;
  circle_exponential().residual(x, r);
  EXPECT_LE(r.norm(), 4e-12);
  // Quadratic: r_{k+1} ≤ C r_k² once in the asymptotic range and above the round-off floor.
  int quadratic_pairs = 0;
  const auto& history = result.residual_history;
  ASSERT_EQ(history.size(), static_cast<size_t>(result.iterations + 1));
  for (size_t k = 0; k + 1 < history.size(); ++k) {
    if (history[k] < 1e-1 && history[k + 1] > 1e3 * kEps) {
      EXPECT_LE(history[k + 1], 10 * history[k] * history[k]) << "iteration " << k;
      ++quadratic_pairs;
    }
  }
  EXPECT_GE(quadratic_pairs, 2) << "too few iterations to observe the rate";
}

TEST(NewtonSolver, SymmetricLdltMatchesLuAndConvergesQuadratically) {
  NewtonOptions options;
  options.record_history = true;
  const int n = 6;
  Vec x_ldlt = Vec::Constant(n, 3.0);
  const NewtonResult ldlt = NewtonSolver(options).solve(convex_gradient(n), x_ldlt, 3.0);
  NewtonSystem as_general = convex_gradient(n);
  as_general.symmetric = false;
  Vec x_lu = Vec::Constant(n, 3.0);
  const NewtonResult lu = NewtonSolver(options).solve(as_general, x_lu, 3.0);
  ASSERT_TRUE(ldlt.converged) << describe(ldlt);
  ASSERT_TRUE(lu.converged) << describe(lu);
  EXPECT_LE((x_ldlt - x_lu).norm(), 1e-12);
  const auto& history = ldlt.residual_history;
  ASSERT_GE(history.size(), 3u);
  const double last = history[history.size() - 1], before = history[history.size() - 2];
  EXPECT_LE(last, 10 * before * before + 1e3 * kEps);
}

TEST(NewtonSolver, SingularJacobianFailsWithLinearSolveFailed) {
  // R(x) = x² + 1 has no real root; from x = 1 the full Newton step lands on x = 0, J = 0.
  for (bool symmetric : {true, false}) {
    NewtonSystem system;
    system.symmetric = symmetric;
    system.residual = [](const Vec& x, Vec& r) { r = (x.array().square() + 1).matrix(); };
    system.jacobian = [](const Vec& x, SparseMatrix& J) {
      J = sparse_from(Eigen::MatrixXd::Constant(1, 1, 2 * x[0]));
    };
    Vec x = Vec::Constant(1, 1.0);
    const NewtonResult result = NewtonSolver().solve(system, x, 1.0);
    EXPECT_FALSE(result.converged);
    EXPECT_EQ(result.reason, "linear_solve_failed") << "symmetric=" << symmetric;
    EXPECT_EQ(x[0], 0.0);
    EXPECT_NEAR(result.residual_norm, 1.0, 1e-15);
  }
}

TEST(NewtonSolver, MaxIterationsOneGivesNewtonMaxIter) {
  NewtonOptions options;
  options.max_iterations = 1;
  Vec x(2);
  x << 1.0, -1.0;
  const NewtonResult result = NewtonSolver(options).solve(circle_exponential(), x, 4.0);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.reason, "newton_max_iter");
  EXPECT_EQ(result.iterations, 1);
  EXPECT_GT(result.residual_norm, result.threshold);
  EXPECT_NE(describe(result).find("newton_max_iter"), std::string::npos);
}

// The stopping contract, observed where quadratic convergence would hide a loose test: with a
// Jacobian twice too large the iteration contracts the residual by exactly ½ per update, so it
// passes through every decade above the threshold. The solver must stop at the first residual
// at or below result.threshold — not earlier (a looser test), not later — and without polishing
// the reported residual is that iterate's.
TEST(NewtonSolver, StopsAtTheFirstResidualBelowItsThreshold) {
  NewtonSystem system;
  system.symmetric = true;
  system.residual = [](const Vec& x, Vec& r) { r = x; };
  system.jacobian = [](const Vec& x, SparseMatrix& J) {
    J = sparse_from(Eigen::MatrixXd::Identity(x.size(), x.size()) * 2.0);
  };
  NewtonOptions options;
  options.line_search = false;
  options.record_history = true;
  options.max_iterations = 200;
  for (const double start : {1.0, 1e3, 1e-3}) {
    Vec x = Vec::Constant(3, start);
    const NewtonResult result = NewtonSolver(options).solve(system, x, 1.0);
    ASSERT_TRUE(result.converged) << describe(result);
    const auto& history = result.residual_history;
    ASSERT_EQ(history.size(), static_cast<size_t>(result.iterations + 1));
    EXPECT_LE(result.residual_norm, result.threshold) << "start " << start;
    EXPECT_EQ(result.residual_norm, history.back());
    for (size_t k = 0; k + 1 < history.size(); ++k) {
      EXPECT_GT(history[k], result.threshold) << "start " << start << ": stopped late at " << k;
    }
    // ½ per update: the first residual below the threshold is within a factor 2 of it.
    EXPECT_GT(result.residual_norm, 0.5 * result.threshold * (1 - 1e-12)) << "start " << start;
  }
}

TEST(NewtonSolver, NonFiniteResidualIsNan) {
  NewtonSystem system;
  system.residual = [](const Vec& x, Vec& r) { r = (x.array().log() - 1).matrix(); };
  system.jacobian = [](const Vec& x, SparseMatrix& J) {
    J = sparse_from(Eigen::MatrixXd::Constant(1, 1, 1 / x[0]));
  };
  Vec outside = Vec::Constant(1, -1.0);
  EXPECT_EQ(NewtonSolver().solve(system, outside, 1.0).reason, "nan");

  // From x = 10 the full step lands at x < 0: the line search shortens it instead of failing,
  // while plain Newton reports the NaN.
  Vec x = Vec::Constant(1, 10.0);
  const NewtonResult damped = NewtonSolver().solve(system, x, 1.0);
  ASSERT_TRUE(damped.converged) << describe(damped);
  EXPECT_NEAR(x[0], std::exp(1.0), 1e-11);
  NewtonOptions plain;
  plain.line_search = false;
  x = Vec::Constant(1, 10.0);
  EXPECT_EQ(NewtonSolver(plain).solve(system, x, 1.0).reason, "nan");
}

TEST(NewtonSolver, ReusesSymbolicFactorisationWhilePatternIsUnchanged) {
  const NewtonSystem system = convex_gradient(5);
  NewtonSolver solver;
  Vec x = Vec::Constant(5, 2.0);
  EXPECT_EQ(solver.solve(system, x, 3.0).symbolic_analyses, 1);
  x = Vec::Constant(5, -2.0);
  const NewtonResult reused = solver.solve(system, x, 3.0);
  EXPECT_TRUE(reused.converged);
  EXPECT_GT(reused.iterations, 1);
  EXPECT_EQ(reused.symbolic_analyses, 0);
  solver.forget_pattern();
  x = Vec::Constant(5, 2.0);
  EXPECT_EQ(solver.solve(system, x, 3.0).symbolic_analyses, 1);

  NewtonOptions no_reuse;
  no_reuse.reuse_symbolic = false;
  NewtonSolver fresh(no_reuse);
  x = Vec::Constant(5, 2.0);
  const NewtonResult each = fresh.solve(system, x, 3.0);
  EXPECT_EQ(each.symbolic_analyses, each.linear_solves);
}

TEST(NewtonSolver, ObjectiveLineSearchGlobalisesMinimisation) {
  // E(x) = √(1 + x²): plain Newton on E' maps x to −x³ and diverges from |x| > 1.
  NewtonSystem system;
  system.symmetric = true;
  // hypot keeps the diverging iterates from overflowing into a spurious zero residual.
  system.objective = [](const Vec& x) { return std::hypot(1.0, x[0]); };
  system.residual = [](const Vec& x, Vec& r) {
    r = Vec::Constant(1, x[0] / std::hypot(1.0, x[0]));
  };
  system.jacobian = [](const Vec& x, SparseMatrix& J) {
    J = sparse_from(Eigen::MatrixXd::Constant(1, 1, std::pow(std::hypot(1.0, x[0]), -3)));
  };
  Vec x = Vec::Constant(1, 2.0);
  const NewtonResult damped = NewtonSolver().solve(system, x, 1.0);
  ASSERT_TRUE(damped.converged) << describe(damped);
  EXPECT_LE(std::abs(x[0]), 1e-12);
  NewtonOptions plain;
  plain.line_search = false;
  x = Vec::Constant(1, 2.0);
  EXPECT_FALSE(NewtonSolver(plain).solve(system, x, 1.0).converged);

  // E(x) = −cos x at x = 2 has E'' < 0: the Newton step climbs, which the solver refuses.
  NewtonSystem concave;
  concave.symmetric = true;
  concave.objective = [](const Vec& y) { return -std::cos(y[0]); };
  concave.residual = [](const Vec& y, Vec& r) { r = Vec::Constant(1, std::sin(y[0])); };
  concave.jacobian = [](const Vec& y, SparseMatrix& J) {
    J = sparse_from(Eigen::MatrixXd::Constant(1, 1, std::cos(y[0])));
  };
  x = Vec::Constant(1, 2.0);
  EXPECT_EQ(NewtonSolver().solve(concave, x, 1.0).reason, "not_descent");
}

// ---------------------------------------------------------------------------------------------
// One step against hand-computed formulas on H = p²/2m + kq²/2 with F = −c v.

struct Step {
  double q, p;
};

std::map<std::string, std::function<Step(double, double, double, double, double, double)>>
hand_steps() {
  // Arguments: m, k, c, q, p, h.
  return {
      {"explicit_euler",
       [](double m, double k, double c, double q, double p, double h) {
         return Step{q + h * p / m, p + h * (-k * q - c * p / m)};
       }},
      {"implicit_euler",
       [](double m, double k, double c, double q, double p, double h) {
         const double v = (p - h * k * q) / (m + h * c + h * h * k);
         return Step{q + h * v, m * v};
       }},
      {"symplectic_euler_a",
       [](double m, double k, double c, double q, double p, double h) {
         const double p1 = p + h * (-k * q - c * p / m);
         return Step{q + h * p1 / m, p1};
       }},
      {"symplectic_euler_b",
       [](double m, double k, double c, double q, double p, double h) {
         const double q1 = q + h * p / m;
         return Step{q1, p + h * (-k * q1 - c * p / m)};
       }},
      {"stormer_verlet",
       [](double m, double k, double c, double q, double p, double h) {
         // The last half-kick takes the damping at the new velocity (implicit, second order):
         // p⁺ = p½ + (h/2)(−k q⁺ − c p⁺/m).
         const double p_half = p + (h / 2) * (-k * q - c * p / m);
         const double q1 = q + h * p_half / m;
         return Step{q1, (p_half - (h / 2) * k * q1) / (1 + h * c / (2 * m))};
       }},
      {"rk4",
       [](double m, double k, double c, double q, double p, double h) {
         // Linear system y' = A y: RK4 is the degree-4 Taylor polynomial of exp(hA).
         Eigen::Matrix2d A;
         A << 0, 1 / m, -k, -c / m;
         const Eigen::Matrix2d hA = h * A;
         const Eigen::Matrix2d phi = Eigen::Matrix2d::Identity() + hA + hA * hA / 2 +
                                     hA * hA * hA / 6 + hA * hA * hA * hA / 24;
         const Eigen::Vector2d y = phi * Eigen::Vector2d(q, p);
         return Step{y[0], y[1]};
       }},
  };
}

TEST(OneStep, MatchesHandFormulaUndampedDampedAndFiniteDifferenceJacobian) {
  struct Case {
    const char* label;
    Oscillator::Options options;
  };
  const Case cases[] = {
      {"undamped", {.mass = 2.0, .stiffness = 3.0, .q0 = 0.7, .p0 = -0.4}},
      {"damped", {.mass = 2.0, .stiffness = 3.0, .damping = 0.8, .q0 = 0.7, .p0 = -0.4}},
      {"damped_no_jacobian",
       {.mass = 2.0,
        .stiffness = 3.0,
        .damping = 0.8,
        .damping_jacobian = false,
        .q0 = 0.7,
        .p0 = -0.4}},
  };
  const double h = 0.1;
  for (const auto& [name, formula] : hand_steps()) {
    for (const Case& c : cases) {
      SCOPED_TRACE(std::string(name) + " " + c.label);
      const Oscillator problem(c.options);
      auto integrator = make_integrator(name);
      State state = run(*integrator, problem, h, 1);
      const auto& o = c.options;
      const Step expected = formula(o.mass, o.stiffness, o.damping, o.q0, o.p0, h);
      // Exact Jacobians solve a linear step in one Newton update, to round-off; the
      // finite-difference Jacobian leaves a residual within the Newton tolerance (1e-12).
      const bool newton_limited = name == "implicit_euler" && !o.damping_jacobian;
      const double tolerance = newton_limited ? 1e-12 : 4 * kEps;
      EXPECT_NEAR(state.q[0], expected.q, tolerance);
      EXPECT_NEAR(state.p[0], expected.p, tolerance);
      EXPECT_DOUBLE_EQ(state.t, h);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Exact discrete energy laws on H = ½p² + ½ω²q² (docs/METHOD.md §7, Ω = hω).

TEST(EnergyLaw, ExplicitEulerMultipliesByOnePlusOmegaSquared) {
  const double omega = 2.0, h = 0.05;
  const Oscillator problem({.stiffness = omega * omega});
  auto integrator = make_integrator("explicit_euler");
  const State state = run(*integrator, problem, h, 100);
  const double growth = std::pow(1 + h * h * omega * omega, 100);
  const double e0 = oscillator_energy(problem.initial_state(), omega);
  EXPECT_NEAR(oscillator_energy(state, omega) / (e0 * growth), 1.0, 1e-13);
  EXPECT_GT(growth, 1.4);  // the law is visible, not lost in the tolerance
}

TEST(EnergyLaw, ImplicitEulerDividesByOnePlusOmegaSquared) {
  const double omega = 2.0, h = 0.05;
  const Oscillator problem({.stiffness = omega * omega});
  auto integrator = make_integrator("implicit_euler");
  const State state = run(*integrator, problem, h, 100);
  const double decay = std::pow(1 + h * h * omega * omega, -100);
  const double e0 = oscillator_energy(problem.initial_state(), omega);
  EXPECT_NEAR(oscillator_energy(state, omega) / (e0 * decay), 1.0, 1e-13);
}

// The same law far into the decay, stiff and with a non-unit mass: hω = 10 over 100 steps takes
// the energy down by 101^100 = 1e200. Every step must still be solved relative to the state; a
// Newton test with an absolute floor stops iterating once ‖p‖ < tol (after about 2 steps here)
// and the state stalls near 1e-15 instead.
TEST(EnergyLaw, ImplicitEulerKeepsDecayingAtEveryScale) {
  const double mass = 0.25, omega = 100.0, h = 0.1;
  const Oscillator problem({.mass = mass, .stiffness = mass * omega * omega, .p0 = 0.0});
  auto integrator = make_integrator("implicit_euler");
  State state = problem.initial_state();
  integrator->reset(problem, state, h);
  const auto energy = [&](const State& s) {
    return 0.5 * s.p[0] * s.p[0] / mass + 0.5 * mass * omega * omega * s.q[0] * s.q[0];
  };
  const double e0 = energy(state);
  for (int k = 1; k <= 100; ++k) {
    ASSERT_TRUE(integrator->step(problem, state, h).ok) << "step " << k;
    const double expected = e0 * std::pow(1 + h * h * omega * omega, -k);
    // Newton's relative tolerance 1e-12 per step, accumulated over k steps.
    ASSERT_NEAR(energy(state) / expected, 1.0, 1e-10) << "step " << k;
  }
}

// max over steps of |I(q_k, p_k) − I(q_0, p_0)| / |I(q_0, p_0)|.
double invariant_error(const std::string& method, double omega, double h, int steps,
                       const std::function<double(double q, double p)>& invariant) {
  const Oscillator problem({.stiffness = omega * omega});
  auto integrator = make_integrator(method);
  State state = problem.initial_state();
  integrator->reset(problem, state, h);
  const double i0 = invariant(state.q[0], state.p[0]);
  double worst = 0.0;
  for (int k = 0; k < steps; ++k) {
    EXPECT_TRUE(integrator->step(problem, state, h).ok);
    worst = std::max(worst, std::abs(invariant(state.q[0], state.p[0]) - i0) / std::abs(i0));
  }
  return worst;
}

TEST(EnergyLaw, StormerVerletConservesModifiedEnergy) {
  const double omega = 2.0, h = 0.1, w2 = omega * omega;
  auto modified = [&](double q, double p) {
    return 0.5 * p * p + 0.5 * w2 * q * q * (1 - h * h * w2 / 4);
  };
  auto plain = [&](double q, double p) { return 0.5 * p * p + 0.5 * w2 * q * q; };
  // Round-off only: a random walk of ~√N·ε per step over N = 10⁴ steps, with margin.
  EXPECT_LE(invariant_error("stormer_verlet", omega, h, 10000, modified), 1e-12);
  // The plain energy oscillates at O(Ω²), so the check above discriminates.
  EXPECT_GT(invariant_error("stormer_verlet", omega, h, 10000, plain), 1e-3);
}

// Kick first: q' = (1 − Ω²)q + hp, p' = p − hω²q. Expanding ½p'² + ½ω²q'² + c q'p', the p²
// coefficient is ½ + ½h²ω² + ch, so c = −hω²/2; the q² and qp coefficients then close exactly.
// Drift first is the adjoint (h → −h with the roles swapped): c = +hω²/2.
TEST(EnergyLaw, SymplecticEulerConservesItsModifiedEnergy) {
  const double omega = 2.0, h = 0.05, w2 = omega * omega;
  auto with_sign = [&](double sign) {
    return [=](double q, double p) {
      return 0.5 * p * p + 0.5 * w2 * q * q + sign * h / 2 * w2 * q * p;
    };
  };
  EXPECT_LE(invariant_error("symplectic_euler_a", omega, h, 10000, with_sign(-1)), 1e-12);
  EXPECT_GT(invariant_error("symplectic_euler_a", omega, h, 10000, with_sign(+1)), 1e-2);
  EXPECT_LE(invariant_error("symplectic_euler_b", omega, h, 10000, with_sign(+1)), 1e-12);
  EXPECT_GT(invariant_error("symplectic_euler_b", omega, h, 10000, with_sign(-1)), 1e-2);
}

// ---------------------------------------------------------------------------------------------
// Counters, caches, failures.

TEST(Counters, StormerVerletUsesOneGradientPerStepAfterTheFirst) {
  const QuarticPair problem(1.0);
  auto integrator = make_integrator("stormer_verlet");
  run(*integrator, problem, 0.01, 100);
  EXPECT_EQ(integrator->counters().steps, 100);
  EXPECT_EQ(integrator->counters().force_evals, 101);
  // reset() starts the count (and the cache) afresh.
  run(*integrator, problem, 0.01, 10);
  EXPECT_EQ(integrator->counters().force_evals, 11);
}

TEST(Counters, StormerVerletIgnoresStaleGradientWhenStateIsEdited) {
  const QuarticPair problem(1.0);
  auto cached = make_integrator("stormer_verlet");
  State state = run(*cached, problem, 0.01, 3);
  state.q[0] += 0.25;  // e.g. a harness that perturbs or re-projects the state
  State expected = state;
  ASSERT_TRUE(cached->step(problem, state, 0.01).ok);
  auto fresh = make_integrator("stormer_verlet");
  fresh->reset(problem, expected, 0.01);
  ASSERT_TRUE(fresh->step(problem, expected, 0.01).ok);
  EXPECT_EQ(state.q, expected.q);
  EXPECT_EQ(state.p, expected.p);
}

TEST(Counters, StormerVerletIsReversible) {
  const QuarticPair problem(1.0);
  auto integrator = make_integrator("stormer_verlet");
  const State start = problem.initial_state();
  State state = start;
  integrator->reset(problem, state, 0.1);
  ASSERT_TRUE(integrator->step(problem, state, 0.1).ok);
  ASSERT_TRUE(integrator->step(problem, state, -0.1).ok);  // uses the cached gradient at q⁺
  EXPECT_LE((state.q - start.q).norm(), 8 * kEps);
  EXPECT_LE((state.p - start.p).norm(), 8 * kEps);
  // Two gradients for the first step, one (at the new q) for the second.
  EXPECT_EQ(integrator->counters().force_evals, 3);
}

TEST(Counters, ImplicitEulerReportsNewtonWorkAndSolvesTheStepEquation) {
  const QuarticPair problem(4.0);
  auto integrator = make_integrator("implicit_euler");
  const double h = 0.2;
  const State start = problem.initial_state();
  State state = start;
  integrator->reset(problem, state, h);
  ASSERT_TRUE(integrator->step(problem, state, h).ok);
  const Counters& counters = integrator->counters();
  EXPECT_EQ(counters.steps, 1);
  EXPECT_GT(counters.newton_iters, 1);  // nonlinear: more than one Newton update
  EXPECT_EQ(counters.linear_solves, counters.newton_iters);
  EXPECT_EQ(counters.hessian_evals, counters.newton_iters);
  // M(q⁺ − q)/h = p + h(−∇V(q⁺)) and p⁺ = M(q⁺ − q)/h.
  const Vec velocity = (state.q - start.q) / h;
  Vec gradient;
  problem.gradient(state.q, gradient);
  const Vec residual = MassOperator(problem).apply(state.q, velocity) - start.p + h * gradient;
  EXPECT_LE(residual.norm(), 1e-12 * (start.p.norm() + h * gradient.norm()) + 1e-13);
  EXPECT_LE((state.p - MassOperator(problem).apply(state.q, velocity)).norm(), 1e-13);
}

TEST(Failure, ImplicitEulerWithOneNewtonIterationFailsCleanly) {
  Vec q0(2);
  q0 << 3.0, -2.0;
  const QuarticPair problem(50.0, q0);
  auto integrator = make_integrator("implicit_euler:max_iter=1");
  State state = problem.initial_state();
  integrator->reset(problem, state, 1.0);
  StepStatus status;
  EXPECT_NO_THROW(status = integrator->step(problem, state, 1.0));
  EXPECT_FALSE(status.ok);
  EXPECT_EQ(status.reason, "newton_max_iter");
  EXPECT_NE(status.message.find("residual"), std::string::npos) << status.message;
  EXPECT_EQ(integrator->counters().steps, 0);
  EXPECT_EQ(integrator->counters().newton_iters, 1);

  // The same step converges when Newton may iterate: the failure is the iteration cap.
  auto patient = make_integrator("implicit_euler");
  state = problem.initial_state();
  patient->reset(problem, state, 1.0);
  const StepStatus ok = patient->step(problem, state, 1.0);
  EXPECT_TRUE(ok.ok) << ok.message;
}

// ---------------------------------------------------------------------------------------------
// Convergence order on the nonlinear QuarticPair, by step doubling: e(h) = ‖y_h − y_{h/2}‖.

TEST(Order, EachMethodShowsItsDeclaredOrder) {
  const QuarticPair problem(1.0);
  const double t_end = 1.0;
  for (const std::string name : {"explicit_euler", "implicit_euler", "symplectic_euler_a",
                                 "symplectic_euler_b", "stormer_verlet", "rk4"}) {
    SCOPED_TRACE(name);
    auto integrator = make_integrator(name);
    auto final_state = [&](int steps) {
      const State s = run(*integrator, problem, t_end / steps, steps);
      Vec y(4);
      y << s.q, s.p;
      return y;
    };
    const int base = 40;
    const Vec y1 = final_state(base), y2 = final_state(2 * base), y4 = final_state(4 * base);
    const double order = std::log2((y1 - y2).norm() / (y2 - y4).norm());
    EXPECT_NEAR(order, integrator->info().order, 0.3);
  }
}

// ---------------------------------------------------------------------------------------------
// Factories and registry.

TEST(Factory, RejectsBadParametersByName) {
  try {
    make_integrator("implicit_euler:tol=-1");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tol"), std::string::npos) << e.what();
  }
  try {
    make_integrator("implicit_euler:tolerance=1e-9");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("tolerance"), std::string::npos) << what;
    EXPECT_NE(what.find("tol,"), std::string::npos) << what;
    EXPECT_NE(what.find("max_iter"), std::string::npos) << what;
  }
  EXPECT_THROW(make_integrator("implicit_euler:max_iter=0"), InputError);
  EXPECT_THROW(make_integrator("rk4:order=5"), InputError);
  EXPECT_EQ(make_integrator("implicit_euler")->spec(), "implicit_euler:max_iter=50,tol=1e-12");
  EXPECT_EQ(make_integrator("implicit_euler:tol=1e-10")->spec(),
            "implicit_euler:max_iter=50,tol=1e-10");
}

TEST(Registry, EveryEntryNamesItselfAndDeclaresAnOrder) {
  ASSERT_FALSE(integrator_registry().empty());
  for (const auto& entry : integrator_registry()) {
    SCOPED_TRACE(entry.name);
    const auto integrator = make_integrator(entry.name);
    const MethodInfo info = integrator->info();
    EXPECT_EQ(info.name, entry.name);
    EXPECT_GT(info.order, 0);
    EXPECT_FALSE(info.reference.empty());
    // Exactly one of explicit/implicit (adaptive library solvers may be either).
    EXPECT_NE((info.flags & kExplicit) != 0, (info.flags & kImplicit) != 0);
  }
}

// Every registered configuration gets a family from method_family(), one of the listed ones;
// every listed family is some method's (no dead label in the figures' legend); the anchors pin
// the classification of one method per family, so a swapped branch or flag test fails here.
TEST(Registry, EveryMethodHasAFamily) {
  std::set<std::string> reached;
  const auto& families = method_families();
  for (const auto& spec : integrator_test_specs()) {
    SCOPED_TRACE(spec);
    const auto method = make_integrator(spec);
    const std::string family = method_family(method->info(), method->provider());
    EXPECT_FALSE(family.empty());
    EXPECT_NE(std::find(families.begin(), families.end(), family), families.end()) << family;
    reached.insert(family);
  }
  for (const auto& family : families) EXPECT_TRUE(reached.count(family)) << family;
  const std::vector<std::pair<std::string, std::string>> anchors = {
      {"stormer_verlet", "explicit_symplectic"},
      {"odeint_mclachlan4", "explicit_symplectic"},
      {"composition:scheme=kahan_li8", "explicit_symplectic"},
      {"rk4", "explicit_rk"},
      {"hp", "implicit_variational"},
      {"implicit_euler", "implicit_other"},
      {"adaptive_verlet", "adaptive_geomint"},
      {"cvode_bdf", "adaptive_library"},
      {"gsl_rk8pd", "adaptive_library"},
      {"odeint_dopri5", "adaptive_library"}};
  for (const auto& [spec, family] : anchors) {
    const auto method = make_integrator(spec);
    EXPECT_EQ(method_family(method->info(), method->provider()), family) << spec;
  }
  EXPECT_THROW(method_family(MethodInfo{"flagless", 1, 0, "none"}, MethodProvider::geomint()),
               std::logic_error);
}

// The provider is data of the registry entry (integrators/registry.def), not a reading of the
// name: an adaptive method's family follows it whatever the method is called, every built-in
// entry names geomint or a library by name, and make_integrator and integrator_maker pass it on.
TEST(Registry, ProviderIsTheEntrysDataNotTheName) {
  const MethodInfo adaptive{"cvode_lookalike", 4, kExplicit | kAdaptive, "none"};
  EXPECT_EQ(method_family(adaptive, MethodProvider::geomint()), "adaptive_geomint");
  EXPECT_EQ(method_family(adaptive, MethodProvider::library_named("SUNDIALS")), "adaptive_library");
  const std::map<std::string, std::string> anchors = {{"cvode_bdf", "library:SUNDIALS"},
                                                      {"ida", "library:SUNDIALS"},
                                                      {"arkode_erk", "library:SUNDIALS"},
                                                      {"gsl_msbdf", "library:GSL"},
                                                      {"odeint_mclachlan4", "library:Boost.Odeint"},
                                                      {"adaptive_verlet", "geomint"},
                                                      {"rkn_adaptive", "geomint"},
                                                      {"exec", "user"},
                                                      {"mujoco", "engine:MuJoCo"},
                                                      {"ode", "engine:ODE"},
                                                      {"bullet", "engine:Bullet"}};
  for (const auto& entry : integrator_registry()) {
    if (!entry.builtin) continue;
    SCOPED_TRACE(entry.name);
    const MethodProvider& provider = method_provider(entry.name);
    // A built-in entry is geomint's, a named library's, or runs the user's own code (`exec`).
    EXPECT_TRUE(provider.kind == MethodProvider::Kind::kGeomint ||
                provider.kind == MethodProvider::Kind::kUser ||
                ((provider.kind == MethodProvider::Kind::kLibrary ||
                  provider.kind == MethodProvider::Kind::kEngine) &&
                 !provider.library.empty()));
    EXPECT_EQ(make_integrator(entry.name)->provider(), provider);
    EXPECT_EQ(integrator_maker(entry.name)()->provider(), provider);
    const auto anchor = anchors.find(entry.name);
    if (anchor != anchors.end()) {
      EXPECT_EQ(provider.label(), anchor->second);
    }
  }
  EXPECT_THROW(method_provider("no_such_method"), InputError);
  // One record of info, provider and needs; a structure need is the interface's key.
  const MethodRecord boris = method_record(*make_integrator("boris"));
  EXPECT_EQ(boris.info.name, "boris");
  EXPECT_EQ(boris.provider.label(), "geomint");
  EXPECT_EQ(boris.needs.structure, &ChargedParticleStructure::kStructureKey);
  EXPECT_EQ(method_record(*make_integrator("lie_poisson")).needs.structure,
            &FreeRigidBodyStructure::kStructureKey);
  EXPECT_EQ(method_record(*make_integrator("gsl_rk8pd")).provider.label(), "library:GSL");
}

}  // namespace
}  // namespace integrators_test
}  // namespace geomint
