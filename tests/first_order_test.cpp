// First-order-only problems (van der Pol, Robertson; capability kFirstOrderOnly, docs/DESIGN.md
// §2) through the harness: which methods apply and why the others do not, every applicable
// method on a mildly stiff van der Pol, and tight CVODE runs reproducing the IVP Test Set's
// reference values at its end times (scd, docs/PROBLEMS.md "Stiff first-order references").
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "harness/run.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace first_order_test {
namespace {

RunResult run(const std::string& problem, const std::string& method, double dt, double t_end) {
  RunConfig config;
  config.dt = dt;
  config.t_end = t_end;
  config.timing_repeats = 0;
  return run_one(problem, method, config);
}

TEST(FirstOrderRuns, OnlyFirstOrderCapableMethodsApplyAndTheOthersSayWhy) {
  const auto problem = make_problem("van_der_pol");
  int capable = 0;
  for (const auto& spec : integrator_test_specs()) {
    const auto method = make_integrator(spec);
    const unsigned flags = method->info().flags;
    const Applicability fit = applicable(*method, *problem);
    EXPECT_EQ(fit.ok, (flags & kFirstOrderCapable) != 0) << spec;
    capable += fit.ok;
    if (!fit.ok) {
      EXPECT_NE(fit.reason.find("'van_der_pol' is a first-order ODE"), std::string::npos)
          << fit.reason;
      EXPECT_NE(fit.reason.find("cvode_bdf"), std::string::npos) << fit.reason;
    }
  }
  // CVODE (BDF, BDF+KLU, Adams), IDA, ARKODE, three GSL, two odeint, rk4, implicit Euler.
  EXPECT_EQ(capable, 12);
  try {
    run("van_der_pol", "stormer_verlet", 1e-3, 0.1);
    FAIL() << "a Lagrangian method ran on a first-order problem";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("methods that apply: "), std::string::npos);
  }
}

// μ = 10 (ε = 0.01): stiff enough to separate the methods, mild enough for rk4 at h = 1e-3
// (h|λ| ≤ 0.3). Every first-order-capable method against a tight CVODE BDF run at t = 0.5.
TEST(FirstOrderRuns, EveryApplicableMethodAgreesWithATightRun) {
  const std::string problem = "van_der_pol:mu=10";
  const RunResult tight = run(problem, "cvode_bdf:rtol=1e-12,atol=1e-12", 0, 0.5);
  ASSERT_TRUE(tight.ok);
  const Vec& y_ref = tight.final_state.q;
  for (const auto& spec : first_order_methods()) {
    const auto method = make_integrator(spec);
    const bool adaptive = method->info().flags & kAdaptive;
    const bool euler = method->info().order == 1;
    const std::string tuned =
        adaptive ? spec + (spec.find(':') == std::string::npos ? ":" : ",") + "rtol=1e-9,atol=1e-9"
                 : spec;
    const RunResult result = run(problem, tuned, euler ? 1e-5 : 1e-3, 0.5);
    ASSERT_TRUE(result.ok) << tuned << ": " << result.record.message.value_or("");
    ASSERT_EQ(result.final_state.p.size(), 0) << tuned;
    const double error = (result.final_state.q - y_ref).lpNorm<Eigen::Infinity>();
    // Backward Euler: O(h) = 1e-5 times the solution's curvature scale; the others 1e-6.
    EXPECT_LT(error, euler ? 1e-3 : 1e-6) << tuned;
    EXPECT_EQ(result.record.metrics.count("energy_err_max"), 0u) << tuned;
  }
}

// The IVP Test Set's VDPOL (t = 2) and ROBER (t = 1e11) references are reproduced by a tight
// CVODE BDF run: ≥ 9.5 and ≥ 10 significant correct digits (scd: −log10 of the largest relative
// component error; the Test Set's RADAU runs in extended precision give 16).
TEST(FirstOrderRuns, TightCvodeRunsReproduceTheTestSetReferences) {
  const RunResult vdpol = run("van_der_pol", "cvode_bdf:rtol=1e-12,atol=1e-12", 0, 2.0);
  ASSERT_TRUE(vdpol.ok) << vdpol.record.message.value_or("");
  EXPECT_GE(vdpol.record.metrics.at("scd"), 9.5);
  EXPECT_LT(vdpol.record.metrics.at("error_final"), 1e-9);
  const RunResult rober = run("robertson", "cvode_bdf:rtol=1e-12,atol=1e-22", 0, 1e11);
  ASSERT_TRUE(rober.ok) << rober.record.message.value_or("");
  EXPECT_GE(rober.record.metrics.at("scd"), 10.0);
  // y2 ~ 8e-14 at the end: a run that gets y2 wrong cannot reach 10 digits.
  EXPECT_NEAR(rober.final_state.q[1], 0.8333360770334713e-13, 1e-22);
  // A run that stops short of the reference time reports no scd.
  const RunResult short_run = run("robertson", "cvode_bdf:rtol=1e-6,atol=1e-14", 0, 1e3);
  EXPECT_EQ(short_run.record.metrics.count("scd"), 0u);
}

// The commands and options written for (q, p) refuse a first-order problem with an input error
// or leave their metric out, instead of crashing (both crashed before).
TEST(FirstOrderRuns, LagrangianOnlyOptionsRefuseOrSkip) {
  try {
    make_problem("robertson:initial=/nonexistent.csv");
    FAIL() << "initial= accepted on a first-order problem";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("first-order"), std::string::npos) << error.what();
  }
  RunConfig config;
  config.dt = 1e-3;
  config.t_end = 0.05;
  config.timing_repeats = 0;
  config.extra_metrics = {"symplecticity_defect", "period_measured", "energy_growth_exponent"};
  const RunResult result = run_one("van_der_pol:mu=10", "rk4", config);
  EXPECT_TRUE(result.ok);
  EXPECT_EQ(result.record.metrics.count("symplecticity_defect"), 0u);
}

}  // namespace
}  // namespace first_order_test
}  // namespace geomint
