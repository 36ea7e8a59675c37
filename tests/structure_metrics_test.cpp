// Optional structure metrics (harness/structure_metrics.*; docs/USAGE.md "Optional structure
// metrics"): the symplecticity defect of the linearised step at round-off for every
// declared-symplectic method and O(h^{p+1}) for non-symplectic ones, the period from zero
// crossings, the energy growth exponent.
#include "harness/structure_metrics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "harness/run_spec.hpp"

namespace geomint {
namespace structure_metrics_test {
namespace {

// Round-off: DΦ is the exact linearised step (Integrator::step_tangent), and for an implicit
// method it is the derivative of its step equations at the converged point, which is symplectic
// whatever the Newton tolerance left (integrators/tangent.hpp). Measured ≤ 4.4e-16 (docs/USAGE.md
// "Optional structure metrics"); non-symplectic methods must sit far above it.
constexpr double kDefectFloor = 1e-14;

double defect(const std::string& method, const std::string& problem_spec, double h) {
  const auto problem = make_problem(problem_spec);
  return symplecticity_defect(MethodFactory(method), *problem, problem->initial_state(), h);
}

RunRecord run_with(const std::string& problem, const std::string& method, double dt, double t_end,
                   const std::vector<std::string>& metrics) {
  RunConfig config;
  config.dt = dt;
  config.t_end = t_end;
  config.timing_repeats = 0;
  config.extra_metrics = metrics;
  return run_one(problem, method, config).record;
}

// Every declared-symplectic fixed-step method with a linearised step, on a two-degree-of-freedom
// nonlinear problem (in one degree of freedom symplectic only means area-preserving).
TEST(SymplecticityDefect, DeclaredSymplecticMethodsSitAtTheFloor) {
  const auto problem = make_problem("kepler");
  int checked = 0;
  for (const auto& spec : integrator_test_specs()) {
    const auto method = make_integrator(spec);
    if (!(method->info().flags & kSymplectic) || !applicable(*method, *problem).ok ||
        !symplecticity_defect_applies(*method, *problem)) {
      continue;
    }
    const double value =
        symplecticity_defect(MethodFactory(spec), *problem, problem->initial_state(), 0.05);
    std::printf("%-50s defect %.3g\n", spec.c_str(), value);
    EXPECT_LE(value, kDefectFloor) << spec;
    ++checked;
  }
  EXPECT_GE(checked, 10);
}

// Non-symplectic methods: far above the floor, and shrinking like a power of h fitted between h
// and h/2 on kepler:e=0.5. A map of order p that starts from the state alone differs from the
// exact, symplectic flow by O(h^{p+1}): explicit and implicit Euler and Newmark with γ = 0.6
// (p = 1) measure slope 2.0, trapezoidal Newmark (p = 2) 3.0, RK4 5.4 between h = 0.08 and
// 0.04 and 6.0 further down (5.97, 5.99, 6.00 from h = 0.04 to 0.005, a power above p + 1,
// which the difference quotient's floor hid). HHT and generalized-α measure 2.0 = p: their
// first step starts from the consistent acceleration, and its error is O(h²) (the start-up error
// that does not accumulate, so their global order stays 2; docs/USAGE.md "Optional structure
// metrics").
TEST(SymplecticityDefect, NonSymplecticMethodsAreAboveTheFloorAndScaleWithTheOrder) {
  struct Case {
    std::string spec;
    double h;
    double slope;  // least power of h expected
  };
  for (const Case& c : std::vector<Case>{{"explicit_euler", 0.02, 2},
                                         {"implicit_euler", 0.02, 2},
                                         {"newmark:beta=0.25,gamma=0.6", 0.02, 2},
                                         {"newmark", 0.02, 3},
                                         {"rk4", 0.08, 5},
                                         {"rk4", 0.02, 6},
                                         {"hht:alpha=-0.3", 0.02, 2},
                                         {"generalized_alpha:rho_inf=0.5", 0.02, 2}}) {
    const double coarse = defect(c.spec, "kepler:e=0.5", c.h);
    const double fine = defect(c.spec, "kepler:e=0.5", c.h / 2);
    const double slope = std::log2(coarse / fine);
    std::printf("%-32s defect(h=%g) %.3g defect(h=%g) %.3g slope %.2f\n", c.spec.c_str(), c.h,
                coarse, c.h / 2, fine, slope);
    EXPECT_GT(fine, 1e4 * kDefectFloor) << c.spec;
    EXPECT_GT(slope, c.slope - 0.25) << c.spec;
  }
}

// A linear problem with non-unit masses: the symplectic methods' defect is round-off there too.
TEST(SymplecticityDefect, LinearProblemIsAtRoundOffForSymplecticMethods) {
  for (const std::string spec : {"stormer_verlet", "implicit_midpoint", "gauss:s=2"}) {
    EXPECT_LE(defect(spec, "spring_chain:n=3,mass=0.7", 0.1), kDefectFloor) << spec;
  }
  EXPECT_GT(defect("rk4", "spring_chain:n=3,mass=0.7", 0.5), 1e-6);
}

// No linearised step, no defect: the library and adaptive solvers and forced problems report
// the column empty (the metric is absent), with the reason symplecticity_defect_not_applicable
// gives, instead of a difference quotient.
TEST(SymplecticityDefect, IsNotApplicableWithoutALinearisedStep) {
  const auto kepler = make_problem("kepler");
  for (const std::string spec : {"odeint_velocity_verlet", "adaptive_verlet", "cvode_bdf"}) {
    EXPECT_NE(symplecticity_defect_not_applicable(*make_integrator(spec), *kepler), "") << spec;
    EXPECT_TRUE(std::isnan(
        symplecticity_defect(MethodFactory(spec), *kepler, kepler->initial_state(), 0.05)));
  }
  EXPECT_NE(symplecticity_defect_not_applicable(*make_integrator("stormer_verlet"),
                                                *make_problem("damped_oscillator")),
            "");
  EXPECT_EQ(symplecticity_defect_not_applicable(*make_integrator("stormer_verlet"), *kepler), "");
  EXPECT_FALSE(run_with("kepler", "odeint_velocity_verlet", 0.05, 1, {"symplecticity_defect"})
                   .metrics.count("symplecticity_defect"));
}

TEST(SymplecticityDefect, UnknownMetricNameIsAnInputError) {
  EXPECT_THROW(check_optional_metrics({"symplecticity"}, "--metric"), InputError);
  EXPECT_NO_THROW(check_optional_metrics(optional_metric_names(), "--metric"));
}

// Normal modes of the discrete map against the closed forms on a linear chain of 0.7 masses with
// fixed ends (GNI §I.5, §XIII.2): Störmer–Verlet's step matrix has trace 2 − (hω)², so
// cos hω̃ = 1 − (hω)²/2, ω̃ = (2/h) arcsin(hω/2); the implicit midpoint rule's eigenvalues are
// (1 + ihω/2)/(1 − ihω/2), ω̃ = (2/h) arctan(hω/2); both with ρ = 1. Explicit Euler's are
// 1 ± ihω: ρ = √(1 + h²ω²), ω̃ = arctan(hω)/h.
TEST(NormalModes, DiscreteFrequenciesFollowTheClosedForms) {
  const auto chain = make_problem("spring_chain:n=5,mass=0.7,stiffness=1.3,ends=free");
  const double h = 0.5;
  struct Case {
    std::string spec;
    double (*frequency)(double h, double omega);
    double (*amplitude)(double h, double omega);
  };
  const std::vector<Case> cases = {
      {"stormer_verlet", [](double h, double w) { return 2 / h * std::asin(h * w / 2); },
       [](double, double) { return 1.0; }},
      {"implicit_midpoint", [](double h, double w) { return 2 / h * std::atan(h * w / 2); },
       [](double, double) { return 1.0; }},
      {"explicit_euler", [](double h, double w) { return std::atan(h * w) / h; },
       [](double h, double w) { return std::sqrt(1 + h * h * w * w); }}};
  for (const Case& c : cases) {
    const std::vector<DiscreteMode> modes = discrete_normal_modes(MethodFactory(c.spec), *chain, h);
    ASSERT_EQ(modes.size(), 5u) << c.spec;
    EXPECT_LE(modes.front().omega, 1e-7) << "the free chain's translation";
    for (const DiscreteMode& mode : modes) {
      std::printf("%-18s omega %.6f discrete %.12f rho %.15f\n", c.spec.c_str(), mode.omega,
                  mode.omega_discrete, mode.amplitude);
      EXPECT_NEAR(mode.omega_discrete, c.frequency(h, mode.omega), 1e-13) << c.spec;
      EXPECT_NEAR(mode.amplitude, c.amplitude(h, mode.omega), 1e-13) << c.spec;
    }
  }
}

// Full relative precision for the slow modes of a long chain: the dense eigensolver leaves λ_j
// an absolute error of about ε λ_max, (ω_max/ω_1)² ≈ 1.6e4 times ω_1² here, and ω̃ taken from
// the trace of DΦ loses another 1/(hω)². 199 masses of 0.7 on springs of 1.3, fixed ends
// (ω_j = 2√(k/m) sin(jπ/(2(n + 1))), j = 1..n), fixed–free (2√(k/m) sin((2j − 1)π/(2(2n + 1))),
// j = 1..n) and free ends (2√(k/m) sin(jπ/(2n)), j = 0..n−1, j = 0 the translation);
// Störmer–Verlet's sin(hω̃/2) = hω/2 and the implicit
// midpoint rule's tan(hω̃/2) = hω/2, all evaluated in long double from the same double k and m
// the problem holds. A few ulps relative, every mode.
TEST(NormalModes, SlowModesOfALongChainToFullRelativePrecision) {
  constexpr int kMasses = 199;
  constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  const double mass = 0.7, stiffness = 1.3, h = 0.5;
  const long double scale =
      2 * std::sqrt(static_cast<long double>(stiffness) / static_cast<long double>(mass));
  const long double pi = 3.141592653589793238462643383279502884L;
  for (const std::string ends : {"fixed", "fixed_free", "free"}) {
    const bool fixed = ends != "free";
    const auto chain = make_problem("spring_chain:n=199,mass=0.7,stiffness=1.3,ends=" + ends);
    for (const std::string method : {"stormer_verlet", "implicit_midpoint"}) {
      const std::vector<DiscreteMode> modes =
          discrete_normal_modes(MethodFactory(method), *chain, h);
      ASSERT_EQ(modes.size(), static_cast<size_t>(kMasses)) << method;
      double worst_omega = 0, worst_discrete = 0;
      for (int i = 0; i < kMasses; ++i) {
        const int j = fixed ? i + 1 : i;
        const DiscreteMode& mode = modes[i];
        if (j == 0) {  // the free chain's translation: ω = 0 to rounding, no relative error
          EXPECT_LE(mode.omega, 1e-7) << method;
          continue;
        }
        const long double omega =
            ends == "fixed_free" ? scale * std::sin((2 * j - 1) * pi / (2 * (2 * kMasses + 1)))
                                 : scale * std::sin(j * pi / (2 * (fixed ? kMasses + 1 : kMasses)));
        const long double half_angle = h * omega / 2;
        const long double discrete =
            2 / static_cast<long double>(h) *
            (method == "stormer_verlet" ? std::asin(half_angle) : std::atan(half_angle));
        const double omega_error = static_cast<double>(std::abs((mode.omega - omega) / omega));
        const double discrete_error =
            static_cast<double>(std::abs((mode.omega_discrete - discrete) / discrete));
        worst_omega = std::max(worst_omega, omega_error);
        worst_discrete = std::max(worst_discrete, discrete_error);
        EXPECT_LE(omega_error, 4 * kEpsilon) << method << " mode " << j;
        EXPECT_LE(discrete_error, 4 * kEpsilon) << method << " mode " << j;
        EXPECT_NEAR(mode.amplitude, 1.0, 4 * kEpsilon) << method << " mode " << j;
      }
      std::printf(
          "%-17s %s ends: lowest omega %.17g; largest relative error omega %.2e, "
          "discrete %.2e\n",
          method.c_str(), ends.c_str(), modes[fixed ? 0 : 1].omega, worst_omega, worst_discrete);
    }
  }
}

// The columns: Störmer–Verlet's largest relative frequency error on the harmonic oscillator is
// (2/(hω)) arcsin(hω/2) − 1 ≈ (hω)²/24, reported only for linear problems and when asked for.
TEST(NormalModes, MetricsAreReportedForLinearProblemsOnly) {
  const RunRecord harmonic = run_with("harmonic:omega=3", "stormer_verlet", 0.1, 1,
                                      {"mode_freq_err_max", "mode_damping_max"});
  ASSERT_TRUE(harmonic.metrics.count("mode_freq_err_max"));
  EXPECT_NEAR(harmonic.metrics.at("mode_freq_err_max"), 2 / 0.3 * std::asin(0.15) - 1, 1e-13);
  EXPECT_LE(harmonic.metrics.at("mode_damping_max"), 1e-14);
  EXPECT_NO_THROW(to_row(harmonic));
  EXPECT_FALSE(run_with("pendulum", "stormer_verlet", 0.1, 1, {"mode_freq_err_max"})
                   .metrics.count("mode_freq_err_max"));
  EXPECT_FALSE(run_with("harmonic:omega=3", "stormer_verlet", 0.1, 1, {})
                   .metrics.count("mode_freq_err_max"));
  EXPECT_NE(normal_modes_not_applicable(*make_integrator("stormer_verlet"),
                                        *make_problem("spring_chain:model=fpu_beta")),
            "");
}

// A problem that declares itself linear has a constant Hessian K and ∇V(q) = K q.
TEST(NormalModes, LinearProblemsHaveAConstantHessian) {
  int linear = 0;
  for (const auto& spec : problem_test_specs()) {
    const auto problem = make_problem(spec);
    if (!problem->is_linear()) continue;
    ++linear;
    ASSERT_TRUE(problem->has(kHessian)) << spec;
    const State state = problem->initial_state();
    const Vec shifted = state.q + Vec::LinSpaced(state.q.size(), 0.3, -0.7);
    SparseMatrix at_state, at_shifted;
    problem->hessian(state.q, at_state);
    problem->hessian(shifted, at_shifted);
    const Eigen::MatrixXd stiffness(at_state);
    EXPECT_LE((stiffness - Eigen::MatrixXd(at_shifted)).cwiseAbs().maxCoeff(),
              1e-12 * stiffness.cwiseAbs().maxCoeff())
        << spec;
    // ∇V(q) − ∇V(q₀) = K(q − q₀): V is quadratic, so ∇V is affine (elastic_rod's end load adds a
    // constant to it).
    Vec gradient, gradient_at_state;
    problem->gradient(shifted, gradient);
    problem->gradient(state.q, gradient_at_state);
    EXPECT_LE(
        (gradient - gradient_at_state - stiffness * (shifted - state.q)).cwiseAbs().maxCoeff(),
        1e-12 * stiffness.cwiseAbs().maxCoeff() * shifted.cwiseAbs().maxCoeff())
        << spec;
  }
  EXPECT_GE(linear, 4);
}

// Störmer–Verlet's period error is O(h²): halving dt divides it by ~4.
TEST(PeriodMeasured, PendulumPeriodConvergesAtSecondOrder) {
  const RunRecord coarse =
      run_with("pendulum:theta0=1", "stormer_verlet", 0.02, 60, {"period_measured"});
  const RunRecord fine =
      run_with("pendulum:theta0=1", "stormer_verlet", 0.01, 60, {"period_measured"});
  ASSERT_TRUE(coarse.metrics.count("period_err_rel"));
  const double e1 = coarse.metrics.at("period_err_rel"), e2 = fine.metrics.at("period_err_rel");
  std::printf("pendulum period_err_rel %.3g (dt=0.02) %.3g (dt=0.01), measured %.10g\n", e1, e2,
              fine.metrics.at("period_measured"));
  EXPECT_LT(std::abs(e2), 1e-4);
  EXPECT_NEAR(e1 / e2, 4.0, 0.5);
  // Not asked for: not computed.
  EXPECT_FALSE(run_with("pendulum:theta0=1", "stormer_verlet", 0.02, 60, {})
                   .metrics.count("period_measured"));
}

// Problems with exact periods, each through its period_observable (problems/problem.hpp): the
// pendulum's angle and Kepler's x by default, and for nbody the second body's x relative to the
// centre of mass — here a two-body problem with non-unit masses, G = 1.3 and a centre of mass
// drifting by 8 (about 7 orbit diameters) over the run, so q[0] itself never crosses 0 twice.
// Kepler's third law: T = 2π a^{3/2}/√μ, μ = G(m₁ + m₂), 1/a = 2/r − v²/μ (vis-viva).
TEST(PeriodMeasured, MatchesExactPeriodsThroughEachProblemsObservable) {
  const double mu = 1.3 * (3 + 0.25), r = 1.5, v = 1.4;  // relative distance and speed
  const double a = 1 / (2 / r - v * v / mu);
  const double two_body_period = 2 * std::acos(-1.0) * std::pow(a, 1.5) / std::sqrt(mu);
  struct Case {
    std::string problem;
    double period;
    double h;
  };
  const Case cases[] = {
      {"pendulum:theta0=2.5", make_problem("pendulum:theta0=2.5")->period(), 0.005},
      {"kepler:e=0.3", 2 * std::acos(-1.0), 0.002},
      {"nbody:preset=custom,masses=3/0.25,G=1.3,positions=0/0/1.5/0,velocities=0.2/-0.1/0.2/1.3",
       two_body_period, 0.002},
  };
  // The same orbit from a state file (initial=FILE wraps the problem; the wrapper must forward
  // the observable).
  const std::string two_body = cases[2].problem;
  const std::string state_file = ::testing::TempDir() + "two_body_state.csv";
  {
    const State start = make_problem(two_body)->initial_state();
    std::ofstream out(state_file);
    out.precision(17);
    for (int i = 0; i < start.q.size(); ++i) out << start.q[i] << "," << start.p[i] << "\n";
  }
  std::vector<Case> all(std::begin(cases), std::end(cases));
  all.push_back({two_body + ",initial=" + state_file, two_body_period, 0.002});
  for (const auto& [spec, period, h] : all) {
    const RunRecord record =
        run_with(spec, "stormer_verlet", h, 10.5 * period, {"period_measured"});
    ASSERT_TRUE(record.metrics.count("period_measured")) << spec;
    const double measured = record.metrics.at("period_measured");
    std::printf("%s: period_measured %.10g, exact %.10g\n", spec.c_str(), measured, period);
    EXPECT_NEAR(measured / period, 1.0, 1e-4) << spec;
  }
}

// explicit Euler on the harmonic oscillator multiplies H by 1 + h²ω² per step, so while
// t·h ≪ 1 the error grows like t·h: exponent 1. Störmer–Verlet's error on Kepler is bounded:
// exponent ~0 over the last three decades of a 1000-period run.
TEST(EnergyGrowthExponent, DriftIsOneAndBoundedIsZero) {
  const double drift = run_with("harmonic", "explicit_euler", 1e-4, 10, {"energy_growth_exponent"})
                           .metrics.at("energy_growth_exponent");
  const double bounded =
      run_with("kepler", "stormer_verlet", 0.01, 6283, {"energy_growth_exponent"})
          .metrics.at("energy_growth_exponent");
  std::printf("energy_growth_exponent: explicit_euler/harmonic %.3f, stormer_verlet/kepler %.3f\n",
              drift, bounded);
  EXPECT_NEAR(drift, 1.0, 0.1);
  EXPECT_NEAR(bounded, 0.0, 0.1);
}

// Every optional metric has its column in the run schema (to_row throws on an unknown metric).
TEST(OptionalMetrics, EveryOneIsReportedAndHasAColumn) {
  const RunRecord record =
      run_with("pendulum:theta0=1", "stormer_verlet", 0.01, 100, optional_metric_names());
  for (const std::string name :
       {"symplecticity_defect", "period_measured", "period_err_rel", "energy_growth_exponent"}) {
    EXPECT_TRUE(record.metrics.count(name)) << name;
  }
  EXPECT_NO_THROW(to_row(record));
}

// The divergence rule is an option (docs/USAGE.md "Failure rows"): explicit Euler at h = 0.1
// multiplies H by 1.01 per step, so a factor of 10 stops it after ln 11/ln 1.01 ≈ 241 steps, and
// inf lets it run to t = 300 and report the growth, 1.01³⁰⁰⁰ − 1 = 9.2e12.
TEST(DivergeFactor, LowFactorStopsAndInfinityRunsToTheEnd) {
  RunConfig config;
  config.dt = 0.1;
  config.t_end = 300;
  config.timing_repeats = 0;
  config.diverge_factor = 10;
  const RunResult stopped = run_one("harmonic", "explicit_euler", config);
  EXPECT_EQ(stopped.record.status, "diverged");
  EXPECT_NEAR(*stopped.record.t_reached, 24.0, 1e-9);
  EXPECT_LE(stopped.record.metrics.at("energy_err_max"), 10.0);
  config.diverge_factor = std::numeric_limits<double>::infinity();
  const RunResult finished = run_one("harmonic", "explicit_euler", config);
  EXPECT_EQ(finished.record.status, "ok");
  EXPECT_EQ(*finished.record.steps, 3000);
  EXPECT_NEAR(finished.record.metrics.at("energy_err_max"), std::pow(1.01, 3000) - 1,
              1e-6 * 9.2e12);
}

}  // namespace
}  // namespace structure_metrics_test
}  // namespace geomint
