// Command-line contract (DESIGN.md §4): bad input exits 2 with a message naming what was wrong
// and writes no output file; good input works; the README's tables match `geomint list`.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "integrators/integrator.hpp"

namespace geomint {
namespace {

namespace fs = std::filesystem;

struct Outcome {
  int exit_code;
  std::string output;  // stdout and stderr
};

Outcome geomint(const std::string& arguments) {
  const std::string command = std::string(GEOMINT_BINARY) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "geomint_cli_test";
  fs::create_directories(dir);
  fs::remove_all(dir / name);
  return dir / name;
}

struct BadInput {
  std::string arguments;
  std::string must_mention;
};

class BadRunInput : public testing::TestWithParam<BadInput> {};

TEST_P(BadRunInput, ExitsTwoNamesTheInputAndWritesNothing) {
  const fs::path out = scratch("bad.csv");
  const Outcome outcome = geomint(GetParam().arguments + " --out " + out.string());
  EXPECT_EQ(outcome.exit_code, 2) << outcome.output;
  EXPECT_NE(outcome.output.find(GetParam().must_mention), std::string::npos) << outcome.output;
  EXPECT_FALSE(fs::exists(out));
}

INSTANTIATE_TEST_SUITE_P(
    Cli, BadRunInput,
    testing::Values(
        BadInput{"run --problem pendulum --method nosuch --dt 0.1 --t-end 1", "stormer_verlet"},
        BadInput{"run --problem nosuch --method rk4 --dt 0.1 --t-end 1", "kepler"},
        BadInput{"run --problem pendulum --method rk4:colour=red --dt 0.1 --t-end 1", "colour"},
        BadInput{"run --problem pendulum:theta0=abc --method rk4 --dt 0.1 --t-end 1", "theta0"},
        BadInput{"run --problem kepler:e=1.5 --method rk4 --dt 0.1 --t-end 1", "e=1.5"},
        BadInput{"run --problem pendulum --method rk4 --dt 0 --t-end 1", "--dt"},
        BadInput{"run --problem pendulum --method rk4 --dt -0.1 --t-end 1", "--dt"},
        BadInput{"run --problem pendulum --method rk4 --dt 0.1 --t-end 0", "--t-end"},
        BadInput{"run --problem pendulum --method rk4 --dt abc --t-end 1", "--dt"},
        BadInput{"run --problem 'pendulum:' --method rk4 --dt 0.1 --t-end 1", "malformed"},
        BadInput{"order --problem pendulum --method rk4 --dt 0.1 --levels 2 --t-end 1",
                 "--levels"}));

TEST(Cli, BadSceneExitsTwoAndWritesNothing) {
  const fs::path folder = scratch("scene");
  fs::create_directories(folder);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"title = 'x'\n[[runs]]\nlabel = 'a'\nproblems = [\n", "malformed"},
      {"title = 'x'\n[[runs]]\nlabel = 'a'\nmethods = ['rk4']\ndt = 0.1\nt_end = 1.0\n",
       "problems"},
      {"title = 'x'\n[[runs]]\nlabel = 'a'\nproblems = ['kepler']\nmethods = ['rk4']\n"
       "dt = 0.1\nt_end = -1.0\n",
       "t_end"},
  };
  for (const auto& [text, needle] : cases) {
    std::ofstream(folder / "scene.toml") << text;
    const Outcome outcome = geomint("sweep " + (folder / "scene.toml").string());
    EXPECT_EQ(outcome.exit_code, 2) << outcome.output;
    EXPECT_NE(outcome.output.find(needle), std::string::npos) << outcome.output;
    EXPECT_FALSE(fs::exists(folder / "summary.csv"));
    EXPECT_FALSE(fs::exists(folder / "table.md"));
  }
}

TEST(Cli, RunWritesOneRowWithProvenance) {
  const fs::path out = scratch("run.csv");
  const Outcome outcome = geomint(
      "run --problem harmonic --method stormer_verlet --dt 0.1 "
      "--t-end 1 --timing-repeats 1 --out " +
      out.string());
  ASSERT_EQ(outcome.exit_code, 0) << outcome.output;
  std::ifstream in(out);
  std::string line, header;
  int provenance = 0, data = 0;
  while (std::getline(in, line)) {
    if (line.rfind("# ", 0) == 0) {
      ++provenance;
    } else if (header.empty()) {
      header = line;
    } else {
      ++data;
    }
  }
  EXPECT_GE(provenance, 5);
  EXPECT_EQ(data, 1);
  EXPECT_NE(header.find("energy_err_max"), std::string::npos);
  EXPECT_NE(header.find("wall_s"), std::string::npos);
  // Harmonic has no angular momentum: the column is left out, not written as zero.
  EXPECT_EQ(header.find("angular_momentum_err_max"), std::string::npos);
}

