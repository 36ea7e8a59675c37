// The bad-input suite (issue 14; docs/DESIGN.md §4, README "Exit codes"): a registry of command
// lines and scene files, each with the exit code it must give, a word its message must contain and
// the files it may leave behind (none, for bad input). Every case runs the built `geomint` under
// `timeout` (the hang guard): a case that runs past its limit fails as a hang, not by stalling
// the suite. Each case runs in its own scratch folder; after it, the folder must hold exactly the
// files the case wrote there beforehand plus the ones it expects, and the folder's parent
// nothing but the folder, so an output that escapes (a label "../../x") is caught too.
//
// Add a case here for every new option and every new way of rejecting input.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace geomint {
namespace {

namespace fs = std::filesystem;

struct Case {
  std::string name;       // test name suffix (letters, digits, underscores)
  std::string arguments;  // after `geomint`; {dir} is the case's scratch folder
  int exit_code;          // 0 ok, 1 a run failed (a row), 2 bad input
  std::string word;       // the output (stdout + stderr) must contain this
  // Files created in {dir} before the run: relative path → content; a path ending in '/' is a
  // directory.
  std::vector<std::pair<std::string, std::string>> setup = {};
  // Files the run may leave in {dir} (relative paths, directories included). Bad input: none.
  std::set<std::string> outputs = {};
  int timeout_s = 30;  // hang guard
};

std::ostream& operator<<(std::ostream& out, const Case& c) { return out << c.name; }

// A minimal valid scene around one [[runs]] block body (or any text after the title).
std::string scene(const std::string& body) { return "title = 'bad input'\n" + body; }
const std::string kRunBlock =
    "[[runs]]\nlabel = 'a'\nproblems = ['pendulum']\nmethods = ['stormer_verlet']\n";

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

std::set<std::string> children(const fs::path& root) {
  std::set<std::string> out;
  for (const auto& entry : fs::directory_iterator(root)) out.insert(entry.path().filename());
  return out;
}

std::set<std::string> tree(const fs::path& root) {
  std::set<std::string> out;
  if (!fs::exists(root)) return out;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    out.insert(fs::relative(entry.path(), root).string());
  }
  return out;
}

