// Every method's failures reach the result row (docs/DESIGN.md §3, "Failures are rows"): each
// registered method runs a problem that breaks after a few steps, once through step() (or
// adaptive_step()) by hand and once through the harness (run_one, whose fixed-step loop is
// Integrator::advance), and the row must carry the failure the hand loop saw, after as many
// good steps. A method whose advance() drops a step's status (position Verlet once reported its
// unconverged force kick as `ok`) fails here whatever the method family.
//
// Its own executable: the test problem is registered, which changes the process-wide problem
// registry that the registry-driven suites iterate (as tests/registration does).
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "integrators/integrator.hpp"

namespace geomint {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// A built-in problem whose gradient (kind=gradient, on the harmonic oscillator), force
// (kind=force, the harmonic oscillator with a force that is zero until then) or gradient under
// holonomic constraints (kind=constrained, the Cartesian pendulum) turns NaN once q[0] falls
// below half its initial value: after about ten steps of 0.1 from q[0] > 0 towards q[0] < 0.
class TurnsNan final : public Problem, public HolonomicConstraints, public NonConservativeForce {
 public:
  TurnsNan(std::unique_ptr<Problem> base, bool poison_force)
      : base_(std::move(base)),
        base_constraints_(base_->as_constrained()),
        poison_force_(poison_force) {
    threshold_ = 0.5 * base_->initial_state().q[0];
    set_mass(base_->mass());
    set_capabilities(base_->capabilities() & kHessian);
    set_defaults(0.1, 3.0);
  }

  State initial_state() const override { return base_->initial_state(); }
  double potential(const Vec& q) const override {
    return poisoned_gradient(q) ? kNan : base_->potential(q);
  }
  void gradient(const Vec& q, Vec& g) const override {
    base_->gradient(q, g);
    if (poisoned_gradient(q)) g.setConstant(kNan);
  }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    base_->hessian(q, H);
    if (poisoned_gradient(q)) H = Eigen::MatrixXd::Constant(dof(), dof(), kNan).sparseView();
  }
  const NonConservativeForce* as_forced() const override { return poison_force_ ? this : nullptr; }
  bool has_force_jacobian() const override { return true; }
  void force(const Vec& q, const Vec&, double, Vec& f) const override {
    f = Vec::Constant(dof(), poisoned(q) ? kNan : 0.0);
  }
  void force_jacobian_v(const Vec& q, const Vec&, double, SparseMatrix& C) const override {
    C.resize(dof(), dof());
    C.setZero();
    if (poisoned(q)) C = Eigen::MatrixXd::Constant(dof(), dof(), kNan).sparseView();
    C.makeCompressed();
  }

  // The base's time-free constraints (cartesian_pendulum for kind=constrained).
  const HolonomicConstraints* as_constrained() const override {
    return base_constraints_ != nullptr ? this : nullptr;
  }
  int constraint_count() const override {
    return base_constraints_ != nullptr ? base_constraints_->constraint_count() : 0;
  }
  void constraint(const Vec& q, Vec& g) const override { base_constraints_->constraint(q, g); }
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override {
    base_constraints_->constraint_jacobian(q, G);
  }
  void constraint_curvature(const Vec& q, const Vec& v, Vec& c) const override {
    base_constraints_->constraint_curvature(q, v, c);
  }
  void constraint_hessian(const Vec& q, const Vec& lambda, SparseMatrix& K) const override {
    base_constraints_->constraint_hessian(q, lambda, K);
  }
  std::vector<std::string> multiplier_names() const override {
    return base_constraints_->multiplier_names();
  }

 private:
  // NaN below the threshold, and NaN in, NaN out.
  bool poisoned(const Vec& q) const { return !(q[0] >= threshold_); }
  bool poisoned_gradient(const Vec& q) const { return !poison_force_ && poisoned(q); }

  std::unique_ptr<Problem> base_;
  const HolonomicConstraints* base_constraints_;  // base_->as_constrained(), or nullptr
  bool poison_force_;
  double threshold_ = 0;
};

std::unique_ptr<Problem> make_turns_nan(Params& params) {
  const std::string kind =
      params.choice("kind", "gradient", {"gradient", "force", "constrained"}, "what turns NaN");
  if (kind == "constrained") {
    return std::make_unique<TurnsNan>(make_problem("cartesian_pendulum"), false);
  }
  return std::make_unique<TurnsNan>(make_problem("harmonic"), kind == "force");
}

