// The bad-input suite (docs/DESIGN.md §4, docs/USAGE.md "Exit codes"): a registry of
// command lines and scene files, each with the exit code it must give, a word its message must
// contain and the files it may leave behind (none, for bad input). Every case runs the built
// `geomint` under `timeout` (the hang guard): a case that runs past its limit fails as a hang, not
// by stalling the suite. Each case runs in its own scratch folder; after it, the folder must hold
// exactly the files the case wrote there beforehand plus the ones it expects, and the folder's
// parent nothing but the folder, so an output that escapes (a label "../../x") is caught too.
//
// Add a case here for every new option and every new way of rejecting input.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "harness/paths.hpp"
#include "harness/table.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace bad_input_test {
namespace {

namespace fs = std::filesystem;
using test::npy_file;

struct Case {
  std::string name;       // test name suffix (letters, digits, underscores)
  std::string arguments;  // after `geomint`; {dir} is the case's scratch folder
  int exit_code;          // 0 ok, 1 a run failed (a row), 2 bad input
  std::string word;       // the output (stdout + stderr) must contain this
  // Files created in {dir} before the run: relative path → content; a path ending in '/' is a
  // directory; {tag} in a path is this machine's temporary_host_tag().
  std::vector<std::pair<std::string, std::string>> setup = {};
  // Files the run may leave in {dir} (relative paths, directories included). Bad input: none.
  std::set<std::string> outputs = {};
  int timeout_s = 30;            // hang guard
  std::string environment = {};  // "NAME=value ..." set for the run (env(1)), e.g. GEOMINT_THREADS
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

// A Google Benchmark JSON document with one benchmark measured once per value (microseconds).
std::string bench_json(const std::vector<double>& times_us) {
  std::string rows;
  for (std::size_t i = 0; i < times_us.size(); ++i) {
    rows += (i ? ",\n" : "") + std::string("{\"name\": \"BM_Step\", \"run_name\": \"BM_Step\", ") +
            "\"run_type\": \"iteration\", \"repetitions\": " + std::to_string(times_us.size()) +
            ", \"iterations\": 100, \"real_time\": " + std::to_string(times_us[i]) +
            ", \"cpu_time\": " + std::to_string(times_us[i]) + ", \"time_unit\": \"us\"}";
  }
  return "{\"context\": {\"commit\": \"abc\"},\n\"benchmarks\": [\n" + rows + "\n]}\n";
}
const std::string kBenchJson = bench_json({10, 11, 12, 10.5, 11.5, 10.2});

const std::string kPendulumNpyDict = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }";
const std::vector<double> kPendulumRows = {0, 0.5, 0, 0.1, 0.49, 0.1};
const std::string kPendulumNpy = npy_file(kPendulumNpyDict, kPendulumRows);
// A valid pendulum trajectory (its default initial state θ0 = 0.5, p0 = 0) in CSV.
const std::string kPendulumCsv = "t,q0,p0\n0,0.5,0\n0.1,0.49,-0.05\n";
const std::string kScore = "score --problem pendulum --out {dir}/out.csv ";

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
      {"TodaPeriodicTooFewParticles", "run --problem toda:n=2 --method rk4 --dt 0.1 --t-end 1", 2,
       "[3, 100000] for ends=periodic"},
      {"TodaDisplacementOutOfRange",
       "run --problem toda:displacement=60 --method rk4 --dt 0.1 --t-end 1", 2,
       "|displacement| <= 50"},
      {"TodaCouplingNotPositive", "run --problem toda:alpha=0 --method rk4 --dt 0.1 --t-end 1", 2,
       "alpha=0 is out of range (allowed: > 0)"},
      {"ElasticRodModeAboveElements",
       "run --problem elastic_rod:elements=4,mode=5,amplitude=0.1 --method rk4 --dt 0.1 --t-end 1",
       2, "mode=5 must be in [1, 4] for elements=4"},
      {"ElasticRodAtRestWithoutLoad",
       "run --problem elastic_rod:load=0 --method rk4 --dt 0.1 --t-end 1", 2,
       "give a load != 0 or an amplitude != 0"},
      {"ElasticRodTooManyElements",
       "run --problem elastic_rod:elements=5000 --method rk4 --dt 0.1 --t-end 1", 2, "elements"},
      {"UnknownIntegrableMetric",
       "run --problem kepler --method rk4 --dt 0.1 --t-end 1 --metric lrl_err", 2, "lrl_err_max"},
      {"UnknownLinearSolver",
       "run --problem elastic_bar:nx=2,ny=1,nz=1 --method hp:linear_solver=cg_amgx --dt 0.01 "
       "--t-end 0.01",
       2, "auto, ldlt, ldlt_metis, cholmod, cg, cg_ichol, cg_amg"},
      {"RigidBodyTriangleInequality",
       "run --problem rigid_body:I1=1,I2=1.2,I3=2.5 --method rattle --dt 0.1 --t-end 1", 2,
       "I3 = 2.5 must be < I1 + I2 = 2.2 (triangle inequality"},
      // A flat body runs as Euler's equations; the 9-coordinate form says why it cannot.
      {"RigidBodyFlatBodyHasASingularMassTensor",
       "run --problem rigid_body:I1=1,I2=2,I3=3 --method rattle --dt 0.1 --t-end 1", 2,
       "I3 = 3 equals I1 + I2 (a flat body, a lamina): its mass d3 = (I1+I2+I3)/2 - I3 is 0, so "
       "the mass tensor of the 9-coordinate form is singular"},
      {"HeavyTopOutsideTheTriangleInequality",
       "run --problem heavy_top:I1=2,I2=1,I3=0.6666666666666666 --method rattle --dt 0.1 "
       "--t-end 1",
       2, "I1 = 2 must be < I2 + I3"},
      // Euler's equations need positive moments only: zero, negative and NaN still refused.
      {"RigidBodyEulerZeroMoment",
       "run --problem rigid_body_euler:I1=2,I2=1,I3=0 --method rk4 --dt 0.1 --t-end 1", 2,
       "I3=0 is out of range (allowed: > 0)"},
      {"RigidBodyEulerNegativeMoment",
       "run --problem rigid_body_euler:I1=-2,I2=1,I3=1 --method rk4 --dt 0.1 --t-end 1", 2,
       "I1=-2 is out of range (allowed: > 0)"},
      {"RigidBodyEulerNanMoment",
       "run --problem rigid_body_euler:I1=2,I2=nan,I3=1 --method rk4 --dt 0.1 --t-end 1", 2,
       "I2='nan' is not a finite number"},
      // --- the Lie–Poisson splitting runs on free rigid bodies only (applicable()) ---
      {"LiePoissonOnKepler", "run --problem kepler --method lie_poisson --dt 0.1 --t-end 1", 2,
       "integrates free rigid bodies only (rigid_body, rigid_body_euler"},
      {"LiePoissonOrderThree",
       "run --problem rigid_body_euler --method lie_poisson:order=3 --dt 0.1 --t-end 1", 2,
       "order"},
      // --- the SPRK family: a table name from its list, conservative problems only ---
      {"SprkUnknownTable", "run --problem kepler --method sprk:table=mclachlan7 --dt 0.1 --t-end 1",
       2, "table='mclachlan7' is not allowed (allowed: euler1"},
      {"SprkWithAForce", "run --problem damped_oscillator --method sprk --dt 0.1 --t-end 1", 2,
       "integrates conservative systems only (its step follows a Hamiltonian H(q, p) and has no "
       "term for a force); problem 'damped_oscillator'"},
      // --- the RKN families: a table or pair from their lists, conservative problems only ---
      {"RknUnknownTable", "run --problem kepler --method rkn:table=dprkn7 --dt 0.1 --t-end 1", 2,
       "table='dprkn7' is not allowed (allowed: nystrom4"},
      {"RknAdaptivePairWithoutEmbedding",
       "run --problem kepler --method rkn_adaptive:pair=nystrom4 --t-end 1", 2,
       "pair='nystrom4' is not allowed (allowed: dprkn4"},
      {"RknWithAForce", "run --problem damped_oscillator --method rkn --dt 0.1 --t-end 1", 2,
       "integrates conservative systems only"},
      {"QuaternionOnHeavyTop", "run --problem heavy_top --method quaternion --dt 0.1 --t-end 1", 2,
       "integrates free rigid bodies only (rigid_body, rigid_body_euler"},
      {"QuaternionUnknownBase",
       "run --problem rigid_body --method quaternion:base=rk5 --dt 0.1 --t-end 1", 2, "rk4"},
      // --- physics-engine methods (engines/): their options and the problems they model ---
      {"MujocoUnknownIntegrator",
       "run --problem pendulum --method mujoco:integrator=rk5 --dt 0.1 --t-end 1", 2,
       "(allowed: euler, rk4, implicit)"},
      {"MujocoUnknownDefaults",
       "run --problem pendulum --method mujoco:defaults=tuned --dt 0.1 --t-end 1", 2,
       "(allowed: clean, shipped)"},
      {"MujocoUnknownKey", "run --problem pendulum --method mujoco:damping=0 --dt 0.1 --t-end 1", 2,
       "damping"},
      {"MujocoOnAProblemItDoesNotModel", "run --problem kepler --method mujoco --dt 0.1 --t-end 1",
       2, "problems that apply: pendulum, double_pendulum, rod_chain:coordinates=joint"},
      {"MujocoOnCartesianRodChain",
       "run --problem rod_chain --method mujoco:integrator=rk4 --dt 0.01 --t-end 1", 2,
       "(rod_chain:coordinates=joint)"},
      {"OdeUnknownStep", "run --problem pendulum --method ode:step=dense --dt 0.1 --t-end 1", 2,
       "(allowed: world, quick)"},
      {"OdeOnAProblemItDoesNotModel", "run --problem harmonic --method ode --dt 0.1 --t-end 1", 2,
       "problems that apply: pendulum, double_pendulum, rod_chain:coordinates=joint, "
       "spherical_pendulum, spherical_pendulum:coordinates=angles, heavy_top, rigid_body"},
      {"MujocoOnATopNoBodyHas",
       "run --problem heavy_top:I1=0.3,I2=0.3,I3=0.5,chi3=1 --method mujoco --dt 0.01 --t-end 1", 2,
       "not those of a mass distribution"},
      {"BulletUnknownIntegrator",
       "run --problem pendulum --method bullet:integrator=implicit --dt 0.1 --t-end 1", 2,
       "(allowed: euler, rk4)"},
      {"BulletUnknownGyro", "run --problem rigid_body --method bullet:gyro=semi --dt 0.1 --t-end 1",
       2, "(allowed: none, explicit, implicit_body, implicit_world)"},
      {"BulletRk4OnTheFreeBody",
       "run --problem rigid_body --method bullet:integrator=rk4 --dt 0.1 --t-end 1", 2,
       "the free body (rigid_body) is a btRigidBody"},
      {"BulletGyroOnAMultiBody",
       "run --problem heavy_top --method bullet:gyro=explicit --dt 0.1 --t-end 1", 2,
       "only the free body (rigid_body) is"},
      {"DartUnknownIntegrator",
       "run --problem pendulum --method dart:integrator=implicit --dt 0.1 --t-end 1", 2,
       "(allowed: world, semi_implicit_euler, euler, rk4)"},
      {"DartChainLongerThanItBuilds",
       "run --problem rod_chain:coordinates=joint,n=2048 --method dart --dt 0.01 --t-end 1", 2,
       "builds chains of at most 1024 links"},
      // --- holonomic constraints (applicable()): the message names what applies ---
      {"UnconstrainedMethodOnConstrainedProblem",
       "run --problem rod_chain --method stormer_verlet --dt 0.01 --t-end 1", 2,
       "holonomic constraints, which problem 'rod_chain' has; methods that do:"},
      {"ConstrainedMethodOnUnconstrainedProblem",
       "run --problem pendulum --method rattle --dt 0.1 --t-end 1", 2,
       "problem 'pendulum' has none"},
      // --- the general Lagrangian kind (is_non_separable): separable-only methods
      // refused ---
      {"VerletOnNonSeparableProblem",
       "run --problem double_pendulum --method stormer_verlet --dt 0.01 --t-end 1", 2,
       "theta2=-0.2' is non-separable"},
      {"SymplecticEulerOnPolarKepler",
       "run --problem kepler:coordinates=polar --method symplectic_euler_a --dt 0.01 --t-end 1", 2,
       "assumes a separable Lagrangian"},
      {"NewmarkOnNonSeparableProblem",
       "run --problem double_pendulum --method newmark --dt 0.01 --t-end 1", 2, "non-separable"},
      {"CompositionOfVerletOnNonSeparableProblem",
       "order --problem double_pendulum --method composition --dt 0.01 --t-end 1", 2,
       "non-separable"},
      {"RattleOnUnconstrainedProblem",
       "run --problem double_pendulum --method rattle --dt 0.01 --t-end 1", 2,
       "is for problems with holonomic constraints"},
      {"HpMinimizeOnNonSeparableProblem",
       "run --problem double_pendulum --method hp:solver=minimize --dt 0.01 --t-end 1", 2,
       "needs the step to be the minimiser of a scalar E_k(v)"},
      {"HpMinimizeOnPolarKepler",
       "run --problem kepler:coordinates=polar --method hp:alpha=0.25,solver=minimize --dt 0.01 "
       "--t-end 1",
       2, "on a general L(q, v) it is not"},
      {"HpLeftRuleOnNonSeparableProblem",
       "run --problem double_pendulum --method hp:alpha=0,solver=newton --dt 0.01 --t-end 1", 2,
       "assumes a separable Lagrangian"},
      // --- the generalized leapfrog and Tao's method ---
      {"TaoOrderThree", "run --problem double_pendulum --method tao:order=3 --dt 0.01 --t-end 1", 2,
       "order='3' is not allowed (allowed: 2, 4)"},
      {"TaoNegativeCoupling",
       "run --problem double_pendulum --method tao:omega=-1 --dt 0.01 --t-end 1", 2, ">= 0"},
      {"TaoOnConstrainedProblem", "run --problem rod_chain --method tao --dt 0.01 --t-end 1", 2,
       "does not handle holonomic constraints"},
      // The reason is the force, not separability (the leapfrog runs non-separable H).
      {"LeapfrogOnForcedProblem",
       "run --problem damped_oscillator --method generalized_leapfrog --dt 0.01 --t-end 1", 2,
       "integrates conservative systems only (its step follows a Hamiltonian H(q, p) and has no "
       "term for a force); problem 'damped_oscillator' has a non-conservative force"},
      {"TaoOnForcedProblem", "run --problem damped_oscillator --method tao --dt 0.01 --t-end 1", 2,
       "integrates conservative systems only (its step follows a Hamiltonian H(q, p)"},
      {"LeapfrogZeroIterations",
       "run --problem double_pendulum --method generalized_leapfrog:max_iter=0 --dt 0.01 --t-end 1",
       2, "max_iter=0 is out of range"},
      // --- the charged particle and the Boris pusher ---
      {"BorisOnAnotherProblem", "run --problem double_pendulum --method boris --dt 0.01 --t-end 1",
       2, "integrates charged particles only"},
      {"VerletOnChargedParticle",
       "run --problem charged_particle --method stormer_verlet --dt 0.01 --t-end 1", 2,
       "non-separable"},
      {"ChargedParticleWithoutCharge", "run --problem charged_particle:charge=0 --method boris", 2,
       "charge"},
      {"ChargedParticleWithoutField", "run --problem charged_particle:B=0 --method boris", 2,
       "!= 0"},
      {"ChargedParticleNegativeMass", "run --problem charged_particle:mass=-1 --method boris", 2,
       "> 0"},
      {"ChargedParticleBottleLength",
       "run --problem charged_particle:field=bottle,length=0 --method boris", 2, "length"},
      {"TrapezoidDelOnNonSeparableProblem",
       "run --problem kepler:coordinates=polar --method del:rule=trapezoid --dt 0.01 --t-end 1", 2,
       "non-separable"},
      {"SphericalPendulumAnglesOnThePole",
       "run --problem spherical_pendulum:coordinates=angles,theta0=0 --method del", 2, "pole"},
      {"SphericalPendulumAnglesOnTheUpperPole",
       "run --problem spherical_pendulum:coordinates=angles,theta0=3.141592653589793 --method rk4",
       2, "pole"},
      {"SpringPendulumAtTheOrigin", "run --problem spring_pendulum:r0=0 --method del", 2, "r0"},
      {"RodChainUnknownCoordinates", "run --problem rod_chain:coordinates=polar --method del", 2,
       "joint"},
      // --initial on the general kind runs (p = M(q)v + a); a start where M(q) is singular does
      // not.
      {"InitialStateOnThePoleOfTheAngles",
       "run --problem spherical_pendulum:coordinates=angles --method del --initial {dir}/start.csv "
       "--dt 0.01 --t-end 1",
       2,
       "is not positive definite at the given q (a coordinate singularity",
       {{"start.csv", "q,v\n0,0.1\n0.2,0.3\n"}},
       {"start.csv"}},
      {"InitialStateAtTheOriginOfPolarKepler",
       "run --problem kepler:coordinates=polar --method rk4 --initial {dir}/start.csv --dt 0.01 "
       "--t-end 1",
       2,
       "q = 0 is out of range for r (the radius) of problem 'kepler:coordinates=polar,e=0.6' "
       "(allowed: > 0)",
       {{"start.csv", "q,p\n0,0.1\n0.2,0.3\n"}},
       {"start.csv"}},
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
      // Included gates files (results/gates.toml includes results/<scene>/gates.toml): each
      // message names the file at fault.
      {"GateIncludeMissing",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "nosuch/gates.toml",
       {{"g.toml", "include = ['nosuch/gates.toml']\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1\n"}},
       {"g.toml", "s", "s/summary.csv"}},
      {"GateIncludePatternMatchesNothing",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "matches no file",
       {{"g.toml", "include = ['*/gates.toml']\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1\n"}},
       {"g.toml", "s", "s/summary.csv"}},
      {"GateIncludeCycle",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "cycle",
       {{"g.toml", "include = ['s/gates.toml']\n"},
        {"s/", ""},
        {"s/gates.toml", "include = ['../g.toml']\n"},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1\n"}},
       {"g.toml", "s", "s/gates.toml", "s/summary.csv"}},
      {"GateNameInTwoIncludedFiles",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "also in gates file",
       {{"g.toml", "include = ['a.toml', 'b.toml']\n"},
        {"a.toml", "[[gate]]\nname = 'same'\ncolumn = 'x'\nmin = 0\n"},
        {"b.toml", "[[gate]]\nname = 'same'\ncolumn = 'x'\nmax = 9\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1\n"}},
       {"g.toml", "a.toml", "b.toml", "s", "s/summary.csv"}},
      {"GateOfAnotherSceneInASceneFolder",
       "gate {dir}/s {dir}/s/summary.csv",
       2,
       "not the scene of the folder",
       {{"s/", ""},
        {"s/scene.toml", "name = 's'\n"},
        {"s/gates.toml", "[[gate]]\nname = 'a'\nscene = 'other'\ncolumn = 'x'\nmin = 0\n"},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1\n"}},
       {"s", "s/scene.toml", "s/gates.toml", "s/summary.csv"}},
      {"GateFolderWithoutGatesFile",
       "gate {dir}/s",
       2,
       "s/gates.toml",
       {{"s/", ""}, {"s/summary.csv", "# scene: s\nlabel,x\na,1\n"}},
       {"s", "s/summary.csv"}},
      {"GateWithoutResults",
       "gate {dir}/g.toml",
       2,
       "give the results",
       {{"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmin = 0\n"}},
       {"g.toml"}},
      // --- the results site (harness/report.*, docs/REPORT.md): nothing written on bad input ---
      {"ReportResultsNotAFolder", "report --results {dir}/nosuch --out {dir}/site", 2,
       "not a folder"},
      {"ReportNoScene",
       "report --results {dir}/r --out {dir}/site",
       2,
       "no scene",
       {{"r/", ""}},
       {"r"}},
      {"ReportOutIsNotItsSite",
       "report --results {dir}/r --out {dir}/site",
       2,
       ".geomint-report",
       {{"r/", ""},
        {"r/s/", ""},
        {"r/s/scene.toml", "title = 'x'\n"},
        {"site/", ""},
        {"site/notes.txt", "mine"}},
       {"r", "r/s", "r/s/scene.toml", "site", "site/notes.txt"}},
      {"ReportOutIsAFile",
       "report --results {dir}/r --out {dir}/site",
       2,
       "is a file",
       {{"r/", ""}, {"r/s/", ""}, {"r/s/scene.toml", "title = 'x'\n"}, {"site", "x"}},
       {"r", "r/s", "r/s/scene.toml", "site"}},
      {"ReportBadGates",
       "report --results {dir}/r --gates {dir}/g.toml --out {dir}/site",
       2,
       "NaN",
       {{"r/", ""},
        {"r/s/", ""},
        {"r/s/scene.toml", "title = 'x'\n"},
        {"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmin = nan\n"}},
       {"r", "r/s", "r/s/scene.toml", "g.toml"}},
      {"ReportMalformedScene",
       "report --results {dir}/r --out {dir}/site",
       2,
       "malformed",
       {{"r/", ""}, {"r/s/", ""}, {"r/s/scene.toml", "title = \n"}},
       {"r", "r/s", "r/s/scene.toml"}},
      {"ReportDamagedTable",
       "report --results {dir}/r --out {dir}/site",
       2,
       "summary.csv",
       {{"r/", ""},
        {"r/s/", ""},
        {"r/s/scene.toml", "title = 'x'\n"},
        {"r/s/summary.csv", "label,x\na,1,2\n"}},
       {"r", "r/s", "r/s/scene.toml", "r/s/summary.csv"}},
      // figures.toml (docs/REPORT.md "Figure captions") is read whole before anything is written.
      {"ReportFiguresTomlUnknownKey",
       "report --results {dir}/r --out {dir}/site",
       2,
       "figures.toml: [[figure]] 'a.png': unknown key 'colour'",
       {{"r/", ""},
        {"r/s/", ""},
        {"r/s/scene.toml", "title = 'x'\n"},
        {"r/s/a.png", "png"},
        {"r/s/figures.toml", "[[figure]]\nfile = 'a.png'\ncaption = 'c'\ncolour = 1\n"}},
       {"r", "r/s", "r/s/scene.toml", "r/s/a.png", "r/s/figures.toml"}},
      {"ReportFiguresTomlEmptyCaption",
       "report --results {dir}/r --out {dir}/site",
       2,
       "key 'caption' is empty",
       {{"r/", ""},
        {"r/s/", ""},
        {"r/s/scene.toml", "title = 'x'\n"},
        {"r/s/a.png", "png"},
        {"r/s/figures.toml", "[[figure]]\nfile = 'a.png'\ncaption = ''\n"}},
       {"r", "r/s", "r/s/scene.toml", "r/s/a.png", "r/s/figures.toml"}},
      {"ReportFiguresTomlMissingFigure",
       "report --results {dir}/r --out {dir}/site",
       2,
       "no such figure 'b.png'",
       {{"r/", ""},
        {"r/s/", ""},
        {"r/s/scene.toml", "title = 'x'\n"},
        {"r/s/a.png", "png"},
        {"r/s/figures.toml", "[[figure]]\nfile = 'b.png'\ncaption = 'c'\n"}},
       {"r", "r/s", "r/s/scene.toml", "r/s/a.png", "r/s/figures.toml"}},
      {"ReportClaimsMissing",
       "report --results {dir}/r --claims {dir}/nosuch.md --out {dir}/site",
       2,
       "nosuch.md",
       {{"r/", ""}, {"r/s/", ""}, {"r/s/scene.toml", "title = 'x'\n"}},
       {"r", "r/s", "r/s/scene.toml"}},
      // --out is replaced whole: refused, before anything is written, when that would delete the
      // working folder or the input, or when no file can be created there.
      {"ReportOutWithTrailingSlash",  // `make report SITE=site/`: the previous site is replaced
       "report --results {dir}/r --out {dir}/site/",
       0,
       "open",
       {{"r/", ""},
        {"r/s/", ""},
        {"r/s/scene.toml", "title = 'x'\n"},
        {"site/", ""},
        {"site/.geomint-report", ""},
        {"site/index.html", "old"}},
       {"r", "r/s", "r/s/scene.toml", "site", "site/.geomint-report", "site/index.html",
        "site/style.css", "site/s", "site/s/index.html"}},
      {"ReportOutEmpty",  // refused for every option (harden_options), before report's own check
       "report --results {dir}/r --out ''",
       2,
       "--out: an empty value is not allowed",
       {{"r/", ""}, {"r/s/", ""}, {"r/s/scene.toml", "title = 'x'\n"}},
       {"r", "r/s", "r/s/scene.toml"}},
      {"ReportOutIsTheCurrentFolder",  // run inside a previous site: `--out .` deleted it
       "report --results {dir}/r --out .",
       2,
       "the current folder",
       {{".geomint-report", ""}, {"r/", ""}, {"r/s/", ""}, {"r/s/scene.toml", "title = 'x'\n"}},
       {".geomint-report", "r", "r/s", "r/s/scene.toml"}},
      {"ReportOutAboveTheCurrentFolder",
       "report --results {dir}/r --out ..",
       2,
       "the current folder",
       {{"r/", ""}, {"r/s/", ""}, {"r/s/scene.toml", "title = 'x'\n"}},
       {"r", "r/s", "r/s/scene.toml"}},
      {"ReportOutHoldsTheResults",  // results kept inside a previous site
       "report --results {dir}/site/r --out {dir}/site",
       2,
       "the results folder",
       {{"site/", ""},
        {"site/.geomint-report", ""},
        {"site/r/", ""},
        {"site/r/s/", ""},
        {"site/r/s/scene.toml", "title = 'x'\n"}},
       {"site", "site/.geomint-report", "site/r", "site/r/s", "site/r/s/scene.toml"}},
      {"ReportOutHoldsTheGates",
       "report --results {dir}/r --gates {dir}/site/g.toml --out {dir}/site",
       2,
       "the gates file",
       {{"r/", ""},
        {"r/s/", ""},
        {"r/s/scene.toml", "title = 'x'\n"},
        {"site/", ""},
        {"site/.geomint-report", ""},
        {"site/g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmin = 0\n"}},
       {"r", "r/s", "r/s/scene.toml", "site", "site/.geomint-report", "site/g.toml"}},
      {"ReportOutInProc",
       "report --results {dir}/r --out /proc/geomint-site",
       2,
       "no file can be created in folder '/proc'",
       {{"r/", ""}, {"r/s/", ""}, {"r/s/scene.toml", "title = 'x'\n"}},
       {"r", "r/s", "r/s/scene.toml"}},
      {"ReportOutUnderAFile",
       "report --results {dir}/r --out {dir}/file/site",
       2,
       "is not a directory",
       {{"r/", ""}, {"r/s/", ""}, {"r/s/scene.toml", "title = 'x'\n"}, {"file", "x"}},
       {"r", "r/s", "r/s/scene.toml", "file"}},
      // A scene folder named like a file of the site would overwrite it (or fail half-way).
      {"ReportSceneNamedIndexHtml",
       "report --results {dir}/r --out {dir}/site",
       2,
       "r/index.html' has the name of a file of the site",
       {{"r/", ""}, {"r/index.html/", ""}, {"r/index.html/scene.toml", "title = 'x'\n"}},
       {"r", "r/index.html", "r/index.html/scene.toml"}},
      {"ReportSceneNamedStyleCss",
       "report --results {dir}/r --out {dir}/site",
       2,
       "r/style.css' has the name of a file of the site",
       {{"r/", ""}, {"r/style.css/", ""}, {"r/style.css/scene.toml", "title = 'x'\n"}},
       {"r", "r/style.css", "r/style.css/scene.toml"}},
      {"ReportSceneNamedLikeTheMarker",
       "report --results {dir}/r --out {dir}/site",
       2,
       "r/.geomint-report' has the name of a file of the site",
       {{"r/", ""}, {"r/.geomint-report/", ""}, {"r/.geomint-report/scene.toml", "title = 'x'\n"}},
       {"r", "r/.geomint-report", "r/.geomint-report/scene.toml"}},
      {"ReportQuickWithoutQuickTables",
       "report --quick --results {dir}/r --out {dir}/site",
       2,
       "make gate-quick",
       {{"r/", ""},
        {"r/s/", ""},
        {"r/s/scene.toml", "title = 'x'\n"},
        {"r/s/summary.csv", "label,x\na,1\n"}},
       {"r", "r/s", "r/s/scene.toml", "r/s/summary.csv"}},
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
      // --- every error at once (RunSpec::validate): the second error is named too ---
      {"RunListsEveryError",
       "run --problem pendulum --method rk4 --dt -0.1 --t-end 1 --series {dir}/s.csv --every 0", 2,
       "--every"},
      {"OrderListsEveryError",
       "order --problem pendulum --method rk4 --dt -0.1 --levels 2 --t-end 1", 2, "--dt"},
      {"ReferenceEveryZero", "reference --problem pendulum --t-end 1 --every 0 --out {dir}/r.csv",
       2, "--every"},
      {"ReferenceEveryNegative",
       "reference --problem pendulum --t-end 1 --every -0.5 --out {dir}/r.csv", 2, "--every"},
      // The generator integrates unconstrained systems: it would drop the constraint forces.
      {"ReferenceConstrainedProblem",
       "reference --problem rod_chain:n=2 --t-end 1 --out {dir}/r.csv", 2, "holonomic constraints"},
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
      // --- sharded sweeps, merge, slurm (docs/CLUSTER.md "Running on a cluster"): refused before
      // any
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
      // --- --format: csv or json, for run, order and sweep (docs/USAGE.md "JSON tables") ---
      {"RunFormatXml",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --format xml --out {dir}/s.xml", 2,
       "--format: 'xml' is not a table format (allowed: csv, json)"},
      {"OrderFormatXml",
       "order --problem pendulum --method rk4 --dt 0.1 --t-end 1 --format xml --out {dir}/o.xml", 2,
       "--format: 'xml' is not a table format (allowed: csv, json)"},
      {"OrderFormatJsonWithoutOut",
       "order --problem pendulum --method rk4 --dt 0.1 --t-end 1 --format json", 2,
       "--format json applies to the --out table"},
      {"SweepFormatXml",
       "sweep {dir}/scene.toml --format xml",
       2,
       "--format: 'xml' is not a table format (allowed: csv, json)",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"SweepFormatJsonWithShard",
       "sweep {dir}/scene.toml --format json --shard 0/2",
       2,
       "a shard's tables stay CSV",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"SweepJsonTableIsAFolder",
       "sweep {dir}/scene.toml --out {dir}/out --format json",
       2,
       "summary.json",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")},
        {"out/summary.json/", ""}},
       {"scene.toml", "out", "out/summary.json"},
       10},
      {"TimingOnlyWithNoTiming",
       "sweep {dir}/scene.toml --timing-only --no-timing",
       2,
       "--timing-only",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"ProgressIntervalZero",
       "sweep {dir}/scene.toml --progress-interval 0",
       2,
       "--progress-interval takes a number in [0.01 - 86400]",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ntiming_repeats = 0\n")}},
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
      {"SceneTimingBudgetZero",
       "sweep {dir}/scene.toml",
       2,
       "'timing_budget_s' must be in (0, 86400]",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ntiming_budget_s = 0\n")}},
       {"scene.toml"}},
      {"SceneTimingBudgetNan",
       "sweep {dir}/scene.toml",
       2,
       "'timing_budget_s' must be in (0, 86400]",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ntiming_budget_s = nan\n")}},
       {"scene.toml"}},
      {"SceneWallBudgetNegative",
       "sweep {dir}/scene.toml",
       2,
       "'wall_budget_s' must be in [0, 86400] seconds",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\nwall_budget_s = -1\n")}},
       {"scene.toml"}},
      {"SceneWallBudgetNan",
       "sweep {dir}/scene.toml",
       2,
       "'wall_budget_s' must be in [0, 86400] seconds",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\nwall_budget_s = nan\n")}},
       {"scene.toml"}},
      {"SceneSeriesEveryNegative",
       "sweep {dir}/scene.toml",
       2,
       "series_every",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\nseries_every = -1\n")}},
       {"scene.toml"}},
      {"SceneSeriesSectionOutOfRange",
       "sweep {dir}/scene.toml",
       2,
       "series_section = 1: a Poincare section needs a coordinate index in 0..0",
       {{"scene.toml",
         scene(kRunBlock + "dt = 0.1\nt_end = 1.0\nseries_every = 1\nseries_section = 1\n")}},
       {"scene.toml"}},
      {"SceneSeriesSectionConstrained",
       "sweep {dir}/scene.toml",
       2,
       "unforced, unconstrained, separable",
       {{"scene.toml",
         scene("[[runs]]\nlabel = 'a'\nproblems = ['cartesian_pendulum']\nmethods = ['rattle']\n"
               "dt = 0.1\nt_end = 1.0\nseries_every = 1\nseries_section = 0\n")}},
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
      // --- tables, shards, debris ---
      // A damaged table is refused whole, naming the file and the line: the intact row
      // "a,12.5" fails the band, the same row cut inside its number passes it.
      {"GateTableCutInsideANumber",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "summary.csv' line 3",
       {{"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmax = 10\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1"}},
       {"g.toml", "s", "s/summary.csv"}},
      {"GateRowWithTooFewFields",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "summary.csv' line 4",
       {{"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmax = 10\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x,y\na,1,2\nb,1\n"}},
       {"g.toml", "s", "s/summary.csv"}},
      {"GateRowWithTooManyFields",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "summary.csv' line 3",
       {{"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmax = 10\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1,2\n"}},
       {"g.toml", "s", "s/summary.csv"}},
      {"GateUnterminatedQuote",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "quote",
       {{"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmax = 10\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x\na,1\n\"b,2\n"}},
       {"g.toml", "s", "s/summary.csv"}},
      {"GateHeaderOnlyCutShort",
       "gate {dir}/g.toml {dir}/s/summary.csv",
       2,
       "summary.csv' line 2",
       {{"g.toml", "[[gate]]\nname = 'a'\ncolumn = 'x'\nmax = 10\n"},
        {"s/", ""},
        {"s/summary.csv", "# scene: s\nlabel,x"}},
       {"g.toml", "s", "s/summary.csv"}},
      {"MarkdownOnlyTableCutShort",
       "sweep {dir}/scene.toml --markdown-only",
       2,
       "summary.csv' line 3",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"summary.csv", "# command: geomint sweep\nlabel,problem,method,status\na,pendulum,st"}},
       {"scene.toml", "summary.csv"}},
      {"TimingOnlyTableCutShort",
       "sweep {dir}/scene.toml --timing-only",
       2,
       "summary.csv' line 3",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"summary.csv", "# command: geomint sweep\nlabel,problem,method,status\na,pendulum,st"}},
       {"scene.toml", "summary.csv"}},
      // --- merge: shard counts the file names claim are checked before anything is sized ---
      {"MergeShardCountZero",
       "merge {dir}",
       2,
       "0 shards",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"shards/", ""},
        {"shards/summary.0-of-0.csv", "# variant: full\ncanonical_index,label\n"}},
       {"scene.toml", "shards", "shards/summary.0-of-0.csv"},
       10},
      {"MergeShardCountHuge",
       "merge {dir}",
       2,
       "999999999 shards",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"shards/", ""},
        {"shards/summary.0-of-999999999.csv", "# variant: full\ncanonical_index,label\n"}},
       {"scene.toml", "shards", "shards/summary.0-of-999999999.csv"},
       10},
      {"MergeShardCountAboveUnits",
       "merge {dir}",
       2,
       "1 units",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"shards/", ""},
        {"shards/summary.0-of-2.csv", "# variant: full\ncanonical_index,label\n"}},
       {"scene.toml", "shards", "shards/summary.0-of-2.csv"},
       10},
      // --shard and --shards share one cap, and no shard may be past the scene's last unit (the
      // run below would take far longer than the timeout if it were computed).
      {"ShardCountAboveCap",
       "sweep {dir}/scene.toml --shard 0/1000001",
       2,
       "--shard",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"ShardCountAboveUnits",
       "sweep {dir}/scene.toml --shard 0/2",
       2,
       "1 unit(s)",
       {{"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"scene.toml"},
       10},
      {"SlurmOutNotWritable",
       "slurm {dir}/scene.toml --out /proc/geomint-slurm",
       2,
       "--out '/proc/geomint-slurm'",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"SlurmShardsAboveUnits",
       "slurm {dir}/scene.toml --shards 5",
       2,
       "1 unit(s)",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")}},
       {"scene.toml"}},
      // --markdown-only checks the tables are this scene's, as --timing-only does ({dir} is the
      // folder "work", so the scene is "work").
      {"MarkdownOnlyOtherScene",
       "sweep {dir}/scene.toml --markdown-only",
       2,
       "scene 'other'",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"summary.csv",
         "# command: geomint sweep\n# scene: other\n# variant: full\nlabel,problem,method,status\n"
         "a,pendulum,stormer_verlet,ok\n"}},
       {"scene.toml", "summary.csv"}},
      {"MarkdownOnlyOtherVariant",
       "sweep {dir}/scene.toml --markdown-only",
       2,
       "quick variant",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"summary.csv",
         "# command: geomint sweep\n# scene: work\n# variant: quick\nlabel,problem,method,status\n"
         "a,pendulum,stormer_verlet,ok\n"}},
       {"scene.toml", "summary.csv"}},
      {"MarkdownOnlyOtherBlocks",
       "sweep {dir}/scene.toml --markdown-only",
       2,
       "block 'a'",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"summary.csv",
         "# command: geomint sweep\nlabel,problem,method,status\nz,pendulum,stormer_verlet,ok\n"}},
       {"scene.toml", "summary.csv"}},
      // --- one scene per output folder: a sweep, shard or merge refuses a folder holding
      // another scene's tables, shards or series, and writes nothing there ---
      {"SweepIntoOtherScenesFolder",
       "sweep {dir}/scene.toml",
       2,
       "scene 'other'",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ntiming_repeats = 0\n")},
        {"summary.csv",
         "# command: geomint sweep\n# scene: other\n# variant: full\nlabel,problem,method,status\n"
         "a,pendulum,stormer_verlet,ok\n"}},
       {"scene.toml", "summary.csv"}},
      {"ShardIntoOtherScenesShards",
       "sweep {dir}/scene.toml --shard 0/1",
       2,
       "scene 'work'",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"shards/", ""},
        {"shards/summary.0-of-2.csv", "# scene: other\n# shard: 0/2\ncanonical_index,label\n"}},
       {"scene.toml", "shards", "shards/summary.0-of-2.csv"}},
      {"SweepIntoOtherScenesSeries",
       "sweep {dir}/scene.toml --out {dir}/out",
       2,
       "scene 'other'",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ntiming_repeats = 0\n")},
        {"out/", ""},
        {"out/series/", ""},
        {"out/series/b/", ""},
        {"out/series/b/rk4.csv", "# command: geomint sweep results/other/scene.toml\nt,energy\n"}},
       {"scene.toml", "out", "out/series", "out/series/b", "out/series/b/rk4.csv"}},
      {"MergeIntoOtherScenesFolder",
       "merge {dir}",
       2,
       "scene 'other'",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"shards/", ""},
        {"shards/summary.0-of-1.csv", "# variant: full\n# shard: 0/1\ncanonical_index,label\n"},
        {"order.csv", "# scene: other\nlabel\n"}},
       {"scene.toml", "shards", "shards/summary.0-of-1.csv", "order.csv"}},
      // --- debris: a rerun removes the temporaries a killed run of this machine left (pid
      // 2147483646 is no live process; {tag} is this machine's, temporary_host_tag), in the
      // tables' folder, shards/ and the series folders ---
      {"SweepRemovesStaleTemporaries",
       "sweep {dir}/scene.toml",
       0,
       "done",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ntiming_repeats = 0\n"
                                         "series_every = 1\n")},
        {"summary.csv.2147483646.0.h{tag}.tmp", "partial"},
        {"table.md.2147483646.7.h{tag}.tmp", "partial"},
        {"series/a/", ""},
        {"series/a/stormer_verlet.csv.2147483646.3.h{tag}.tmp", "partial"}},
       {"scene.toml", "summary.csv", "table.md", "series", "series/a",
        "series/a/stormer_verlet.csv"},
       60},
      {"ShardRemovesStaleTemporaries",
       "sweep {dir}/scene.toml --shard 0/1",
       0,
       "done",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\ntiming_repeats = 0\n")},
        {"shards/", ""},
        {"shards/summary.0-of-1.csv.2147483646.0.h{tag}.tmp", "partial"}},
       {"scene.toml", "shards", "shards/summary.0-of-1.csv"},
       60},
      {"MergeRemovesStaleTemporaries",
       "merge {dir}",
       1,
       "another scene version",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")},
        {"shards/", ""},
        {"shards/summary.0-of-1.csv",
         "# variant: full\n# scene_hash: x\n# shard: 0/1\ncanonical_index,label\n"},
        {"shards/summary.0-of-1.csv.2147483646.2.h{tag}.tmp", "partial"},
        {"summary.csv.2147483646.0.h{tag}.tmp", "partial"},
        {"hosts.csv.2147483646.1.h{tag}.tmp", "partial"}},
       {"scene.toml", "shards", "shards/summary.0-of-1.csv"},
       60},
      // --- paths, Slurm scripts, CLI messages ---
      // The same file spelled two ways (the run is in {dir}): a relative name and "./name", or a
      // path through "..", is still one file.
      {"SeriesIsOutSpelledWithDotSlash",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --timing-repeats 0 --series ./x.csv "
       "--out x.csv",
       2, "--series"},
      {"SeriesIsOutSpelledThroughParent",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --timing-repeats 0 --series x.csv "
       "--out sub/../x.csv",
       2,
       "--series",
       {{"sub/", ""}},
       {"sub"}},
      // Outputs where no file can be created, found by a probe file before any computing (the
      // runs would outlast the timeout): /proc and /sys, where access(2) says yes to root.
      {"OutUnderProc",
       "run --problem pendulum --method rk4 --dt 1e-7 --t-end 1000 --out /proc/geomint.csv",
       2,
       "--out",
       {},
       {},
       10},
      {"SeriesUnderSys",
       "run --problem pendulum --method rk4 --dt 1e-7 --t-end 1000 --series /sys/geomint.csv",
       2,
       "--series",
       {},
       {},
       10},
      {"OrderOutUnderProc",
       "order --problem pendulum --method rk4 --dt 1e-4 --levels 3 --t-end 1000 --out "
       "/proc/geomint.csv",
       2,
       "--out",
       {},
       {},
       10},
      // Names longer than the file system takes: the file's own (with room for its temporary),
      // and a folder to be created.
      {"OutNameTooLong",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --timing-repeats 0 --out {dir}/" +
           std::string(250, 'a') + ".csv",
       2, "bytes long"},
      {"OutFolderNameTooLong",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --timing-repeats 0 --out {dir}/" +
           std::string(300, 'a') + "/x.csv",
       2, "bytes long"},
      // A 100 kB path of nested folders: refused at once (the output check was quadratic in it).
      {"OutPathOf100kB",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --timing-repeats 0 --out {dir}/" +
           [] {
             std::string path;
             for (int i = 0; i < 50000; ++i) path += "a/";
             return path;
           }() +
           "x.csv",
       2,
       "bytes long",
       {},
       {},
       10},
      // A sweep's tables and series are checked before its first (long) run.
      {"SweepSummaryIsADirectory",
       "sweep {dir}/scene.toml",
       2,
       "summary.csv",
       {{"summary.csv/", ""},
        {"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"summary.csv", "scene.toml"},
       10},
      {"SweepTableMdIsADirectory",
       "sweep {dir}/scene.toml",
       2,
       "table.md",
       {{"table.md/", ""},
        {"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"table.md", "scene.toml"},
       10},
      {"SweepSeriesIsAFile",
       "sweep {dir}/scene.toml",
       2,
       "series",
       {{"series", "x"},
        {"scene.toml",
         scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\nseries_every = 1\n")}},
       {"series", "scene.toml"},
       10},
      {"SweepShardIsADirectory",
       "sweep {dir}/scene.toml --shard 0/1",
       2,
       "summary.0-of-1.csv",
       {{"shards/summary.0-of-1.csv/", ""},
        {"scene.toml", scene(kRunBlock + "dt = 1e-7\nt_end = 1000.0\ntiming_repeats = 0\n")}},
       {"shards", "shards/summary.0-of-1.csv", "scene.toml"},
       10},
      {"MarkdownOnlyTableMdIsADirectory",
       "sweep {dir}/scene.toml --markdown-only",
       2,
       "table.md",
       {{"table.md/", ""},
        {"summary.csv",
         "# command: geomint sweep scene.toml\nlabel,problem,method,status\n"
         "a,pendulum,rk4,ok\n"},
        {"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")}},
       {"table.md", "summary.csv", "scene.toml"}},
      // A malformed reference file (results/references/ of the working folder, here {dir}) is
      // bad input of the scene, found when it loads, for runs and order studies alike.
      {"SweepRunMeetsMalformedReference",
       "sweep {dir}/scene.toml",
       2,
       "not a valid reference",
       {{"results/references/", ""},
        {"results/references/henon_heiles_energy_0.08333333333333333_p1_0.1_q1_0_q2_0.1.csv",
         "junk\n"},
        {"scene.toml", scene("[[runs]]\nlabel = 'a'\nproblems = ['henon_heiles']\n"
                             "methods = ['rk4']\ndt = 0.1\nt_end = 1.0\ntiming_repeats = 0\n")}},
       {"results", "results/references",
        "results/references/henon_heiles_energy_0.08333333333333333_p1_0.1_q1_0_q2_0.1.csv",
        "scene.toml"}},
      {"SweepOrderMeetsMalformedReference",
       "sweep {dir}/scene.toml",
       2,
       "not a valid reference",
       {{"results/references/", ""},
        {"results/references/henon_heiles_energy_0.08333333333333333_p1_0.1_q1_0_q2_0.1.csv",
         "# reference_problem: henon_heiles:energy=0.08333333333333333,p1=0.1,q1=0,q2=0.1\n"
         "# estimated_error_max: 1e-14\nt,q_0,q_1,p_0,p_1\n0,0,0.1,x,0\n"},
        {"scene.toml", scene("[[orders]]\nlabel = 'o'\nproblems = ['henon_heiles']\n"
                             "methods = ['rk4']\ndt0 = 0.1\nlevels = 3\nt_end = 1.0\n")}},
       {"results", "results/references",
        "results/references/henon_heiles_energy_0.08333333333333333_p1_0.1_q1_0_q2_0.1.csv",
        "scene.toml"}},
      // A dense eigensolver on a million degrees of freedom: refused by size, not std::bad_alloc.
      {"ModesTooLargeForDenseEigensolver",
       "modes --problem spring_chain:n=1000000 --method stormer_verlet --dt 0.1", 2,
       "more than the 2000"},
      // Parse errors say what the option takes, or which options the verb has, and its --help.
      {"CliNotANumberSaysWhatTheOptionTakes",
       "run --problem pendulum --method rk4 --dt 1e-5x --t-end 1", 2, "--dt takes a number"},
      {"CliRangeSaysTheRange", "sweep {dir}/scene.toml --jobs 0", 2,
       "--jobs takes an integer in [1 - 256]"},
      {"CliUnknownOptionListsTheVerbsOptions", "run --problem pendulum --method rk4 --frob 1", 2,
       "run takes: --problem, --method"},
      {"CliExtraArgumentPointsToTheVerbsHelp", "sweep {dir}/a.toml {dir}/b.toml", 2,
       "see geomint sweep --help"},
      // --- failure rows, budgets, order fit ---
      // The force kick's fixed point diverges (h·c/m = 8): the advance() path, which the run
      // takes, once dropped the status and reported `ok` after 100 force evaluations per step.
      {"PositionVerletForceKickFailureIsARow",
       "run --problem damped_oscillator:zeta=4 --method position_verlet --dt 0.5 --t-end 5 "
       "--timing-repeats 0",
       1, "force_kick_max_iter"},
      {"StormerVerletForceKickFailureIsARow",
       "run --problem damped_oscillator:zeta=4 --method stormer_verlet --dt 0.5 --t-end 5 "
       "--timing-repeats 0",
       1, "force_kick_max_iter"},
      // 10^10 Verlet steps (an hour, then three timing repeats) end at once as a budget row
      // that says how to raise the budget.
      {"FixedStepHugeHorizonEnds",
       "run --problem pendulum --method stormer_verlet --dt 0.1 --t-end 1e9",
       1,
       "--max-steps",
       {},
       {},
       10},
      {"FixedStepHugeHorizonIsAMaxStepsRow",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1e9",
       1,
       ",max_steps,",
       {},
       {},
       10},
      {"WallBudgetNegative", "run --problem pendulum --method rk4 --wall-budget -0.5", 2,
       "--wall-budget must be in [0, 86400] seconds (0: no budget; got -0.5)"},
      {"WallBudgetTooLarge", "run --problem pendulum --method rk4 --wall-budget 1e9", 2,
       "--wall-budget must be in [0, 86400]"},
      {"WallBudgetNan", "run --problem pendulum --method rk4 --wall-budget nan", 2,
       "--wall-budget: NaN is not allowed"},
      {"WallBudgetSpentIsATimeoutRow",
       "run --problem kepler --method rk4 --dt 0.001 --t-end 100 --wall-budget 1e-9", 1,
       ",timeout,"},
      {"FixedStepBudgetFromTheCommandLine",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --max-steps 9", 1, "max_steps"},
      {"FixedStepBudgetJustEnough",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --max-steps 10 "
       "--timing-repeats 0",
       0, ",ok,"},
      {"MaxStepsZero", "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --max-steps 0", 2,
       "--max-steps"},
      {"MaxStepsAboveCap",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --max-steps 100000000000", 2,
       "--max-steps"},
      {"SceneHugeHorizonEnds",
       "sweep {dir}/scene.toml",
       0,
       "1 failed run",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1e9\ntiming_repeats = 0\n")}},
       {"scene.toml", "summary.csv", "table.md"},
       10},
      {"SceneMaxStepsEnds",
       "sweep {dir}/scene.toml",
       0,
       "1 failed run",
       {{"scene.toml",
         scene(kRunBlock + "dt = 0.1\nt_end = 1.0\nmax_steps = 5\ntiming_repeats = 0\n")}},
       {"scene.toml", "summary.csv", "table.md"}},
      {"SceneMaxStepsZero",
       "sweep {dir}/scene.toml",
       2,
       "max_steps",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\nmax_steps = 0\n")}},
       {"scene.toml"}},
      // Iteration limits of the implicit solvers (tests/methods_test.cpp, EveryImplicitMethod).
      {"CompositionMaxIterOnExplicitBase",
       "run --problem pendulum --method composition:max_iter=1 --dt 0.1 --t-end 1", 2, "explicit"},
      {"CvodeMaxNonlinItersZero",
       "run --problem pendulum --method cvode_bdf:max_nonlin_iters=0 --t-end 1", 2,
       "max_nonlin_iters"},
      {"CompositionAtItsIterationLimitIsARow",
       "run --problem pendulum:theta0=2.5 --method composition:base=implicit_midpoint,max_iter=1 "
       "--dt 0.2 --t-end 2 --timing-repeats 0",
       1, "newton_max_iter"},
      // --- perf-compare (harness/perf_compare.*, docs/PERF.md): every input validated whole ---
      {"PerfCompareTruncatedJson",
       "perf-compare {dir}/a.json {dir}/b.json",
       2,
       "truncated",
       {{"a.json", kBenchJson}, {"b.json", kBenchJson.substr(0, kBenchJson.size() / 2)}},
       {"a.json", "b.json"}},
      {"PerfCompareNotGoogleBenchmark",
       "perf-compare {dir}/a.json {dir}/b.json",
       2,
       "\"benchmarks\"",
       {{"a.json", kBenchJson}, {"b.json", "{\"rows\": []}"}},
       {"a.json", "b.json"}},
      {"PerfCompareFailedBenchmark",
       "perf-compare {dir}/a.json {dir}/b.json",
       2,
       "reported an error",
       {{"a.json", kBenchJson},
        {"b.json",
         replace_all(kBenchJson, "\"iterations\"", "\"error_occurred\": true, \"iterations\"")}},
       {"a.json", "b.json"}},
      {"PerfCompareOverflowingTime",
       "perf-compare {dir}/a.json {dir}/b.json",
       2,
       "benchmark 'BM_Step' has real_time 1e+300 s = inf ns, outside the range",
       {{"a.json", replace_all(kBenchJson, "\"us\"", "\"s\"")},
        {"b.json", replace_all(bench_json({10, 11, 1e300, 10.5, 11.5, 10.2}), "\"us\"", "\"s\"")}},
       {"a.json", "b.json"}},
      {"PerfCompareEndlessInput",
       "perf-compare /dev/zero {dir}/a.json",
       2,
       "/dev/zero: more than 64 MiB, the limit of one benchmark file",
       {{"a.json", kBenchJson}},
       {"a.json"}},
      {"PerfCompareTooFewRepetitions",
       "perf-compare {dir}/a.json {dir}/a.json",
       2,
       "at least 5",
       {{"a.json", bench_json({1.0, 2.0, 3.0})}},
       {"a.json"}},
      {"PerfCompareAlphaOutOfRange",
       "perf-compare {dir}/a.json {dir}/a.json --alpha 1.5",
       2,
       "--alpha",
       {{"a.json", kBenchJson}},
       {"a.json"}},
      {"PerfCompareEmptyFolder",
       "perf-compare {dir}/a.json {dir}/empty",
       2,
       "no *.json",
       {{"a.json", kBenchJson}, {"empty/", ""}},
       {"a.json", "empty"}},
      {"PerfCompareMissingFile",
       "perf-compare {dir}/a.json {dir}/nosuch.json",
       2,
       "nosuch.json",
       {{"a.json", kBenchJson}},
       {"a.json"}},
      // The energy-preserving contrasts (integrators/avf.cpp, integrators/projection.cpp).
      {"ProjectionUnknownBase",
       "run --problem kepler --method projection:base=rk4 --dt 0.1 --t-end 1", 2, "gauss"},
      {"ProjectionGaussStagesOutOfRange",
       "run --problem kepler --method projection:s=4 --dt 0.1 --t-end 1", 2, "s"},
      {"ProjectionOnNonSeparableProblem",
       "run --problem double_pendulum --method projection --dt 0.01 --t-end 1", 2, "non-separable"},
      {"AvfOnNonSeparableProblem", "run --problem double_pendulum --method avf --dt 0.01 --t-end 1",
       2, "non-separable"},
      {"AvfWithAForce", "run --problem damped_oscillator --method avf --dt 0.1 --t-end 1", 2,
       "conservative"},
      {"AvfZeroNodes", "run --problem kepler --method avf:nodes=0 --dt 0.1 --t-end 1", 2, "nodes"},
      {"ProjectionOnConstrainedProblem",
       "run --problem rod_chain --method projection --dt 0.01 --t-end 1", 2,
       "holonomic constraints, which problem 'rod_chain' has"},
      // Errors of 10^3-10^4 on an orbit of size 1 once fitted "order 0.999".
      {"OrderFromErrorsAboveTheSolutionIsNoFit",
       "order --problem kepler:e=0.999 --method stormer_verlet --dt 0.01 --levels 4 --t-end 2", 1,
       "not small against the solution"},
      // --- files that are not there: said so, not "malformed ...: File could not be opened" ---
      {"SceneDoesNotExist", "sweep {dir}/missing.toml", 2, "missing.toml' does not exist"},
      {"GatesFileDoesNotExist", "gate {dir}/missing.toml {dir}", 2, "missing.toml' does not exist"},
      {"MergeImplicitSceneDoesNotExist",
       "merge {dir}/out",
       2,
       "out/scene.toml' does not exist",
       {{"out/", ""}, {"out/shards/", ""}, {"out/shards/summary.csv", "# variant: full\nlabel\n"}},
       {"out", "out/shards", "out/shards/summary.csv"}},
      // --- NaN and inf pass a plain range check (comparisons with NaN are false) ---
      {"ProgressIntervalNan",
       "sweep {dir}/scene.toml --progress-interval nan",
       2,
       "--progress-interval",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"ProgressIntervalInf",
       "sweep {dir}/scene.toml --progress-interval inf",
       2,
       "--progress-interval",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"ProgressIntervalNanFromEnvironment",
       "sweep {dir}/scene.toml",
       2,
       "--progress-interval",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")}},
       {"scene.toml"},
       30,
       "GEOMINT_PROGRESS_INTERVAL=nan"},
      {"DtNan", "run --problem pendulum --method rk4 --dt nan --t-end 1", 2, "--dt"},
      {"PerfCompareAlphaNan",
       "perf-compare {dir}/a.json {dir}/a.json --alpha nan",
       2,
       "--alpha",
       {{"a.json", kBenchJson}},
       {"a.json"}},
      // --- an empty value (an unset shell variable) is not 0 ---
      {"EmptyDivergeFactor", "run --problem pendulum --method rk4 --diverge-factor ''", 2,
       "--diverge-factor: an empty value is not allowed"},
      {"EmptyWallBudget", "run --problem pendulum --method rk4 --wall-budget ''", 2,
       "--wall-budget: an empty value is not allowed"},
      {"EmptyTimingRepeats", "run --problem pendulum --method rk4 --timing-repeats ''", 2,
       "--timing-repeats: an empty value is not allowed"},
      {"EmptyJobs",
       "sweep {dir}/scene.toml --jobs ''",
       2,
       "--jobs: an empty value is not allowed",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")}},
       {"scene.toml"}},
      {"EmptyOrderLevels", "order --problem pendulum --method rk4 --dt 0.1 --t-end 1 --levels ''",
       2, "--levels: an empty value is not allowed"},
      {"EmptySpecValue", "run --problem pendulum:theta0= --method rk4", 2,
       "key 'theta0' has an empty value"},
      {"EmptyMethodSpecValue", "run --problem pendulum --method hp:alpha=,tol=1e-10", 2,
       "key 'alpha' has an empty value"},
      // --- initial states: a radius or length coordinate must be > 0 ---
      {"PolarKeplerNegativeRadius",
       "run --problem kepler:coordinates=polar --method gauss --initial {dir}/start.csv",
       2,
       "r (the radius)",
       {{"start.csv", "q,p\n-1,0\n0,1\n"}},
       {"start.csv"}},
      {"SpringPendulumNegativeLength",
       "run --problem spring_pendulum --method gauss --initial {dir}/start.csv",
       2,
       "r (the spring length)",
       {{"start.csv", "q,p\n-1.4,0\n0.5,0\n"}},
       {"start.csv"}},
      // --- slurm --submit without sbatch: refused before any script is written ---
      {"SlurmSubmitWithoutSbatch",
       "slurm {dir}/scene.toml --submit",
       2,
       "sbatch is not on PATH",
       {{"scene.toml", scene(kRunBlock + "dt = 0.1\nt_end = 1.0\n")}},
       {"scene.toml"},
       30,
       "PATH=/nonexistent"},
      // --- did you mean: misspelt verbs, options, names and keys ---
      {"MisspeltVerb", "swep {dir}/scene.toml", 2, "did you mean 'sweep'?"},
      {"MisspeltVerbTransposed", "rnu --problem pendulum", 2, "did you mean 'run'?"},
      {"MisspeltOption", "run --problem pendulum --method rk4 --dtt 0.1", 2,
       "did you mean '--dt'?"},
      {"MisspeltOptionWithValue", "run --problem pendulum --method rk4 --t-edn=1", 2,
       "did you mean '--t-end'?"},
      {"MisspeltProblem", "run --problem pendlum --method rk4", 2, "did you mean 'pendulum'?"},
      {"MisspeltMethod", "run --problem pendulum --method stormer_verlett", 2,
       "did you mean 'stormer_verlet'?"},
      {"MisspeltParameter", "run --problem pendulum:thta0=1 --method rk4", 2,
       "did you mean 'theta0'?"},
      {"MisspeltListName", "list rod_chian", 2, "did you mean 'rod_chain'?"},
      {"ListUnknownName", "list frobnicate", 2, "neither a method nor a problem"},
      // --- the ranges `geomint list NAME` prints are the ones enforced ---
      {"RodChainTooManyRods", "run --problem rod_chain:coordinates=joint,n=4097 --method rk4", 2,
       "1..4096"},
      // The Cartesian form keeps its own, smaller cap, stated in n's help and in the message.
      {"RodChainCartesianTooManyRods", "run --problem rod_chain:n=65 --method rattle", 2,
       "coordinates=cartesian; allowed: 1 to 64"},
      {"ArticulatedChainTooManyLinks", "run --problem articulated_chain:n=4097 --method rk4", 2,
       "1..4096"},
      {"ArticulatedChainWrongLengthList",
       "run --problem articulated_chain:n=3,masses=1/2 --method rk4", 2,
       "parameter masses has 2 entries; allowed: exactly n = 3"},
      {"ArticulatedChainNonPositiveInertia",
       "run --problem articulated_chain:n=2,inertias=1/0 --method rk4", 2,
       "inertias entry 2 is 0; allowed: > 0"},
      // The thread count of the element loops (problems/parallel.hpp): refused before any output.
      {"ThreadsZero",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --out {dir}/a.csv",
       2,
       "GEOMINT_THREADS='0' is not allowed: use an integer in [1, 256]",
       {},
       {},
       30,
       "GEOMINT_THREADS=0"},
      {"ThreadsNotANumber",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --out {dir}/a.csv",
       2,
       "GEOMINT_THREADS='two'",
       {},
       {},
       30,
       "GEOMINT_THREADS=two"},
      {"ThreadsTooMany",
       "run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --out {dir}/a.csv",
       2,
       "GEOMINT_THREADS='257' is not allowed",
       {},
       {},
       30,
       "GEOMINT_THREADS=257"},
      // --- score: trajectories written by other programs (harness/score.hpp); the inputs stay,
      // nothing else is written ---
      {"ScoreTruncatedCsv",
       kScore + "a.csv",
       2,
       "a.csv: the last line has no terminating newline",
       {{"a.csv", "t,q0,p0\n0,0.5,0\n0.1,0.49,-0.05"}},
       {"a.csv"}},
      {"ScoreNanCsv",
       kScore + "a.csv",
       2,
       "a.csv: line 3, column p0: nan is not a finite",
       {{"a.csv", "t,q0,p0\n0,0.5,0\n0.1,0.49,nan\n"}},
       {"a.csv"}},
      {"ScoreNonMonotoneTime",
       kScore + "a.csv",
       2,
       "a.csv: line 4, column t: t = 0.1 does not",
       {{"a.csv", kPendulumCsv + "0.1,0.48,-0.1\n"}},
       {"a.csv"}},
      {"ScoreShortRow",
       kScore + "a.csv",
       2,
       "a.csv: line 3: 2 fields, the header has 3",
       {{"a.csv", "t,q0,p0\n0,0.5,0\n0.1,0.49\n"}},
       {"a.csv"}},
      {"ScoreWrongWidthForDof",
       kScore + "a.csv",
       2,
       "unexpected column 'q1'",
       {{"a.csv", "t,q0,q1,p0,p1\n0,0.5,0,0,0\n0.1,0.49,0,-0.05,0\n"}},
       {"a.csv"}},
      {"ScoreHeaderless",
       kScore + "a.csv",
       2,
       "a.csv: line 1: no header",
       {{"a.csv", "0,0.5,0\n0.1,0.49,-0.05\n"}},
       {"a.csv"}},
      {"ScoreEmptyFile",
       kScore + "a.csv",
       2,
       "a.csv: the file is empty",
       {{"a.csv", ""}},
       {"a.csv"}},
      {"ScoreStartOffInitialState",
       kScore + "a.csv",
       2,
       "a.csv: line 2, column q0: the first row is not the initial state",
       {{"a.csv", "t,q0,p0\n0,0.6,0\n0.1,0.49,-0.05\n"}},
       {"a.csv"}},
      {"ScoreStartTolNegative",
       kScore + "--start-tol -1 a.csv",
       2,
       "--start-tol must be a finite number >= 0",
       {{"a.csv", kPendulumCsv}},
       {"a.csv"}},
      {"ScoreOneBadFileOfTwo",
       kScore + "good.csv bad.csv",
       2,
       "bad.csv: line 3, column q0",
       {{"good.csv", kPendulumCsv}, {"bad.csv", "t,q0,p0\n0,0.5,0\n0.1,inf,0\n"}},
       {"good.csv", "bad.csv"}},
      {"ScoreNpyWrongDtype",
       kScore + "a.npy",
       2,
       ".npy dtype '<f4'",
       {{"a.npy",
         npy_file("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }", kPendulumRows)}},
       {"a.npy"}},
      {"ScoreNpyBigEndian",
       kScore + "a.npy",
       2,
       ".npy dtype '>f8'",
       {{"a.npy",
         npy_file("{'descr': '>f8', 'fortran_order': False, 'shape': (2, 3), }", kPendulumRows)}},
       {"a.npy"}},
      {"ScoreNpyWrongShape",
       kScore + "a.npy",
       2,
       ".npy array has 2 columns",
       {{"a.npy",
         npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (3, 2), }", kPendulumRows)}},
       {"a.npy"}},
      {"ScoreNpyOneDimensional",
       kScore + "a.npy",
       2,
       "a 2-D array",
       {{"a.npy",
         npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (6,), }", kPendulumRows)}},
       {"a.npy"}},
      {"ScoreNpyFortranOrder",
       kScore + "a.npy",
       2,
       "Fortran order",
       {{"a.npy",
         npy_file("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }", kPendulumRows)}},
       {"a.npy"}},
      {"ScoreNpyTruncatedData",
       kScore + "a.npy",
       2,
       "the file was cut short",
       {{"a.npy", kPendulumNpy.substr(0, kPendulumNpy.size() - 8)}},
       {"a.npy"}},
      {"ScoreNpyTruncatedHeader",
       kScore + "a.npy",
       2,
       ".npy header cut short",
       {{"a.npy", kPendulumNpy.substr(0, 40)}},
       {"a.npy"}},
      {"ScoreNpyNan",
       kScore + "a.npy",
       2,
       "a.npy: row 1, column p0",
       {{"a.npy", npy_file(kPendulumNpyDict,
                           {0, 0.5, 0, 0.1, 0.49, std::numeric_limits<double>::quiet_NaN()})}},
       {"a.npy"}},
      {"ScoreNpyNoMagic",
       kScore + "a.npy",
       2,
       "no \\x93NUMPY magic",
       {{"a.npy", kPendulumCsv}},
       {"a.npy"}},
      {"ScoreMissingFile", kScore + "nosuch.csv", 2, "nosuch.csv: cannot be read"},
      {"ScoreMethodMetric",
       kScore + "--metric symplecticity_defect a.csv",
       2,
       "a trajectory alone gives only",
       {{"a.csv", kPendulumCsv}},
       {"a.csv"}},
      {"ScoreOrderTooFewFiles",
       kScore + "--order a.csv b.csv",
       2,
       "a fit needs at least 3",
       {{"a.csv", kPendulumCsv}, {"b.csv", kPendulumCsv}},
       {"a.csv", "b.csv"}},
      {"ScoreSeriesOfAnotherProblem",
       kScore + "a.csv",
       2,
       "written for the problem 'harmonic",
       {{"a.csv", "# problem: harmonic:mass=1,omega=1,q0=1,v0=0\n" + kPendulumCsv}},
       {"a.csv"}},
  };
  return all;
}

// The binary under test: $GEOMINT_BAD_INPUT_BINARY when set (to run the registry against
// another build, e.g. an older one), else the one built with this suite.
std::string binary() {
  const char* other = std::getenv("GEOMINT_BAD_INPUT_BINARY");
  return other && *other ? other : GEOMINT_BINARY;
}

// Run in the case's folder: a relative output path, and results/references/, are the case's
// own, and a relative output that escapes the checks is caught as a stray file.
std::string fmt_command(const Case& c, const fs::path& dir) {
  return "cd " + shell_quoted(dir.string()) + " && " +
         // timeout found on the suite's PATH: a case may set its own (one without sbatch).
         (c.environment.empty() ? "" : "env " + c.environment + " ") +
         "\"$(command -v timeout)\" -k 5 " + std::to_string(c.timeout_s) + " " +
         shell_quoted(fs::absolute(binary()).string()) + " " +
         replace_all(c.arguments, "{dir}", shell_quoted(dir.string())) + " 2>&1";
}

class BadInput : public testing::TestWithParam<Case> {};

TEST_P(BadInput, ExitCodeMessageAndNoStrayFiles) {
  const Case& c = GetParam();
  // A space and parentheses in the folder, as in a clone's path: the command line quotes it.
  const fs::path base = fs::temp_directory_path() / "geomint bad input (x)" / c.name;
  const fs::path dir = base / "work";
  fs::remove_all(base);
  fs::create_directories(dir);
  std::set<std::string> expected = c.outputs;
  for (const auto& [spelled, content] : c.setup) {
    const std::string path = replace_all(spelled, "{tag}", temporary_host_tag());
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

// `report --out` below a folder the user cannot write is bad input (exit 2, nothing written),
// found by the probe before any page is built. Root writes anywhere: as root the command runs as
// `nobody` through setpriv(1); without setpriv the case cannot be made and is skipped.
TEST(BadInputReport, OutInAReadOnlyFolder) {
  // Not below the test's private (0700) temporary folder: `nobody` must reach the scenes.
  const fs::path dir =
      fs::path("/tmp") / ("geomint_bad_input_read_only." + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "r" / "s");
  fs::create_directories(dir / "locked");
  std::ofstream(dir / "r" / "s" / "scene.toml") << "title = 'x'\n";
  std::string as_user;
  if (::geteuid() == 0) {
    if (std::system("command -v setpriv > /dev/null 2>&1") != 0) {
      GTEST_SKIP() << "root without setpriv: no user for whom a folder is read-only";
    }
    // nobody reads the scenes and runs the build, but cannot write into locked/ (root's, 0755).
    as_user = "setpriv --reuid=65534 --regid=65534 --clear-groups ";
    // A build under a private home (root's /root is 0700, as on a fresh machine) is out of
    // nobody's reach, and the case cannot be made there either.
    if (std::system(
            (as_user + "test -x " + shell_quoted(fs::absolute(binary()).string())).c_str()) != 0) {
      GTEST_SKIP() << "nobody cannot run " << fs::absolute(binary())
                   << " (a folder on its path is private): no user for whom a folder is read-only";
    }
  } else {
    fs::permissions(dir / "locked", fs::perms::owner_write, fs::perm_options::remove);
  }
  const std::string command = "cd " + shell_quoted(dir.string()) + " && " + as_user +
                              "timeout -k 5 30 " + shell_quoted(fs::absolute(binary()).string()) +
                              " report --results " + shell_quoted((dir / "r").string()) +
                              " --out " + shell_quoted((dir / "locked" / "site").string()) +
                              " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 2) << command << "\n" << output;
  EXPECT_NE(output.find("no file can be created in folder"), std::string::npos) << output;
  EXPECT_TRUE(fs::is_empty(dir / "locked")) << output;
  fs::permissions(dir / "locked", fs::perms::owner_write, fs::perm_options::add);
  fs::remove_all(dir);
}

// SIGTERM (what Slurm sends at a time limit) and SIGINT (Ctrl-C) end a sweep as the signal
// would, without the temporary file of its open series writer: `git add results/` after an
// interrupted sweep commits no debris.
void expect_signal_leaves_no_temporary(int signal_number, const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "geomint_bad_input" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  // 10^9 Stormer-Verlet steps (a budget raised to allow them) with a series: the run is still
  // writing when the signal comes.
  std::ofstream(dir / "scene.toml") << scene(kRunBlock +
                                             "dt = 1e-5\nt_end = 1e4\ntiming_repeats = 0\n"
                                             "series_every = 100000\nmax_steps = 1000000000\n");
  const std::string program = binary(), scene_path = (dir / "scene.toml").string();
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    // An ignored signal stays ignored across exec, and the sweep keeps it so (as nohup asks); a
    // test runner started as a background job of a non-interactive shell ignores SIGINT, so the
    // child takes the default disposition the test is about.
    std::signal(signal_number, SIG_DFL);
    execl(program.c_str(), program.c_str(), "sweep", scene_path.c_str(), "--jobs", "1",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  const auto has_temporary = [&] {
    for (const auto& entry : tree(dir)) {
      if (entry.size() > 4 && entry.substr(entry.size() - 4) == ".tmp") return true;
    }
    return false;
  };
  bool seen = false;
  for (int i = 0; i < 300 && !(seen = has_temporary()); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  kill(child, signal_number);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(seen) << "the sweep never opened its series file";
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number)
      << "not ended by the signal: status " << status;
  EXPECT_FALSE(has_temporary()) << "temporary file left after signal " << signal_number;
  fs::remove_all(dir);
}

TEST(Debris, SigtermLeavesNoTemporaryFile) {
  expect_signal_leaves_no_temporary(SIGTERM, "SigtermDebris");
}

TEST(Debris, SigintLeavesNoTemporaryFile) {
  expect_signal_leaves_no_temporary(SIGINT, "SigintDebris");
}

}  // namespace
}  // namespace bad_input_test
}  // namespace geomint