TEST(Cli, SeriesHasStateColumnsAndEndsAtTEnd) {
  const fs::path series = scratch("series.csv");
  const Outcome outcome = geomint(
      "run --problem kepler --method rk4 --dt 0.1 --t-end 1.05 "
      "--timing-repeats 0 --series " +
      series.string() + " --every 3");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.output;
  std::ifstream in(series);
  std::string line, header, last;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) continue;
    if (header.empty()) {
      header = line;
    } else {
      last = line;
    }
  }
  EXPECT_EQ(header, "t,energy,angular_momentum_0,q_0,q_1,p_0,p_1");
  EXPECT_EQ(last.substr(0, last.find(',')), "1.05");
}

TEST(Cli, FailedRunIsARowWithExitOne) {
  // Explicit Euler on a stiff harmonic oscillator at hω = 10 blows up.
  const Outcome outcome = geomint(
      "run --problem harmonic:omega=100 --method explicit_euler "
      "--dt 0.1 --t-end 100 --timing-repeats 0");
  EXPECT_EQ(outcome.exit_code, 1) << outcome.output;
  EXPECT_NE(outcome.output.find(",diverged,"), std::string::npos) << outcome.output;
}

std::set<std::string> readme_table_names(const std::string& marker) {
  std::ifstream in(std::string(GEOMINT_SOURCE_DIR) + "/README.md");
  std::string line;
  bool inside = false;
  std::set<std::string> names;
  const std::regex row(R"(^\| `([a-z0-9_]+)`)");
  while (std::getline(in, line)) {
    if (line.find("<!-- " + marker + ":begin -->") != std::string::npos) inside = true;
    if (line.find("<!-- " + marker + ":end -->") != std::string::npos) inside = false;
    std::smatch match;
    if (inside && std::regex_search(line, match, row)) names.insert(match[1]);
  }
  return names;
}

TEST(Cli, GateExitsZeroOnPassOneOnFailTwoOnBadInput) {
  const std::string root = GEOMINT_SOURCE_DIR;
  const std::string results = root + "/results/fig1_pendulum/summary.csv";
  const fs::path passing = scratch("passing_gates.toml");
  std::ofstream(passing) << "[[gate]]\nname = \"fig1 runs\"\ncolumn = \"status\"\nequals = "
                            "\"ok\"\n";
  const Outcome passed = geomint("gate " + passing.string() + " " + results);
  EXPECT_EQ(passed.exit_code, 0) << passed.output;
  const fs::path failing = scratch("failing_gates.toml");
  std::ofstream(failing) << "[[gate]]\nname = \"too strict\"\nwhere = { method = "
                            "\"stormer_verlet\", label = \"short\" }\ncolumn = "
                            "\"energy_err_max\"\nmax = 1e-9\n";
  const Outcome failed = geomint("gate " + failing.string() + " " + results);
  EXPECT_EQ(failed.exit_code, 1) << failed.output;
  EXPECT_NE(failed.output.find("FAIL too strict"), std::string::npos) << failed.output;
  const fs::path malformed = scratch("malformed_gates.toml");
  std::ofstream(malformed) << "[[gate]]\nname = \"x\"\ncolumn = \"status\"\n";
  const Outcome bad = geomint("gate " + malformed.string() + " " + results);
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("min"), std::string::npos) << bad.output;
  EXPECT_EQ(geomint("gate " + failing.string() + " /nonexistent.csv").exit_code, 2);
}

TEST(Readme, MethodAndProblemTablesMatchTheRegistry) {
  std::set<std::string> methods, problems;
  for (const auto& entry : integrator_registry()) methods.insert(entry.name);
  for (const auto& entry : problem_registry()) problems.insert(entry.name);
  EXPECT_EQ(readme_table_names("methods"), methods);
  EXPECT_EQ(readme_table_names("problems"), problems);
  const Outcome listing = geomint("list");
  for (const auto& name : methods) EXPECT_NE(listing.output.find(name), std::string::npos);
  for (const auto& name : problems) EXPECT_NE(listing.output.find(name), std::string::npos);
}

}  // namespace
}  // namespace geomint
