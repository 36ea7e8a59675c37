// Accuracy gates: bands, canonical spec matching, gates that select nothing, malformed files,
// and the repository's own gates against the committed results.
#include "harness/gate.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "problems/spec.hpp"

namespace geomint {
namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("geomint_gate_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

const char* kResults =
    "# geomint: provenance line\n"
    "label,problem,method,dt,status,energy_err_max\n"
    "short,\"pendulum:omega0=1,theta0=0.5,v0=0\",\"implicit_euler:max_iter=50,tol=1e-12\",0.05,ok,"
    "0.9\n"
    "short,\"pendulum:omega0=1,theta0=0.5,v0=0\",stormer_verlet,0.05,ok,6e-4\n"
    "long,\"pendulum:omega0=1,theta0=0.5,v0=0\",stormer_verlet,0.05,nan,nan\n";

std::vector<GateOutcome> check(const std::string& gates_text) {
  static std::vector<Gate> gates;  // outcomes point into it
  gates = load_gates(write_temp("gates.toml", gates_text));
  return check_gates(gates, load_result_files({write_temp("summary.csv", kResults)}));
}

TEST(Gate, ValueInsideBandPassesAndOutsideFails) {
  const auto outcomes = check(R"(
[[gate]]
name = "inside"
where = { label = "short", method = "stormer_verlet" }
column = "energy_err_max"
max = 1e-3
[[gate]]
name = "outside"
where = { label = "short", method = "stormer_verlet" }
column = "energy_err_max"
max = 1e-4
)");
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_TRUE(outcomes[0].passed);
  EXPECT_EQ(outcomes[0].rows_checked, 1);
  EXPECT_FALSE(outcomes[1].passed);
}

TEST(Gate, SpecsMatchInCanonicalFormAndNumbersAsNumbers) {
  // "implicit_euler" (defaults omitted) must select "implicit_euler:max_iter=50,tol=1e-12";
  // problem keys in another order and dt written as 5e-2 must match too.
  const auto outcomes = check(R"(
[[gate]]
name = "canonical"
where = { method = "implicit_euler", problem = "pendulum:theta0=0.5", dt = 5e-2 }
column = "energy_err_max"
min = 0.5
)");
  EXPECT_TRUE(outcomes[0].passed);
  EXPECT_EQ(outcomes[0].rows_checked, 1);
}

TEST(Gate, GateSelectingNoRowFails) {
  const auto outcomes = check(R"(
[[gate]]
name = "typo"
where = { method = "rk4" }
column = "energy_err_max"
max = 1
)");
  EXPECT_FALSE(outcomes[0].passed);
  EXPECT_EQ(outcomes[0].rows_checked, 0);
}

TEST(Gate, NanFailsEveryBandAndStatusIsCheckedAsText) {
  const auto outcomes = check(R"(
[[gate]]
name = "nan"
where = { label = "long" }
column = "energy_err_max"
min = -1e300
[[gate]]
name = "status"
column = "status"
equals = "ok"
)");
  EXPECT_FALSE(outcomes[0].passed);
  EXPECT_FALSE(outcomes[1].passed);
  EXPECT_EQ(outcomes[1].rows_checked, 3);
}

TEST(Gate, FileFilterRestrictsRowsToMatchingPaths) {
  const auto outcomes = check(R"(
[[gate]]
name = "other file"
file = "order.csv"
column = "status"
equals = "ok"
)");
  EXPECT_FALSE(outcomes[0].passed);
  EXPECT_EQ(outcomes[0].rows_checked, 0);
}

TEST(Gate, MalformedGatesFilesAreInputErrorsNamingTheProblem) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\n", "min"},  // no bound
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\nmin = 2\nmax = 1\n", "above"},
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\nmax = 1\ncolour = 1\n", "colour"},
      {"[[gate]]\ncolumn = \"x\"\nmax = 1\n", "name"},
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\nmax = \"1\"\n", "max"},
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\nmax = 1\nwhere = { method = \"rk5\" }\n", "rk5"},
      {"[[gate]\n", "gates file"},
      {"title = \"x\"\n", "title"},
  };
  for (const auto& [text, needle] : cases) {
    try {
      load_gates(write_temp("bad.toml", text));
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(needle), std::string::npos)
          << error.what() << " should mention " << needle;
    }
  }
  EXPECT_THROW(load_result_files({"/nonexistent/summary.csv"}), InputError);
}

TEST(Gate, RepositoryGatesPassOnTheCommittedResults) {
  const std::filesystem::path root = GEOMINT_SOURCE_DIR;
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(root / "results")) {
    for (const char* name : {"summary.csv", "order.csv", "stability.csv"}) {
      if (std::filesystem::exists(entry.path() / name)) {
        files.push_back((entry.path() / name).string());
      }
    }
  }
  const auto gates = load_gates((root / "results" / "gates.toml").string());
  for (const auto& outcome : check_gates(gates, load_result_files(files))) {
    std::string detail;
    for (const auto& line : outcome.lines) detail += "\n  " + line;
    EXPECT_TRUE(outcome.passed) << outcome.gate->name << detail;
  }
}

}  // namespace
}  // namespace geomint