const ProblemRegistrar kRegistrar({"turns_nan",
                                   "test problem: NaN after a few steps",
                                   &make_turns_nan,
                                   {"kind=force", "kind=constrained"}});

// The harmonic oscillator whose gradient and Hessian turn NaN once more gradients have been
// evaluated than fails_when_timed_budget: a run shares one problem object between its metric pass
// and its timing pass (harness/run_spec.hpp), so the test sets the budget to what the metric pass
// takes and the timing pass (harness/run.cpp time_run) fails.
long fails_when_timed_gradients = 0;
long fails_when_timed_budget = std::numeric_limits<long>::max();
class FailsWhenTimed final : public Problem {
 public:
  FailsWhenTimed() : base_(make_problem("harmonic")) {
    set_mass(base_->mass());
    set_capabilities(base_->capabilities() & kHessian);
    set_defaults(0.1, 3.0);
  }
  State initial_state() const override { return base_->initial_state(); }
  double potential(const Vec& q) const override { return base_->potential(q); }
  void gradient(const Vec& q, Vec& g) const override {
    base_->gradient(q, g);
    if (++fails_when_timed_gradients > fails_when_timed_budget) g.setConstant(kNan);
  }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    base_->hessian(q, H);
    if (fails_when_timed_gradients > fails_when_timed_budget) {
      H = Eigen::MatrixXd::Constant(dof(), dof(), kNan).sparseView();
    }
  }

 private:
  std::unique_ptr<Problem> base_;
};
std::unique_ptr<Problem> make_fails_when_timed(Params&) {
  return std::make_unique<FailsWhenTimed>();
}
const ProblemRegistrar kTimedRegistrar({"fails_when_timed",
                                        "test problem: NaN in every instance after the first",
                                        &make_fails_when_timed,
                                        {}});

// The harmonic oscillator whose energy, not state, turns NaN once q[0] falls below half its
// initial value (potential NaN, gradient finite): what a position-dependent mass does exactly on
// its singularity (the spherical pendulum in angles on a pole: 0/0 in the velocity solve).
class EnergyTurnsNan final : public Problem {
 public:
  EnergyTurnsNan() : base_(make_problem("harmonic")) {
    threshold_ = 0.5 * base_->initial_state().q[0];
    set_mass(base_->mass());
    set_capabilities(0);
    set_defaults(0.1, 3.0);
  }
  State initial_state() const override { return base_->initial_state(); }
  double potential(const Vec& q) const override {
    return q[0] >= threshold_ ? base_->potential(q) : kNan;
  }
  void gradient(const Vec& q, Vec& g) const override { base_->gradient(q, g); }

 private:
  std::unique_ptr<Problem> base_;
  double threshold_ = 0;
};

std::unique_ptr<Problem> make_energy_turns_nan(Params&) {
  return std::make_unique<EnergyTurnsNan>();
}

const ProblemRegistrar kEnergyRegistrar({"energy_turns_nan",
                                         "test problem: a finite state whose energy turns NaN",
                                         &make_energy_turns_nan,
                                         {}});

constexpr double kDt = 0.1;
constexpr double kTEnd = 4.0;

bool finite(const State& state) { return state.q.allFinite() && state.p.allFinite(); }

struct Failure {
  std::string reason;  // empty: the run reached t_end
  long good_steps = 0;
};

// The run by hand, as the harness's checks see it with the divergence rule off: the first
// failed status, else "nan" after the first step that leaves a non-finite state.
Failure by_hand(const std::string& method_spec, const std::string& problem_spec) {
  const auto problem = make_problem(problem_spec);
  auto method = make_integrator(method_spec);
  const bool adaptive = method->info().flags & kAdaptive;
  State state = problem->initial_state();
  method->reset(*problem, state, kDt);
  Failure failure;
  const StepGrid grid{state.t, kDt, kTEnd, static_cast<long>(std::ceil(kTEnd / kDt - 1e-9))};
  for (long k = 1; adaptive ? state.t < kTEnd : k <= grid.n; ++k) {
    StepStatus status = adaptive ? method->adaptive_step(*problem, state, kTEnd)
                                 : method->step(*problem, state, grid.time(k) - state.t);
    if (!adaptive) state.t = grid.time(k);
    if (!status.ok) {
      failure.reason = status.reason;
      return failure;
    }
    if (!finite(state)) {
      failure.reason = "nan";
      return failure;
    }
    ++failure.good_steps;
  }
  return failure;
}