const std::vector<Case>& cases() {
  static const std::vector<Case> all = {
      // --- specs and run options (the original cli_test cases) ---
      {"UnknownMethod", "run --problem pendulum --method nosuch --dt 0.1 --t-end 1", 2,
       "stormer_verlet"},
      {"UnknownProblem", "run --problem nosuch --method rk4 --dt 0.1 --t-end 1", 2, "kepler"},
      {"UnknownMethodKey", "run --problem pendulum --method rk4:colour=red --dt 0.1 --t-end 1", 2,
       "colour"},
      {"NonNumericParameter", "run --problem pendulum:theta0=abc --method rk4 --dt 0.1 --t-end 1",
       2, "theta0"},
      {"OutOfRangeParameter", "run --problem kepler:e=1.5 --method rk4 --dt 0.1 --t-end 1", 2,
       "e=1.5"},
      {"RigidBodyTriangleInequality",
       "run --problem rigid_body:I1=1,I2=1.2,I3=2.5 --method rattle --dt 0.1 --t-end 1", 2,
       "I3 = 2.5 must be < I1 + I2 = 2.2 (triangle inequality"},
      // --- holonomic constraints (applicable(), issue 10): the message names what applies ---
      {"UnconstrainedMethodOnConstrainedProblem",
       "run --problem rod_chain --method stormer_verlet --dt 0.01 --t-end 1", 2,
       "holonomic constraints, which problem 'rod_chain' has; methods that do:"},
      {"ConstrainedMethodOnUnconstrainedProblem",
       "run --problem pendulum --method rattle --dt 0.1 --t-end 1", 2,
       "problem 'pendulum' has none"},
      {"ConstrainedOrderOnUnconstrainedProblem",
       "order --problem kepler --method composition:base=rattle --dt 0.1 --t-end 1", 2,
       "holonomic constraints"},
      {"ZeroDt", "run --problem pendulum --method rk4 --dt 0 --t-end 1", 2, "--dt"},
      {"NegativeDt", "run --problem pendulum --method rk4 --dt -0.1 --t-end 1", 2, "--dt"},
      {"ZeroTEnd", "run --problem pendulum --method rk4 --dt 0.1 --t-end 0", 2, "--t-end"},
      {"NonNumericDt", "run --problem pendulum --method rk4 --dt abc --t-end 1", 2, "--dt"},
      {"MalformedSpec", "run --problem 'pendulum:' --method rk4 --dt 0.1 --t-end 1", 2,
       "malformed"},
      {"TooFewLevels", "order --problem pendulum --method rk4 --dt 0.1 --levels 2 --t-end 1", 2,
       "--levels"},
      {"TooManySteps", "run --problem pendulum --method rk4 --dt 1e-12 --t-end 1", 2,
       "steps is more than"},
      // --- absurd parameter values (range checks) ---
      {"HugeTheta0", "run --problem pendulum:theta0=1e308 --method rk4 --dt 0.1 --t-end 1", 2,
       "theta0"},
      {"HugeOmega", "run --problem harmonic:omega=1e300 --method rk4 --dt 0.1 --t-end 1", 2,
       "omega"},
      {"HugeInitialPosition", "run --problem harmonic:q0=1e200 --method rk4 --dt 0.1 --t-end 1", 2,
       "q0"},
      // --- gates files and result paths (harness/gate.*) ---
      {"GateNanBand",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "NaN",
       {{"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmin = nan\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1\n"}},
       {"g.toml", "s", "s/summary.csv"}},
      {"GateFolderWithoutTables",
       "gate {dir}/g.toml {dir}/empty",
       2,
       "no result table",
       {{"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmin = 0\n"}, {"empty/", ""}},
       {"g.toml", "empty"}},
      {"GateMissingResults",
       "gate {dir}/g.toml {dir}/nosuch.csv",
       2,
       "does not exist",
       {{"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmin = 0\n"}},
       {"g.toml"}},
      {"GateNoneApplies",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "applies",
       {{"g.toml", "[[gate]]\nname = 'a'\nscene = 'other'\ncolumn = 'x'\nmin = 0\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1\n"}},
       {"g.toml", "s", "s/summary.csv"}},
      {"GateFileNotSceneAndTable",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "<scene>/<table>.csv",
       {{"g.toml", "[[gate]]\nname = 'a'\nfile = 'summary.csv'\ncolumn = 'x'\nmin = 0\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1\n"}},
       {"g.toml", "s", "s/summary.csv"}},
      // --- a tolerance far below round-off means "to round-off", not a failure ---
      {"ImplicitToleranceBelowRoundOff",
       "run --problem kepler --method implicit_midpoint:tol=1e-300 --dt 0.01 --t-end 1 "
       "--timing-repeats 0",
       0, ",ok,"},
      // --- caps on counts ---
      {"LevelsCap", "order --problem pendulum --method rk4 --dt 0.1 --levels 100 --t-end 1", 2,
       "--levels"},
      {"TimingRepeatsCap",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --timing-repeats 2147483647", 2,
       "--timing-repeats"},
      {"TimingRepeatsNegative",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --timing-repeats -1", 2,
       "--timing-repeats"},
      {"EveryZero",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --series {dir}/s.csv --every 0", 2,
       "--every"},
      {"ReferenceEveryZero", "reference --problem pendulum --t-end 1 --every 0 --out {dir}/r.csv",
       2, "--every"},
      {"ReferenceEveryNegative",
       "reference --problem pendulum --t-end 1 --every -0.5 --out {dir}/r.csv", 2, "--every"},
      // --- divergence rule ---
      {"DivergeFactorNegative",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --diverge-factor -1", 2,
       "--diverge-factor"},
      {"DivergeFactorNan",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --diverge-factor nan", 2,
       "--diverge-factor"},
      // --- optional metrics ---
      {"MetricUnknown", "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --metric foo", 2,
       "unknown metric 'foo'"},
      // --- outputs: collisions and unwritable targets, reported before any computing (the runs
      // below would take far longer than the timeout if they were computed first) ---
      {"SeriesIsOut",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --series {dir}/x.csv --out "
       "{dir}/x.csv",
       2, "--series"},
      {"OutIsADirectory",
       "run --problem pendulum --method rk4 --dt 1e-7 --t-end 1000 --out {dir}/folder",
       2,
       "--out",
       {{"folder/", ""}},
       {"folder"},
       10},
      {"OutUnderAFile",
       "run --problem pendulum --method rk4 --dt 1e-7 --t-end 1000 --out {dir}/file/out.csv",
       2,
       "--out",
       {{"file", "x"}},
       {"file"},
       10},
      {"SeriesUnderAFile",
       "run --problem pendulum --method rk4 --dt 1e-7 --t-end 1000 --series {dir}/file/s.csv",
       2,
       "--series",
       {{"file", "x"}},
       {"file"},
       10},
      {"OrderOutUnderAFile",
       "order --problem pendulum --method rk4 --dt 1e-4 --levels 3 --t-end 1000 --out "
       "{dir}/file/o.csv",
       2,
       "--out",
       {{"file", "x"}},
       {"file"},
       10},
      {"ReferenceOutUnderAFile",
       "reference --problem pendulum --t-end 1000 --dt 1e-5 --out {dir}/file/r.csv",
       2,
       "--out",
       {{"file", "x"}},
       {"file"},
       10},
      {"SweepOutUnderAFile",
       "sweep {dir}/scene.toml --out {dir}/file/out",
       2,
       "--out",
       {{"file", "x"},
        {"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"file", "scene.toml"},
       10},
      // --- sharded sweeps, merge, slurm (README "Running on a cluster"): refused before any
      // of the long runs below is computed ---
      {"ShardOutOfRange",
       "sweep {dir}/scene.toml --shard 8/8",
       2,
       "--shard",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"ShardNotANumber",
       "sweep {dir}/scene.toml --shard a/8",
       2,
       "--shard",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"ShardsWithoutShardFromEnv",
       "sweep {dir}/scene.toml --shards 8",
       2,
       "--shard-from-env",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"ShardAndShardFromEnv",
       "sweep {dir}/scene.toml --shard 1/8 --shard-from-env --shards 8",
       2,
       "not both",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"TimingOnlyWithNoTiming",
       "sweep {dir}/scene.toml --timing-only --no-timing",
       2,
       "--timing-only",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"TimingOnlyBeforeMerge",
       "sweep {dir}/scene.toml --timing-only",
       2,
       "geomint merge",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"MergeWithoutShards",
       "merge {dir}",
       2,
       "holds no shard",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      // --- verbs and the scene path ---
      {"UnknownVerb", "frobnicate", 2, "unknown command"},
      {"UnknownVerbListsVerbs", "frobnicate", 2, "sweep"},
      {"NoVerb", "", 2, "run"},
      {"SceneIsADirectory", "sweep {dir}/folder", 2, "directory", {{"folder/", ""}}, {"folder"}},
      {"SceneMissing", "sweep {dir}/nosuch.toml", 2, "nosuch.toml"},
      // --- scene files ---
      {"SceneMalformed",
       "sweep {dir}/scene.toml",
       2,
       "malformed",
       {{"scene.toml", "title = 'x'\n[[runs]]\nlabel = 'a'\nproblems = [\n"}},
       {"scene.toml"}},
      {"SceneMissingKey",
       "sweep {dir}/scene.toml",
       2,
       "problems",
       {{"scene.toml", scene("[[runs]]\nlabel = 'a'\nmethods = ['rk4']\ndt = 0.1\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"SceneTableColumnUnknown",
       "sweep {dir}/scene.toml",
       2,
       "energy_error_max",
       {{"scene.toml", "title = 'x'\ntable_columns = ['method', 'energy_error_max']\n" + kRunBlock +
                           "dt = 0.1\nt_end = 1.0\n"}},
       {"scene.toml"}},
      {"SceneNegativeTEnd",
       "sweep {dir}/scene.toml",
       2,
       "t_end",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = -1.0\n")}},
       {"scene.toml"}},
      {"SceneSecondMethodUnknown",
       "sweep {dir}/scene.toml --jobs 2",
       2,
       "rk5",
       {{"scene.toml",
         scene("[[runs]]\nlabel = 'a'\nproblems = ['pendulum']\nmethods = ['rk4', 'rk5']\n"
               "dt = 0.1\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"SceneOrderSecondMethodUnknown",
       "sweep {dir}/scene.toml --jobs 2",
       2,
       "rk5",
       {{"scene.toml",
         scene("[[orders]]\nlabel = 'o'\nproblems = ['pendulum']\nmethods = ['rk4', 'rk5']\n"
               "dt0 = 0.1\nlevels = 3\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"SceneTooManySteps",
       "sweep {dir}/scene.toml --jobs 2",
       2,
       "steps is more than",
       {{"scene.toml", scene(kRunBlock + "dt = [0.1, 1e-12]\nt_end = 1.0\nseries_every = 1\n")}},
       {"scene.toml"}},
      {"SceneQuickTooManySteps",
       "sweep {dir}/scene.toml --quick",
       2,
       "steps is more than",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nquick_dt = 1e-12\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"SceneLabelEscapes",
       "sweep {dir}/scene.toml",
       2,
       "label",
       {{"scene.toml",
         scene("[[runs]]\nlabel = '../../x'\nproblems = ['pendulum']\nmethods = ['rk4']\n"
               "dt = 0.1\nt_end = 1.0\nseries_every = 1\n")}},
       {"scene.toml"}},
      {"SceneLabelWithSlash",
       "sweep {dir}/scene.toml",
       2,
       "label",
       {{"scene.toml", scene("[[runs]]\nlabel = 'a/b'\nproblems = ['pendulum']\nmethods = ['rk4']\n"
                             "dt = 0.1\nt_end = 1.0\nseries_every = 1\n")}},
       {"scene.toml"}},
      {"SceneLabelDotDot",
       "sweep {dir}/scene.toml",
       2,
       "label",
       {{"scene.toml",
         scene("[[orders]]\nlabel = '..'\nproblems = ['pendulum']\nmethods = ['rk4']\n"
               "dt0 = 0.1\nlevels = 3\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"SceneLevelsBeyondInt",
       "sweep {dir}/scene.toml",
       2,
       "levels",
       {{"scene.toml", scene("[[orders]]\nlabel = 'o'\nproblems = ['pendulum']\nmethods = ['rk4']\n"
                             "dt0 = 0.1\nlevels = 4294967299\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"SceneTimingRepeatsBeyondInt",
       "sweep {dir}/scene.toml",
       2,
       "timing_repeats",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ntiming_repeats = 4294967296\n")}},
       {"scene.toml"}},
      {"SceneTimingRepeatsCap",
       "sweep {dir}/scene.toml",
       2,
       "timing_repeats",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ntiming_repeats = 100000\n")}},
       {"scene.toml"}},
      {"SceneSeriesEveryNegative",
       "sweep {dir}/scene.toml",
       2,
       "series_every",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\nseries_every = -1\n")}},
       {"scene.toml"}},
      {"SceneQuickTEndNegative",
       "sweep {dir}/scene.toml --quick",
       2,
       "quick_t_end",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\nquick_t_end = -5.0\n")}},
       {"scene.toml"}},
      {"SceneQuickTEndNegativeNotQuick",
       "sweep {dir}/scene.toml",
       2,
       "quick_t_end",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\nquick_t_end = -5.0\n")}},
       {"scene.toml"}},
      {"SceneQuickLevelsZero",
       "sweep {dir}/scene.toml --quick",
       2,
       "quick_levels",
       {{"scene.toml", scene("[[orders]]\nlabel = 'o'\nproblems = ['pendulum']\nmethods = ['rk4']\n"
                             "dt0 = 0.1\nlevels = 3\nquick_levels = 0\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"SceneDivergeFactorNegative",
       "sweep {dir}/scene.toml",
       2,
       "diverge_factor",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ndiverge_factor = -1.0\n")}},
       {"scene.toml"}},
      {"SceneStabilityTinyHMin",
       "sweep {dir}/scene.toml",
       2,
       "h_min",
       {{"scene.toml",
         scene("[[stability]]\nlabel = 's'\nproblems = ['harmonic']\nmethods = ['rk4']\n"
               "h_min = 1e-9\nh_max = 1.0\nt_end = 100.0\n")}},
       {"scene.toml"}},
      {"SceneStabilityMinStepsBeyondInt",
       "sweep {dir}/scene.toml",
       2,
       "scan_points_per_decade",
       {{"scene.toml",
         scene("[[stability]]\nlabel = 's'\nproblems = ['harmonic']\nmethods = ['rk4']\n"
               "scan_points_per_decade = 4294967297\n")}},
       {"scene.toml"}},
      // --- runs that must end as failure rows within the step budget, not hang ---
      {"GslRk8pdTightToleranceEnds",
       "run --problem kepler --method gsl_rk8pd:rtol=1e-300,atol=1e-300 --t-end 20 "
       "--timing-repeats 0",
       1,
       "too much accuracy",
       {},
       {},
       60},
      {"GslMsbdfTightToleranceEnds",
       "run --problem kepler --method gsl_msbdf:rtol=1e-300,atol=1e-300 --t-end 20 "
       "--timing-repeats 0",
       1,
       "too much accuracy",
       {},
       {},
       60},
      {"OdeintDopri5TightToleranceEnds",
       "run --problem kepler --method odeint_dopri5:rtol=1e-300,atol=1e-300 --t-end 20 "
       "--timing-repeats 0",
       1,
       "too much accuracy",
       {},
       {},
       60},
      {"OdeintRosenbrock4TightToleranceEnds",
       "run --problem kepler --method odeint_rosenbrock4:rtol=1e-300,atol=1e-300 --t-end 20 "
       "--timing-repeats 0",
       1,
       "too much accuracy",
       {},
       {},
       60},
      {"GslRk4impTightToleranceEnds",
       "run --problem kepler --method gsl_rk4imp:rtol=1e-300,atol=1e-300 --t-end 20 "
       "--timing-repeats 0",
       1,
       "too much accuracy",
       {},
       {},
       60},
      {"OdeintDopri5HugeHorizonEnds",
       "run --problem kepler --method odeint_dopri5:max_steps=20000 --t-end 1e9 --timing-repeats 0",
       1,
       "max_steps",
       {},
       {},
       60},
      {"GslRk8pdHugeHorizonEnds",
       "run --problem kepler --method gsl_rk8pd:max_steps=20000 --t-end 1e9 --timing-repeats 0",
       1,
       "max_steps",
       {},
       {},
       60},
      {"CvodeHugeHorizonEnds",
       "run --problem kepler --method cvode_adams:max_steps=20000 --t-end 1e9 --timing-repeats 0",
       1,
       "max_steps",
       {},
       {},
       60},
      {"IdaTightToleranceSaysTolerance",
       "run --problem kepler --method ida:rtol=1e-300,atol=1e-300 --t-end 20 --timing-repeats 0",
       1,
       "too much accuracy",
       {},
       {},
       60},
      {"WrapperMaxStepsZero", "run --problem kepler --method gsl_rk8pd:max_steps=0 --t-end 1", 2,
       "max_steps"},
      // --- a sweep with a failing run writes its rows and exits 0 ---
      {"SweepWithFailureRowsExitsZero",
       "sweep {dir}/scene.toml --jobs 2",
       0,
       "1 failed run",
       {{"scene.toml",
         scene("[[runs]]\nlabel = 'a'\nproblems = ['kepler']\n"
               "methods = ['odeint_dopri5:max_steps=100', 'rk4']\ndt = 0.1\nt_end = 20.0\n"
               "timing_repeats = 0\nseries_every = 10\n")}},
       {"scene.toml", "summary.csv", "table.md", "series", "series/a",
        "series/a/odeint_dopri5_max_steps_100.csv", "series/a/rk4.csv"},
       60},
  };
  return all;
}

// The binary under test: $GEOMINT_BAD_INPUT_BINARY when set (to run the registry against
// another build, e.g. an older one), else the one built with this suite.
std::string binary() {
  const char* other = std::getenv("GEOMINT_BAD_INPUT_BINARY");
  return other && *other ? other : GEOMINT_BINARY;
}

std::string fmt_command(const Case& c, const fs::path& dir) {
  return "timeout -k 5 " + std::to_string(c.timeout_s) + " " + binary() + " " +
         replace_all(c.arguments, "{dir}", dir.string()) + " 2>&1";
}

class BadInput : public testing::TestWithParam<Case> {};

TEST_P(BadInput, ExitCodeMessageAndNoStrayFiles) {
  const Case& c = GetParam();
  const fs::path base = fs::temp_directory_path() / "geomint_bad_input" / c.name;
  const fs::path dir = base / "work";
  fs::remove_all(base);
  fs::create_directories(dir);
  std::set<std::string> expected = c.outputs;
  for (const auto& [path, content] : c.setup) {
    if (path.back() == '/') {
      fs::create_directories(dir / path);
    } else {
      std::ofstream(dir / path) << content;
    }
  }
  const std::string command = fmt_command(c, dir);
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  ASSERT_NE(code, 124) << "hang: still running after " << c.timeout_s << " s: " << command;
  ASSERT_NE(code, 137) << "hang: killed after " << c.timeout_s << " s: " << command;
  EXPECT_EQ(code, c.exit_code) << command << "\n" << output;
  EXPECT_NE(output.find(c.word), std::string::npos)
      << "message lacks '" << c.word << "': " << command << "\n"
      << output;
  EXPECT_EQ(tree(dir), expected) << command << "\n" << output;
  EXPECT_EQ(children(base), std::set<std::string>({"work"}))
      << "files outside the case folder: " << command;
  for (const auto& entry : tree(dir)) {
    EXPECT_EQ(entry.find(".tmp"), std::string::npos) << "temporary file left: " << entry;
  }
  fs::remove_all(base);
}

INSTANTIATE_TEST_SUITE_P(Cli, BadInput, testing::ValuesIn(cases()),
                         [](const testing::TestParamInfo<Case>& info) { return info.param.name; });

TEST(BadInputRegistry, NamesAreUniqueAndEveryCaseHasAWord) {
  std::set<std::string> names;
  for (const auto& c : cases()) {
    EXPECT_TRUE(names.insert(c.name).second) << c.name;
    EXPECT_FALSE(c.word.empty()) << c.name;
    EXPECT_TRUE(c.exit_code == 0 || c.exit_code == 1 || c.exit_code == 2) << c.name;
  }
}

}  // namespace
}  // namespace geomint
