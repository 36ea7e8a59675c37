// The `exec` method (integrators/exec_method.cpp, docs/PYTHON.md "Integrators in any language:
// exec:"): the Verlet examples in Python (JSON lines) and C (binary doubles) give the built-in
// stormer_verlet's rows bit for bit and pass the verify kit; every way a process goes wrong is a
// failure row that names it; a bad spec is an InputError.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <string>

#include "harness/run.hpp"
#include "integrators/exec_process.hpp"
#include "problems/shell_words.hpp"
#include "tests/test_util.hpp"
#include "verify/verify.hpp"

namespace geomint {
namespace {

const std::string kPythonVerlet =
    "exec:cmd=/usr/bin/python3 " + shell_quoted(GEOMINT_SOURCE_DIR "/examples/exec/verlet.py");
const std::string kCVerlet = "exec:cmd=" + shell_quoted(GEOMINT_EXEC_VERLET_C) + ",format=binary";

std::string misbehaving(const std::string& mode, const std::string& extra = ",timeout=2") {
  return "exec:cmd=/usr/bin/python3 " +
         shell_quoted(GEOMINT_SOURCE_DIR "/tests/exec/misbehave.py") + " " + mode + extra;
}

RunConfig quiet(double dt, double t_end) {
  RunConfig config;
  config.dt = dt;
  config.t_end = t_end;
  config.timing_repeats = 0;
  return config;
}

// No child left behind: every process this test started has been reaped (waitpid finds none).
void expect_no_children() {
  int status = 0;
  EXPECT_EQ(waitpid(-1, &status, WNOHANG), -1) << "a child process is left (zombie or running)";
}

// Every column but the method's name agrees bit for bit (formatted as the CSV writes them).
void expect_same_row(const RunRecord& built_in, const RunRecord& exec, const std::string& what) {
  EXPECT_EQ(exec.status, built_in.status) << what;
  EXPECT_EQ(exec.steps, built_in.steps) << what;
  EXPECT_EQ(exec.family, built_in.family) << what;
  ASSERT_EQ(exec.metrics.size(), built_in.metrics.size()) << what;
  for (const auto& [name, value] : built_in.metrics) {
    EXPECT_EQ(format_number(exec.metrics.at(name)), format_number(value)) << what << " " << name;
  }
  ASSERT_TRUE(exec.counters && built_in.counters);
  EXPECT_EQ(exec.counters->force_evals, built_in.counters->force_evals) << what;
}

TEST(Exec, VerletExamplesGiveTheBuiltInRowsBitForBit) {
  for (const char* problem : {"kepler:e=0.6", "pendulum:theta0=1.5"}) {
    const RunResult built_in = run_one(problem, "stormer_verlet", quiet(0.01, 20));
    ASSERT_TRUE(built_in.ok);
    for (const std::string& method : {kPythonVerlet, kCVerlet}) {
      const RunResult exec = run_one(problem, method, quiet(0.01, 20));
      ASSERT_TRUE(exec.ok) << method << ": " << exec.record.message.value_or("");
      expect_same_row(built_in.record, exec.record, std::string(problem) + " " + method);
      EXPECT_EQ(exec.final_state.q, built_in.final_state.q) << method;
      EXPECT_EQ(exec.final_state.p, built_in.final_state.p) << method;
    }
  }
  expect_no_children();
}

TEST(Exec, HandshakeDeclaresOrderFlagsAndProvider) {
  const auto method = make_integrator(kCVerlet);
  EXPECT_EQ(method->info().name, "exec");
  EXPECT_EQ(method->info().order, 2);
  EXPECT_EQ(method->info().flags, kExplicit | kSymplectic | kSymmetric | kConservativeOnly);
  EXPECT_EQ(method->provider().label(), "user");
  EXPECT_EQ(method_family(method->info(), method->provider()), "explicit_symplectic");
  // format and timeout at their defaults stay out of the canonical spec (they change no number).
  EXPECT_EQ(make_integrator(kPythonVerlet + ",timeout=10")->spec(), kPythonVerlet);
  // Only ∇V and M⁻¹ cross the pipe: a forced or constrained problem is refused, by name.
  EXPECT_FALSE(applicable(*method, *make_problem("damped_oscillator")).ok);
  EXPECT_FALSE(applicable(*method, *make_problem("cartesian_pendulum")).ok);
  EXPECT_TRUE(applicable(*method, *make_problem("nbody")).ok);
}

// The C example is fast enough for every check of the kit; the Python one runs the order
// ladders and reversibility (its 1e5-step drift checks take tens of seconds).
TEST(Exec, VerletExamplesPassTheVerifyKit) {
  int passed = 0;
  for (const auto& result : verify::verify_method(kCVerlet)) {
    SCOPED_TRACE(verify::describe(result));
    EXPECT_TRUE(result.passed);
    if (result.applies) ++passed;
  }
  EXPECT_GE(passed, 6);  // two orders, drift, map, two reversibility checks
  for (const char* check : {"declared_order_pendulum", "declared_order_kepler",
                            "reversible_pendulum", "reversible_kepler"}) {
    const auto result = verify::run_check(kPythonVerlet, check);
    EXPECT_TRUE(result.applies && result.passed) << verify::describe(result);
  }
  expect_no_children();
}

// The optional linearised step: both examples declare "tangent": true and answer a tangent step
// with DΦ from geomint's Hessian, which agrees with the built-in stormer_verlet's to round-off
// (the matrix products may sum in another order); the state agrees bit for bit.
TEST(Exec, TangentStepsMatchTheBuiltIn) {
  const auto kepler = make_problem("kepler:e=0.6");
  const auto built_in = make_integrator("stormer_verlet");
  State start = kepler->initial_state();
  State expected_state = start;
  Eigen::MatrixXd expected;
  built_in->reset(*kepler, start, 0.01);
  ASSERT_TRUE(built_in->step_tangent(*kepler, expected_state, 0.01, expected).ok);
  for (const std::string& spec : {kPythonVerlet, kCVerlet}) {
    const auto method = make_integrator(spec);
    ASSERT_TRUE(method->has_step_tangent(*kepler)) << spec;
    State state = start;
    Eigen::MatrixXd tangent;
    method->reset(*kepler, start, 0.01);
    ASSERT_TRUE(method->step_tangent(*kepler, state, 0.01, tangent).ok) << spec;
    EXPECT_EQ(state.q, expected_state.q) << spec;
    EXPECT_EQ(state.p, expected_state.p) << spec;
    ASSERT_EQ(tangent.rows(), 4);
    ASSERT_EQ(tangent.cols(), 4);
    EXPECT_LE((tangent - expected).norm(), 1e-14 * expected.norm()) << spec << "\n" << tangent;
    EXPECT_EQ(method->counters().hessian_evals, 2) << spec;
    // The metric that asks for it: symplectic to round-off, as the built-in.
    RunConfig config = quiet(0.01, 5);
    config.extra_metrics = {"symplecticity_defect"};
    const RunResult run = run_one("kepler:e=0.6", spec, config);
    ASSERT_TRUE(run.ok) << run.record.message.value_or("");
    EXPECT_LT(run.record.metrics.at("symplecticity_defect"), 1e-13) << spec;
  }
  // A process that does not declare it has no linearised step: the metric says why not.
  EXPECT_FALSE(make_integrator(misbehaving("die"))->has_step_tangent(*kepler));
  expect_no_children();
}

struct FailureCase {
  std::string mode, status, fragment;
};

TEST(Exec, EveryMisbehaviourIsAFailureRowThatNamesIt) {
  const std::vector<FailureCase> cases = {
      {"die", "exec_died", "exited with status 3 during step"},
      {"segv", "exec_died", "killed by signal 11"},
      {"hang", "exec_timeout", "did not answer step within timeout=1 s; killed pid"},
      {"malformed", "exec_malformed", "line that is not JSON: 'this is not json'"},
      {"wrong_size", "exec_size", "\"q\" has 2 numbers, expected 1 (the problem's dof)"},
      {"nan", "nan", "non-finite number"},
      {"error", "exec_error", "step size too large for my scheme"},
      // Without SIGPIPE blocked for the write, this one would kill the test program.
      {"close_stdin", "exec_died", "stopped reading its input (killed) during a gradient reply"},
  };
  for (const auto& failure : cases) {
    const auto start = std::chrono::steady_clock::now();
    const RunResult result =
        run_one("pendulum", misbehaving(failure.mode, ",timeout=1"), quiet(0.05, 1));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_FALSE(result.ok) << failure.mode;
    EXPECT_EQ(result.record.status, failure.status) << failure.mode;
    EXPECT_NE(result.record.message.value_or("").find(failure.fragment), std::string::npos)
        << failure.mode << ": " << result.record.message.value_or("");
    // Two good steps ran before the process went wrong, and the row says where it stopped.
    EXPECT_EQ(result.record.steps, 2) << failure.mode;
    EXPECT_LT(seconds, 10) << failure.mode;  // the hang is cut at its one-second budget
  }
  expect_no_children();
}

TEST(Exec, BinaryFramesOfTheWrongSizeCodeOrValueAreFailureRows) {
  const std::vector<FailureCase> cases = {
      {"binary_wrong_size", "exec_size", "answered step with 3 values, expected 2"},
      {"binary_nan", "nan", "value 0 is nan"},
      {"binary_text", "exec_malformed", "frame header"},
      {"binary_bad_code", "exec_malformed", "frame header (9, 0)"},
  };
  for (const auto& failure : cases) {
    const RunResult result =
        run_one("pendulum", misbehaving(failure.mode, ",format=binary,timeout=2"), quiet(0.05, 1));
    EXPECT_EQ(result.record.status, failure.status) << failure.mode;
    EXPECT_NE(result.record.message.value_or("").find(failure.fragment), std::string::npos)
        << failure.mode << ": " << result.record.message.value_or("");
    EXPECT_EQ(result.record.steps, 0) << failure.mode;
  }
  expect_no_children();
}

TEST(Exec, BadSpecsAreInputErrorsNamingWhatIsAllowed) {
  using test::input_error_names;
  using Fragments = std::vector<std::string>;
  EXPECT_TRUE(input_error_names(make_integrator, "exec:cmd=/no/such/program",
                                Fragments{"cannot start '/no/such/program'", "No such file"}));
  EXPECT_TRUE(input_error_names(make_integrator,
                                "exec:cmd=" + shell_quoted(GEOMINT_SOURCE_DIR "/README.md"),
                                Fragments{"cannot start", "Permission denied"}));
  EXPECT_TRUE(input_error_names(make_integrator, kCVerlet + "x", Fragments{"format"}));
  EXPECT_TRUE(
      input_error_names(make_integrator, "exec:cmd=a,format=xml", Fragments{"json, binary"}));
  EXPECT_TRUE(input_error_names(make_integrator, "exec:cmd=a,timeout=0", Fragments{"timeout"}));
  EXPECT_TRUE(input_error_names(make_integrator, "exec:cmd=", Fragments{"empty value"}));
  EXPECT_TRUE(
      input_error_names(make_integrator, "exec:format=binary", Fragments{"exec:cmd=PROGRAM"}));
  EXPECT_TRUE(input_error_names(make_integrator, misbehaving("bad_handshake"),
                                Fragments{"flag 'constrained'", "allowed: explicit, implicit"}));
  EXPECT_TRUE(input_error_names(make_integrator, misbehaving("silent_handshake", ",timeout=0.5"),
                                Fragments{"did not answer the handshake within timeout=0.5 s"}));
  // The bare entry (what `geomint list` shows) runs nowhere and says what it needs.
  EXPECT_TRUE(input_error_names(
      [](const std::string& method) { return run_one("kepler", method, quiet(0.01, 1)); }, "exec",
      Fragments{"needs a command: exec:cmd=PROGRAM"}));
  expect_no_children();
}

TEST(Exec, CommandsSplitAtBlanksWithoutAShell) {
  EXPECT_EQ(shell_words("  python3\t-u  my prog.py "),
            (std::vector<std::string>{"python3", "-u", "my", "prog.py"}));
  EXPECT_EQ(shell_words("python3 '/a b (x)/it'\\''s.py' -u"),
            (std::vector<std::string>{"python3", "/a b (x)/it's.py", "-u"}));
  EXPECT_TRUE(shell_words(" \t ").empty());
  // cmd= is split as sh splits it, so an unterminated quote is an input error that says so.
  EXPECT_TRUE(test::input_error_names(make_integrator, "exec:cmd=python3 'unterminated",
                                      std::vector<std::string>{"unterminated"}));
  EXPECT_EQ(describe_wait_status(3 << 8), "exited with status 3");
}

}  // namespace
}  // namespace geomint
