// Time-dependent Hamiltonians H(q, p, t) (problems/structures/time_dependent.hpp): SUNDIALS'
// published ark_damped_harmonic_symplectic output reproduced by sprk, every method's time
// treatment checked against what it does on damped_harmonic_td, and the frozen-time degradation.
#include "problems/structures/time_dependent.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

#include "harness/run.hpp"
#include "integrators/integrator.hpp"
#include "integrators/time_treatment.hpp"

namespace geomint {
namespace time_dependent_test {
namespace {

constexpr const char* kProblem = "damped_harmonic_td";
constexpr const char* kSundialsForm = "damped_harmonic_td:form=sundials";

// The example's output (ark_damped_harmonic_symplectic.out, SUNDIALS 7): t = k·10π/8 and q(t),
// H(q, p, t), printed with "%.6Lf".
struct PrintedRow {
  double q, H;
};
constexpr std::array<PrintedRow, 8> kPrinted = {{{-1.858671, 0.518239},
                                                 {2.097078, 1.797232},
                                                 {2.412988, 4.821524},
                                                 {-3.767992, 0.009034},
                                                 {2.451177, 4.130995},
                                                 {1.242002, 1.013408},
                                                 {-0.806768, 0.352368},
                                                 {0.878500, 0.773974}}};

// SPRKStep's fixed steps with tstop at each output time: steps of dt while they fit, then the
// remainder (ARKODE shortens the step that would pass tstop).
std::array<State, 8> sundials_run(const std::string& method_spec, const Problem& problem) {
  const auto method = make_integrator(method_spec);
  State state = problem.initial_state();
  method->reset(problem, state, 1e-3);
  const double interval = 10 * std::numbers::pi / 8;
  std::array<State, 8> outputs;
  double t_out = 0;
  for (auto& output : outputs) {
    t_out += interval;
    while (state.t + 1e-3 <= t_out) EXPECT_TRUE(method->step(problem, state, 1e-3).ok);
    EXPECT_TRUE(method->step(problem, state, t_out - state.t).ok);
    output = state;
  }
  return outputs;
}

// The example hands SPRKStep q' as its first function, so its stages move q with the â weights
// before kicking p with the a weights (sprk first=drift), at SPRKStep's stage times (time=stages),
// in its code's non-Hamiltonian form. The
// same method and step reproduce every printed digit: the printed values are rounded to 6
// decimals (half a unit: 5e-7), and the two runs differ by rounding only (~1e-12 after 31416
// steps). The documented order (first=kick) misses by far more, as does the Hamiltonian form.
TEST(TimeDependent, SprkReproducesSundialsPublishedOutput) {
  const auto problem = make_problem(kSundialsForm);
  const auto* hamiltonian = problem->as<TimeDependentHamiltonian>();
  ASSERT_NE(hamiltonian, nullptr);
  const auto outputs = sundials_run("sprk:table=mclachlan4,first=drift,time=stages", *problem);
  constexpr double kHalfPrintedUnit = 5e-7, kSlack = 1e-9;
  for (size_t k = 0; k < outputs.size(); ++k) {
    const State& s = outputs[k];
    EXPECT_NEAR(s.q[0], kPrinted[k].q, kHalfPrintedUnit + kSlack) << "output " << k + 1;
    EXPECT_NEAR(hamiltonian->hamiltonian(s.q, s.p, s.t), kPrinted[k].H, kHalfPrintedUnit + kSlack)
        << "output " << k + 1;
  }
  const auto kick_first = sundials_run("sprk:table=mclachlan4,time=stages", *problem);
  double worst = 0;
  for (size_t k = 0; k < kick_first.size(); ++k) {
    worst = std::max(worst, std::abs(kick_first[k].q[0] - kPrinted[k].q));
  }
  EXPECT_GT(worst, 1e-6) << "the substep order should matter at this accuracy";
}

// Every registered method: applicable() admits it on damped_harmonic_td exactly when its time
// treatment is not "none", refusing with the reason; each one admitted really follows H(q, p, t):
// at t = 3 (h = 10⁻³, or its tolerances) it is within 1% of the distance between the reference
// (rk4 at h = 10⁻⁴, error ~1e-14) and the motion of the time-free H(q, p, 0).
TEST(TimeDependent, EveryMethodTreatsTimeAsItDeclares) {
  const auto problem = make_problem(kProblem);
  RunConfig config;
  config.t_end = 3;
  config.timing_repeats = 0;
  config.dt = 1e-4;
  const RunResult reference = run_one(kProblem, "rk4", config);
  ASSERT_TRUE(reference.ok);
  // A method blind to t would follow H(q, p, 0) = ½p² + ½q², the unit harmonic oscillator.
  const State blind = make_problem("harmonic")->exact(config.t_end);
  const double blind_error = std::abs(blind.q[0] - reference.final_state.q[0]) +
                             std::abs(blind.p[0] - reference.final_state.p[0]);
  EXPECT_GT(blind_error, 0.1);
  config.dt = 1e-3;
  int admitted = 0;
  for (const auto& spec : integrator_test_specs()) {
    const auto method = make_integrator(spec);
    const TimeTreatment treatment = time_treatment(*method);
    const Applicability verdict = applicable(*method, *problem);
    if (treatment == TimeTreatment::kNone) {
      EXPECT_FALSE(verdict.ok) << spec;
      // A structure-only method (boris) or an engine is refused for that reason first.
      if (method_needs(method->info()).structure == nullptr &&
          dynamic_cast<const RunsListedProblems*>(method.get()) == nullptr) {
        EXPECT_NE(verdict.reason.find("does not treat time"), std::string::npos) << verdict.reason;
      }
      continue;
    }
    if (!verdict.ok) continue;  // refused for another reason (needs a Hessian)
    ++admitted;
    const RunResult result = run_one(kProblem, spec, config);
    if (!result.ok && spec.find("linear_solver=klu") != std::string::npos) {
      continue;  // KLU needs an analytic sparse Jacobian, which this problem has none of
    }
    ASSERT_TRUE(result.ok) << spec << ": " << result.record.message.value_or("");
    const double error = std::abs(result.final_state.q[0] - reference.final_state.q[0]) +
                         std::abs(result.final_state.p[0] - reference.final_state.p[0]);
    EXPECT_LT(error, 1e-2 * blind_error) << spec << " (" << time_treatment_name(treatment) << ")";
    // Frozen time is first order even for high-order tables: measurably off at h = 10⁻³.
    if (treatment == TimeTreatment::kFrozenPerStep) {
      EXPECT_GT(error, 1e-5) << spec;
    }
  }
  EXPECT_GE(admitted, 5);
}

// A start read from a file (initial=FILE.csv) keeps H(q, p, t): without it the wrapper would pass
// for the time-free H(q, p, 0), and every method would run it.
TEST(TimeDependent, GivenInitialStateKeepsTheTimeDependence) {
  const std::string path = testing::TempDir() + "damped_harmonic_td_start.csv";
  std::ofstream(path) << "0.5,-0.2\n";
  const auto problem = make_problem("damped_harmonic_td:initial=" + path);
  ASSERT_NE(problem->as<TimeDependentHamiltonian>(), nullptr);
  EXPECT_FALSE(applicable(*make_integrator("stormer_verlet"), *problem).ok);
  EXPECT_TRUE(applicable(*make_integrator("sprk"), *problem).ok);
}

// sprk on H(q, p, t), errors at t = 3: the extended phase space keeps each table's order (2 for
// leapfrog, 4 for McLachlan's, whose Nyström condition holds: T is quadratic in p), while the
// frozen step and SPRKStep's stage times are first order whatever the table.
TEST(TimeDependent, SprkOrdersByTimeTreatment) {
  RunConfig config;
  config.t_end = 3;
  config.timing_repeats = 0;
  config.dt = 1e-4;
  const RunResult reference = run_one(kProblem, "rk4", config);
  ASSERT_TRUE(reference.ok);
  auto order = [&](const std::string& spec, double h) {
    double errors[2];
    for (int k = 0; k < 2; ++k) {
      config.dt = h / (1 << k);
      const RunResult result = run_one(kProblem, spec, config);
      EXPECT_TRUE(result.ok) << spec;
      errors[k] = std::abs(result.final_state.q[0] - reference.final_state.q[0]);
    }
    return std::log2(errors[0] / errors[1]);
  };
  for (const auto& [table, declared] : {std::pair{"leapfrog2", 2}, std::pair{"mclachlan4", 4}}) {
    const std::string sprk = std::string("sprk:table=") + table;
    EXPECT_NEAR(order(sprk + ",time=frozen", 0.02), 1.0, 0.15) << table;
    EXPECT_NEAR(order(sprk + ",time=stages", 0.02), 1.0, 0.15) << table;
    EXPECT_NEAR(order(sprk, 0.1), declared, 0.2) << table;
  }
}

}  // namespace
}  // namespace time_dependent_test
}  // namespace geomint
