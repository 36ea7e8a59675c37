// Registry-driven method checks (docs/DESIGN.md §7): every registered method's declared order and
// every declared flag is verified, not only declared, so a new method is checked the day it is
// added; the order, drift and reversibility checks are the geomint::verify kit's (verify/).
// Negative controls make sure the checks can fail.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <map>
#include <string>

#include "harness/order.hpp"
#include "harness/run.hpp"
#include "integrators/integrator.hpp"
#include "verify/verify.hpp"

namespace geomint {
namespace methods_test {
namespace {

// Constraints-only methods (rattle, penalty) are checked on constrained problems instead
// (integrators/constrained_methods_test.cpp): the problems here have no constraints; the
// free-rigid-body splitting on the rigid bodies (integrators/lie_poisson_test.cpp), the Boris
// pusher on the charged particle (integrators/boris_test.cpp).
// The physics-engine methods (engines/) run only the problems they build a model of, none of the
// ladders below but the pendulum; engines/engines_test.cpp tests their orders and schemes there.
std::vector<std::string> fixed_step_methods() {
  std::vector<std::string> out;
  for (const auto& spec : integrator_test_specs()) {
    const auto method = make_integrator(spec);
    if (method->provider().kind == MethodProvider::Kind::kEngine) continue;
    if (!(method->info().flags &
          (kAdaptive | kConstraintsOnly | kFreeRigidBodyOnly | kChargedParticleOnly))) {
      out.push_back(spec);
    }
  }
  return out;
}

std::string test_name(const testing::TestParamInfo<std::string>& info) {
  std::string name;
  for (char c : info.param) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
}

class EveryMethod : public testing::TestWithParam<std::string> {
 protected:
  MethodInfo info() const { return make_integrator(GetParam())->info(); }
};

// Ladders chosen so every method has >= 4 points in its asymptotic range and none reaches the
// round-off plateau before the fit (verify::pendulum_ladder, kepler_ladder); the fit drops
// pre-asymptotic points itself, and verify::declared_order starts high orders at larger steps.
void expect_declared_order(const std::string& method, const verify::Ladder& ladder) {
  const verify::CheckResult result = verify::declared_order(method, ladder);
  ASSERT_TRUE(std::isfinite(result.measured)) << verify::describe(result);
  EXPECT_TRUE(result.passed) << verify::describe(result);
}

TEST_P(EveryMethod, DeclaredOrderOnPendulum) {
  expect_declared_order(GetParam(), verify::pendulum_ladder());
}
TEST_P(EveryMethod, DeclaredOrderOnKepler) {
  expect_declared_order(GetParam(), verify::kepler_ladder());
}

// Non-unit masses: a method that forgets M⁻¹ somewhere (Newmark's initial acceleration, say) is
// exact for m = 1 and loses its order for any other mass, so every order test above would pass.
// Linear problems with exact solutions, heavy and light: harmonic with m = 4, and a fixed-end
// chain of four 2.5-kg masses.
const verify::Ladder kHeavyHarmonicLadder{"harmonic:mass=4,omega=2", 0.1, 7, 5.0};
const verify::Ladder kHeavyChainLadder{"spring_chain:n=4,mass=2.5,stiffness=3", 0.1, 7, 5.0};
TEST_P(EveryMethod, DeclaredOrderWithNonUnitMass) {
  expect_declared_order(GetParam(), kHeavyHarmonicLadder);
  expect_declared_order(GetParam(), kHeavyChainLadder);
}

// Time in the force: the driven damped oscillator (exact transient plus steady state), whose
// force F = −c v + A cos(Ωt) depends on t. Every method that takes forces keeps its declared
// order; one that evaluates F at the wrong time of its step (t_k where t_k + h/2 belongs) drops
// to first order here and passes every unforced test above.
const verify::Ladder kDrivenLadder{"damped_oscillator:omega=2,zeta=0.1,drive=0.8,drive_omega=1.3",
                                   0.1, 7, 5.0};
TEST_P(EveryMethod, DeclaredOrderWithATimeDependentForce) {
  const auto problem = make_problem(kDrivenLadder.problem);
  const Applicability applies = applicable(*make_integrator(GetParam()), *problem);
  if (!applies.ok) GTEST_SKIP() << applies.reason;
  expect_declared_order(GetParam(), kDrivenLadder);
}

// Scale invariance: on a linear problem the discrete map of every fixed-step method commutes
// with scaling the state, Φ(s·y) = s·Φ(y), so the trajectory from s·y₀ is s times the one from
// y₀ — provided every solver test is relative to the state. An absolute floor in a Newton
// tolerance (‖R‖ ≤ tol·max(1, scale)) stops iterating at s = 1e-100 and fails this.
// The largest relative difference between the two trajectories, or the reason a step failed.
struct ScaledRun {
  double defect = 0.0;
  std::string failure;  // the failing step's reason, "" if every step succeeded
};

ScaledRun scaled_trajectory_defect(const std::string& method, const std::string& problem_spec,
                                   double scale, double h, int steps) {
  const auto problem = make_problem(problem_spec);
  const State start = problem->initial_state();
  State unit = start, scaled = start;
  scaled.q *= scale;
  scaled.p *= scale;
  auto unit_integrator = make_integrator(method);
  auto scaled_integrator = make_integrator(method);
  unit_integrator->reset(*problem, unit, h);
  scaled_integrator->reset(*problem, scaled, h);
  ScaledRun run;
  for (int k = 0; k < steps; ++k) {
    const StepStatus unit_status = unit_integrator->step(*problem, unit, h);
    if (!unit_status.ok) return {INFINITY, "unit state: " + unit_status.reason};
    const StepStatus scaled_status = scaled_integrator->step(*problem, scaled, h);
    if (!scaled_status.ok) return {INFINITY, scaled_status.reason};
    const double size = std::sqrt(unit.q.squaredNorm() + unit.p.squaredNorm());
    const double difference = std::sqrt((scaled.q / scale - unit.q).squaredNorm() +
                                        (scaled.p / scale - unit.p).squaredNorm());
    run.defect = std::max(run.defect, difference / size);
  }
  return run;
}

TEST_P(EveryMethod, LinearProblemsAreSolvedScaleFree) {
  // 40 steps; the two trajectories differ by rounding only (≈ steps·ε relative, times the
  // stages), far below the 1e-12 Newton tolerance at which an absolute floor shows. At 1e±100
  // every method must solve. From 1e±170 on, the squares of the state's entries leave double's
  // range (Eigen's norm() gives 0 or inf: a Newton test built on it stops at once or never),
  // and so does the energy: a minimiser, which needs E, may end with a failure that names the
  // objective's underflow or overflow — a failure row, never a wrong "ok".
  for (const char* problem : {"harmonic:mass=4,omega=3", "spring_chain:n=4,mass=2.5"}) {
    for (double scale : {1e-100, 1e100, 1e-170, 1e170, 1e-250, 1e250}) {
      const ScaledRun run = scaled_trajectory_defect(GetParam(), problem, scale, 0.1, 40);
      const bool energy_out_of_range = std::abs(std::log10(scale)) > 150;
      if (energy_out_of_range &&
          (run.failure == "objective_underflow" || run.failure == "objective_overflow")) {
        continue;
      }
      EXPECT_LT(run.defect, 1e-12) << GetParam() << " on " << problem << " scaled by " << scale
                                   << (run.failure.empty() ? "" : ": step failed: " + run.failure);
    }
  }
}

// Bounded energy error with no drift (verify::energy_without_drift): over 1e5 steps the
// least-squares trend of the per-window maxima, times the horizon, must stay below 10% of the
// maximum error itself. A drifting method (explicit Euler, RK4) has trend × T ≈ err_max.
TEST_P(EveryMethod, SymplecticMeansBoundedEnergy) {
  if (!(info().flags & kSymplectic)) GTEST_SKIP() << "not declared symplectic";
  const verify::CheckResult result = verify::energy_without_drift(GetParam());
  EXPECT_TRUE(result.passed) << verify::describe(result);
}

TEST(NegativeControl, DriftCheckFailsForRk4AndExplicitEuler) {
  for (const char* method : {"rk4", "explicit_euler"}) {
    const verify::CheckResult result = verify::energy_without_drift(method);
    EXPECT_FALSE(result.passed) << verify::describe(result);
  }
}

TEST_P(EveryMethod, SymmetricMeansReversible) {
  if (!(info().flags & kSymmetric)) GTEST_SKIP() << "not declared symmetric";
  // 40 steps of round-off at ~1e-16 each, with implicit solves at 1e-12 relative tolerance.
  for (const char* check : {"reversible_pendulum", "reversible_kepler"}) {
    const verify::CheckResult result = verify::run_check(GetParam(), check);
    EXPECT_TRUE(result.passed) << verify::describe(result);
  }
}

TEST(NegativeControl, ReversibilityCheckFailsForNonSymmetricMethods) {
  EXPECT_GT(verify::reversibility_defect("symplectic_euler_a", "pendulum:theta0=1.5", 0.1), 1e-6);
  EXPECT_GT(verify::reversibility_defect("rk4", "pendulum:theta0=1.5", 0.1), 1e-9);
}

// Central force: a variational/symplectic method with a rotation-invariant discrete Lagrangian
// keeps q × p exactly, so only round-off remains: ≤ 1e-13 relative over 1e5 steps.
TEST_P(EveryMethod, SymplecticKeepsKeplerAngularMomentum) {
  if (!(info().flags & kSymplectic)) GTEST_SKIP() << "not declared symplectic";
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 1000.0;  // 1e5 steps
  config.timing_repeats = 0;
  const RunResult result = run_one("kepler:e=0.6", GetParam(), config);
  ASSERT_TRUE(result.ok) << result.record.message.value_or("");
  const double angular0 = std::sqrt(1 - 0.6 * 0.6);
  // Exact conservation up to rounding, which random-walks as eps * sqrt(steps * stages): about
  // 1e-13 for a 5-stage composition over 1e5 steps. The bound is 1e-12, far below RK4's
  // truncation drift (NegativeControl below) and the 1e-10 that separates the two classes.
  EXPECT_LT(result.record.metrics.at("angular_momentum_err_max") / angular0, 1e-12);
}

TEST(NegativeControl, Rk4DoesNotKeepKeplerAngularMomentum) {
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 1000.0;
  config.timing_repeats = 0;
  const RunResult result = run_one("kepler:e=0.6", "rk4", config);
  EXPECT_GT(result.record.metrics.at("angular_momentum_err_max"), 1e-10);
}

// L → cL (masses and potential scaled by the same c) leaves the equations of motion unchanged, so
// every fixed-step method must give the same positions and c times the momenta: a method that
// forgets M⁻¹ somewhere (e.g. in a starting acceleration) passes every check on unit masses and
// fails here. Nonlinear FPU-β chain, c = 4 (masses, k and β), 50 steps of h = 0.1 (hω ≈ 0.2).
TEST_P(EveryMethod, ScalingMassesAndPotentialTogetherKeepsTheMotion) {
  const auto unit = make_problem("spring_chain:n=4,model=fpu_beta");
  const auto heavy = make_problem("spring_chain:n=4,model=fpu_beta,mass=4,stiffness=4,beta=4");
  auto unit_method = make_integrator(GetParam());
  auto heavy_method = make_integrator(GetParam());
  State a = unit->initial_state(), b = heavy->initial_state();
  ASSERT_EQ((b.p - 4 * a.p).norm(), 0.0);
  const double h = 0.1;
  unit_method->reset(*unit, a, h);
  heavy_method->reset(*heavy, b, h);
  for (int k = 0; k < 50; ++k) {
    ASSERT_TRUE(unit_method->step(*unit, a, h).ok) << k;
    ASSERT_TRUE(heavy_method->step(*heavy, b, h).ok) << k;
  }
  // Implicit solves stop at a relative residual of 1e-12 (then polish): 1e-10 leaves room for
  // 50 steps of that; the bug class this targets is an O(h) or O(h²) difference (> 1e-4 here).
  const double q_scale = a.q.norm(), p_scale = a.p.norm();
  EXPECT_LE((b.q - a.q).norm(), 1e-10 * q_scale) << GetParam();
  EXPECT_LE((b.p - 4 * a.p).norm(), 4e-10 * p_scale) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryMethod, testing::ValuesIn(fixed_step_methods()), test_name);

// Every implicit method, its solver stopped at its iteration limit: the step must end the run as
// a failure row that names the non-convergence, never be accepted unconverged (an implicit RK
// step that took its last unconverged iterate passed every order and flag check above, whose
// solves converge). Each family's own limit, the first of these options the method accepts.
// SUNDIALS retries a failed solve with a smaller step, which one iteration then solves: its
// convergence test is made unreachable as well, so every retry fails.
const char* const kIterationLimits[] = {"max_iter=1", "max_nonlin_iters=1,nonlin_conv_coef=1e-300"};
// Implicit methods with no iteration to limit, and why.
const std::map<std::string, std::string> kNoIterationLimit = {
    {"odeint_rosenbrock4", "linearly implicit (Rosenbrock): one linear solve per stage"},
    {"gsl_msbdf", "GSL odeiv2 fixes its iteration count inside the stepper (no option)"},
    {"gsl_rk4imp", "GSL odeiv2 fixes its iteration count inside the stepper (no option)"},
    {"mujoco", "MuJoCo's implicit integrator solves one linear system per step (no iteration)"},
    {"ode",
     "ODE's dWorldStep solves the joint forces directly; dWorldQuickStep's fixed sweep count "
     "is no option of the method"},
};

// Configurations whose step equations one iteration solves exactly, so a limit of one binds
// nothing.
const std::map<std::string, std::string> kSolvedInOneIteration = {
    {"lobatto3ab:s=2", "Stormer-Verlet: its stage equations are linear in the unknowns"},
    {"generalized_leapfrog", "Stormer-Verlet on a separable problem: explicit, nothing to iterate"},
};

std::vector<std::string> implicit_methods() {
  std::vector<std::string> out;
  for (const auto& spec : integrator_test_specs()) {
    if (make_integrator(spec)->info().flags & kImplicit) out.push_back(spec);
  }
  return out;
}

class EveryImplicitMethod : public testing::TestWithParam<std::string> {};

TEST_P(EveryImplicitMethod, SolverAtItsIterationLimitIsAFailureRow) {
  const std::string& spec = GetParam();
  const std::string name = make_integrator(spec)->info().name;
  if (const auto exact = kSolvedInOneIteration.find(spec); exact != kSolvedInOneIteration.end()) {
    GTEST_SKIP() << exact->second;
  }
  std::string limited;
  for (const char* limit : kIterationLimits) {
    const std::string candidate = spec + (spec.find(':') == std::string::npos ? ":" : ",") + limit;
    try {
      make_integrator(candidate);
    } catch (const InputError&) {
      continue;
    }
    limited = candidate;
    break;
  }
  if (limited.empty()) {
    const auto why = kNoIterationLimit.find(name);
    ASSERT_NE(why, kNoIterationLimit.end())
        << spec << " is implicit but takes none of the iteration limits this test knows";
    GTEST_SKIP() << why->second;
  }
  // A nonlinear problem and a step no single iteration solves to tolerance.
  std::string problem = "pendulum:theta0=2.5";
  if (!applicable(*make_integrator(limited), *make_problem(problem)).ok) {
    problem = "cartesian_pendulum:theta0=2.5";
  }
  const Applicability applies = applicable(*make_integrator(limited), *make_problem(problem));
  ASSERT_TRUE(applies.ok) << applies.reason;
  RunConfig config;
  config.dt = 0.2;
  config.t_end = 2.0;
  config.timing_repeats = 0;
  const RunResult result = run_one(problem, limited, config);
  EXPECT_FALSE(result.ok) << limited << " on " << problem << " was accepted";
  std::string text = result.record.status + " " + result.record.message.value_or("");
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  EXPECT_TRUE(text.find("max_iter") != std::string::npos ||
              text.find("converge") != std::string::npos ||
              text.find("conv_fail") != std::string::npos)
      << limited << ": the row does not name non-convergence: " << text;
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryImplicitMethod, testing::ValuesIn(implicit_methods()),
                         test_name);

}  // namespace
}  // namespace methods_test
}  // namespace geomint
