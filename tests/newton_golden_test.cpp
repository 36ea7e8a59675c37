// Golden work and final states of the two Newton loops (integrators/newton.cpp's NewtonSolver and
// integrators/dense_newton.cpp): every registered fixed-step implicit method, on the general-kind
// problems (dense loop) and on separable ones (sparse solver), 20 steps against
// tests/golden/newton_work.csv: status and work counters exactly, the final q and p bit for bit
// (hex floats), so a change of either loop that moves one iteration or one rounding fails here.
// A method registered later fails until its rows are added; GEOMINT_WRITE_NEWTON_GOLDEN=1 rewrites
// the file (only for a change that is meant to move the numbers: say why in the commit).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace newton_golden_test {
namespace {

const char* const kGoldenFile = GEOMINT_SOURCE_DIR "/tests/golden/newton_work.csv";

// Joint angles, polar Kepler and the charged particle run the dense loop (non-separable L) of
// the methods that still have a general-kind step, and implicit_midpoint's one step through the
// sparse NewtonSolver; the pendulum and a spring chain the sparse NewtonSolver.
const std::vector<std::string>& golden_problems() {
  static const std::vector<std::string> problems = {"double_pendulum",
                                                    "kepler:coordinates=polar",
                                                    "rod_chain:coordinates=joint,n=3",
                                                    "charged_particle",
                                                    "pendulum",
                                                    "spring_chain:n=4,model=fpu_beta"};
  return problems;
}

std::string hex(const Vec& v) {
  std::string out;
  for (Eigen::Index i = 0; i < v.size(); ++i) out += fmt::format("{}{:a}", i ? " " : "", v[i]);
  return out;
}

// problem|method -> status|steps|force_evals|newton_iters|linear_solves|factorizations|q|p.
std::map<std::string, std::string> golden_runs() {
  std::map<std::string, std::string> runs;
  for (const std::string& method_spec : integrator_test_specs()) {
    const MethodInfo info = make_integrator(method_spec)->info();
    if (!(info.flags & kImplicit) || (info.flags & kAdaptive)) continue;
    for (const std::string& problem_spec : golden_problems()) {
      if (!applicable(*make_integrator(method_spec), *make_problem(problem_spec)).ok) continue;
      RunConfig config;
      config.dt = 0.02;
      config.t_end = 0.4;
      config.timing_repeats = 0;
      const RunResult result = run_one(problem_spec, method_spec, config);
      const Counters counters = result.record.counters.value_or(Counters{});
      runs[problem_spec + "|" + method_spec] = fmt::format(
          "{}|{}|{}|{}|{}|{}|{}|{}", result.record.status, result.record.steps.value_or(-1),
          counters.force_evals, counters.newton_iters, counters.linear_solves,
          counters.factorizations, hex(result.final_state.q), hex(result.final_state.p));
    }
  }
  return runs;
}

TEST(NewtonGolden, EveryImplicitMethodReproducesItsWorkAndFinalStateBitForBit) {
  const std::map<std::string, std::string> runs = golden_runs();
  ASSERT_GT(runs.size(), 20u) << "the registry lost its implicit methods?";
  if (std::getenv("GEOMINT_WRITE_NEWTON_GOLDEN")) {
    std::ofstream out(kGoldenFile);
    out << "# problem|method|status|steps|force_evals|newton_iters|linear_solves|"
           "factorizations|q|p (tests/newton_golden_test.cpp)\n";
    for (const auto& [key, value] : runs) out << key << "|" << value << "\n";
    GTEST_SKIP() << "wrote " << kGoldenFile;
  }
  std::map<std::string, std::string> golden;
  std::ifstream in(kGoldenFile);
  ASSERT_TRUE(in) << "cannot read " << kGoldenFile;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto second = line.find('|', line.find('|') + 1);
    golden[line.substr(0, second)] = line.substr(second + 1);
  }
  for (const auto& [key, value] : runs) {
    const auto it = golden.find(key);
    if (it == golden.end()) {
      ADD_FAILURE() << "no golden row for " << key << " (a new method? add: " << key << "|" << value
                    << ")";
    } else {
      EXPECT_EQ(value, it->second) << key;
    }
  }
  for (const auto& [key, value] : golden) {
    EXPECT_TRUE(runs.count(key)) << "golden row " << key << " no longer runs";
  }
}

}  // namespace
}  // namespace newton_golden_test
}  // namespace geomint
