// `geomint score` (harness/score.hpp) against `geomint run`: a series that run wrote, read back
// as an outside trajectory (CSV with p or v columns, .npy), gives run's metrics; the reader's
// checks and the order fit over files.
#include "harness/score.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "harness/order.hpp"
#include "harness/run.hpp"
#include "harness/run_spec.hpp"
#include "problems/lagrangian.hpp"
#include "problems/mass_operator.hpp"
#include "problems/spec.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace score_test {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "geomint_score_test";
  fs::create_directories(dir);
  return dir / name;
}

void write(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// A .npy file (format 1.0) of `rows` x `columns` little-endian float64 values.
std::string npy_bytes(const std::vector<double>& values, size_t rows, size_t columns) {
  return test::npy_file(
      fmt::format("{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {}), }}", rows, columns),
      values);
}

// The first method (of a few that cover every kind of problem) that runs `problem`.
std::string method_for(const std::shared_ptr<const Problem>& problem) {
  // Stiff first-order problems (van der Pol at mu = 1000) need an implicit adaptive method.
  if (problem->has(kFirstOrderOnly)) return "cvode_bdf";
  // Constraints on a mass M(q) (andrews): rattle takes them too (its general step).
  for (const char* method : {"stormer_verlet", "rattle", "lie_poisson", "boris", "rk4", "del",
                             "ida:index=2,multiplier_atol=1"}) {
    RunSpec spec{problem, MethodFactory(method), {}};
    spec.config.dt = 0.01;
    spec.config.t_end = 1;
    if (spec.validate().empty()) return method;
  }
  return "";
}

struct RunAndSeries {
  RunRecord record;
  Trajectory trajectory;  // the series read back through score's reader
};

RunAndSeries run_with_series(const std::shared_ptr<const Problem>& problem,
                             const std::string& method, double dt, double t_end,
                             const std::string& name) {
  RunSpec spec{problem, MethodFactory(method), {}};
  spec.config.dt = dt;
  spec.config.t_end = t_end;
  spec.config.timing_repeats = 0;
  spec.config.series_path = scratch(name + ".csv").string();
  RunResult result = run_one(spec);
  EXPECT_TRUE(result.ok) << problem->spec() << " " << method << ": " << result.record.status;
  return {result.record,
          read_trajectory(spec.config.series_path, *problem, kDefaultStartTolerance)};
}

// Every registered problem small enough for a series with its state (dof <= 64): score of the
// series equals run's metrics exactly, because the series holds each step point's (t, q, p) in
// shortest round-trip text (format_number) and score feeds those very states to the very
// observers of the run. Separable, general-Lagrangian (spherical_pendulum:coordinates=angles),
// constrained (cartesian_pendulum, rigid_body) and exact-solution (pendulum, kepler) problems are
// among them.
TEST(Score, AgreesWithRunOnItsOwnSeriesForEveryProblem) {
  std::vector<std::string> specs;
  for (const ProblemEntry& entry : problem_registry()) specs.push_back(entry.name);
  specs.push_back("spherical_pendulum:coordinates=angles");
  specs.push_back("rod_chain:coordinates=joint");
  int scored = 0;
  for (const std::string& name : specs) {
    const auto problem = parse_problem(name);
    if (problem->dof() > 64) continue;
    const std::string method = method_for(problem);
    ASSERT_FALSE(method.empty()) << name;
    const double dt = problem->default_dt();
    const RunAndSeries run = run_with_series(problem, method, dt, 40 * dt, "series");
    const RunRecord record = score_trajectory(*problem, run.trajectory, ScoreConfig{});
    EXPECT_EQ(record.metrics, run.record.metrics) << name << " with " << method;
    EXPECT_EQ(record.steps, run.record.steps) << name;
    EXPECT_EQ(record.problem, run.record.problem) << name;
    ++scored;
  }
  EXPECT_GE(scored, 20);
}

// The same trajectory as velocities (CSV with v columns, p = Mv or p = ∂L/∂v) and as .npy: the
// metrics agree to round-off. v = M⁻¹p then p = Mv (a Cholesky solve and a product for a
// general Lagrangian) changes p by a few ulps, hence the tolerance 1e-10 (absolute, or relative
// above 1): far above those ulps amplified through H, far below any metric's own size.
TEST(Score, VelocityColumnsAndNpyGiveTheSameMetrics) {
  for (const std::string name :
       {"pendulum", "kepler", "spherical_pendulum:coordinates=angles", "cartesian_pendulum"}) {
    const auto problem = parse_problem(name);
    const double dt = problem->default_dt();
    const RunAndSeries run = run_with_series(problem, method_for(problem), dt, 40 * dt, "base");
    const int n = problem->dof();
    const LagrangianSystem* lagrangian = problem->as_lagrangian();
    std::string csv = "t";
    for (int i = 0; i < n; ++i) csv += fmt::format(",q{}", i);
    for (int i = 0; i < n; ++i) csv += fmt::format(",v{}", i);
    csv += '\n';
    std::vector<double> values;
    for (const State& s : run.trajectory.states) {
      const Vec v =
          lagrangian ? lagrangian->velocity(s.q, s.p) : Vec(MassOperator(*problem).solve(s.q, s.p));
      csv += format_number(s.t);
      values.push_back(s.t);
      for (double x : s.q) csv += "," + format_number(x), values.push_back(x);
      for (double x : v) csv += "," + format_number(x);
      for (double x : s.p) values.push_back(x);
      csv += '\n';
    }
    write(scratch("v.csv"), csv);
    write(scratch("p.npy"), npy_bytes(values, run.trajectory.states.size(), 1 + 2 * n));
    const Trajectory from_v =
        read_trajectory(scratch("v.csv").string(), *problem, kDefaultStartTolerance);
    const Trajectory from_npy =
        read_trajectory(scratch("p.npy").string(), *problem, kDefaultStartTolerance);
    const RunRecord by_v = score_trajectory(*problem, from_v, ScoreConfig{});
    const RunRecord by_npy = score_trajectory(*problem, from_npy, ScoreConfig{});
    EXPECT_EQ(by_npy.metrics, run.record.metrics) << name;
    ASSERT_EQ(by_v.metrics.size(), run.record.metrics.size()) << name;
    for (const auto& [key, value] : run.record.metrics) {
      EXPECT_NEAR(by_v.metrics.at(key), value, 1e-10 * std::max(1.0, std::abs(value)))
          << name << " " << key;
    }
  }
}

// Files at halved steps give the order `geomint order` fits from the same runs.
TEST(Score, OrderOverHalvedStepsIsOrdersFit) {
  const auto problem = parse_problem("pendulum");
  std::vector<Trajectory> trajectories;
  std::vector<RunRecord> records;
  for (int k = 0; k < 4; ++k) {
    const RunAndSeries run = run_with_series(problem, "stormer_verlet", 0.1 * std::ldexp(1.0, -k),
                                             2, fmt::format("level{}", k));
    records.push_back(score_trajectory(*problem, run.trajectory, ScoreConfig{}));
    trajectories.push_back(run.trajectory);
  }
  const OrderFit fit = score_order(*problem, trajectories, records);
  const OrderStudy study =
      order_study(problem, MethodFactory("stormer_verlet"), 0.1, 4, 2, kDefaultDivergeFactor);
  EXPECT_EQ(fit.order, study.fit.order);
  EXPECT_NEAR(fit.order, 2, 0.05);
  // Files out of step order, or too few, are bad input.
  std::swap(trajectories[0], trajectories[1]);
  EXPECT_THROW(score_order(*problem, trajectories, records), InputError);
  trajectories.resize(2);
  records.resize(2);
  EXPECT_THROW(score_order(*problem, trajectories, records), InputError);
}

// Each check of the reader refuses its file with a message naming the line or row and column.
TEST(Score, ReaderRefusesDamagedFiles) {
  const auto problem = parse_problem("pendulum");
  const auto refused = [&](const std::string& file, const std::string& bytes,
                           const std::string& word) {
    write(scratch(file), bytes);
    try {
      read_trajectory(scratch(file).string(), *problem, kDefaultStartTolerance);
      ADD_FAILURE() << file << " was accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(word), std::string::npos)
          << file << ": " << error.what();
    }
  };
  refused("empty.csv", "", "empty");
  refused("truncated.csv", "t,q0,p0\n0,0.5,0\n0.1,0.49,0.1", "newline");
  refused("short.csv", "t,q0,p0\n0,0.5,0\n0.1,0.49\n", "line 3");
  refused("nan.csv", "t,q0,p0\n0,0.5,0\n0.1,nan,0.1\n", "line 3, column q0");
  refused("text.csv", "t,q0,p0\n0,0.5,0\n0.1,x,0.1\n", "not a number");
  refused("monotone.csv", "t,q0,p0\n0,0.5,0\n0.1,0.49,0.1\n0.1,0.48,0.1\n", "line 4, column t");
  refused("wide.csv", "t,q0,q1,p0,p1\n0,0.5,0,0,0\n0.1,0.49,0,0.1,0\n", "q1");
  refused("narrow.csv", "t,q0\n0,0.5\n0.1,0.49\n", "no column p0");
  refused("headerless.csv", "0,0.5,0\n0.1,0.49,0.1\n", "no header");
  refused("start.csv", "t,q0,p0\n0,0.6,0\n0.1,0.49,0.1\n", "initial state");
  refused("one_row.csv", "t,q0,p0\n0,0.5,0\n", "at least one step");
  refused("both.csv", "t,q0,p0,v0\n0,0.5,0,0\n0.1,0.49,0.1,0.1\n", "not both");
  const std::vector<double> good = {0, 0.5, 0, 0.1, 0.49, 0.1};
  std::string dtype = npy_bytes(good, 2, 3);
  dtype.replace(dtype.find("<f8"), 3, "<f4");
  refused("dtype.npy", dtype, "dtype");
  std::string fortran = npy_bytes(good, 2, 3);
  fortran.replace(fortran.find("False"), 5, "True ");
  refused("fortran.npy", fortran, "Fortran");
  refused("shape.npy", npy_bytes(good, 3, 2), "columns");
  refused("truncated.npy", npy_bytes(good, 2, 3).substr(0, npy_bytes(good, 2, 3).size() - 8),
          "cut short");
  refused("magic.npy", "t,q0,p0\n", "magic");
  refused("nan.npy",
          npy_bytes({0, 0.5, 0, 0.1, std::numeric_limits<double>::quiet_NaN(), 0.1}, 2, 3),
          "row 1, column q0");
  refused("start.npy", npy_bytes({0, 0.7, 0, 0.1, 0.49, 0.1}, 2, 3), "initial state");
  // The tolerance is the documented one: just inside passes, just outside fails.
  write(scratch("near.csv"), "t,q0,p0\n0,0.5000000004,0\n0.1,0.49,0.1\n");
  EXPECT_NO_THROW(read_trajectory(scratch("near.csv").string(), *problem, 1e-9));
  EXPECT_THROW(read_trajectory(scratch("near.csv").string(), *problem, 1e-10), InputError);
}

}  // namespace
}  // namespace score_test
}  // namespace geomint