std::string test_name(const testing::TestParamInfo<std::string>& info) {
  std::string name;
  for (char c : info.param) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
}

// An error-controlled solver may creep towards the NaN region in ever smaller steps that all
// succeed, until its step budget ends the run: a small budget keeps that quick.
std::string with_small_budget(const std::string& spec) {
  if (!(make_integrator(spec)->info().flags & kAdaptive)) return spec;
  const std::string budgeted =
      spec + (spec.find(':') == std::string::npos ? ":" : ",") + "max_steps=2000";
  try {
    make_integrator(budgeted);
  } catch (const InputError&) {
    return spec;
  }
  return budgeted;
}

class EveryMethodFails : public testing::TestWithParam<std::string> {};

TEST_P(EveryMethodFails, TheRowCarriesTheFailureOfStepAndAdvance) {
  const std::string method_spec = with_small_budget(GetParam());
  std::vector<std::string> not_applicable;
  for (const std::string kind : {"gradient", "force", "constrained"}) {
    const std::string problem_spec = "turns_nan:kind=" + kind;
    const Applicability applies =
        applicable(*make_integrator(method_spec), *make_problem(problem_spec));
    if (!applies.ok) {
      not_applicable.push_back(kind + ": " + applies.reason);
      continue;
    }
    SCOPED_TRACE(problem_spec);
    const Failure expected = by_hand(method_spec, problem_spec);
    ASSERT_FALSE(expected.reason.empty()) << "the method never failed by hand";
    RunConfig config;
    config.dt = kDt;
    config.t_end = kTEnd;
    config.timing_repeats = 0;
    config.diverge_factor = 0;  // only the method's own failures and non-finite states
    const RunResult result = run_one(problem_spec, method_spec, config);
    EXPECT_FALSE(result.ok);
    EXPECT_EQ(result.record.status, expected.reason) << result.record.message.value_or("");
    EXPECT_EQ(result.record.steps, expected.good_steps);
  }
  if (not_applicable.size() == 3) {
    std::string reasons;
    for (const auto& reason : not_applicable) reasons += "\n  " + reason;
    GTEST_SKIP() << "no test problem applies:" << reasons;
  }
}

// A timing pass's failed status is not dropped: the row keeps the metric pass's `ok`, gets no
// wall_s, and its message says why.
TEST(TimingPass, AFailedTimingPassLeavesNoWallTimeAndSaysWhy) {
  RunConfig config;
  config.dt = kDt;
  config.t_end = kTEnd;
  config.timing_repeats = 0;
  config.diverge_factor = 0;
  // The metric pass alone, to count its gradients; the same pass comes first below.
  fails_when_timed_gradients = 0;
  ASSERT_TRUE(run_one("fails_when_timed", "implicit_euler", config).ok);
  const long metric_pass = fails_when_timed_gradients;
  fails_when_timed_gradients = 0;
  fails_when_timed_budget = metric_pass;
  config.timing_repeats = 1;
  const RunResult result = run_one("fails_when_timed", "implicit_euler", config);
  fails_when_timed_budget = std::numeric_limits<long>::max();
  ASSERT_GT(fails_when_timed_gradients, metric_pass) << "the timing pass evaluated no gradient";
  EXPECT_TRUE(result.ok);
  EXPECT_EQ(result.record.status, "ok");
  EXPECT_FALSE(result.record.wall_s.has_value());
  EXPECT_EQ(result.record.message.value_or("").rfind("timing pass failed: ", 0), 0u)
      << result.record.message.value_or("");
}

// A finite state with a NaN energy ends the run as the failure row `nan` (a NaN energy error
// compares false with the divergence bound, so it used to pass as ok).
TEST(EnergyCheck, AFiniteStateWithoutEnergyIsAFailureRow) {
  RunConfig config;
  config.dt = kDt;
  config.t_end = kTEnd;
  config.timing_repeats = 0;
  const RunResult result = run_one("energy_turns_nan", "stormer_verlet", config);
  EXPECT_FALSE(result.ok);
  EXPECT_EQ(result.record.status, "nan");
  EXPECT_NE(result.record.message.value_or("").find("non-finite energy"), std::string::npos)
      << result.record.message.value_or("");
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryMethodFails, testing::ValuesIn(integrator_test_specs()),
                         test_name);

}  // namespace
}  // namespace geomint
