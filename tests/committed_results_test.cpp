// The committed tables are regression data (docs/DESIGN.md §5): every cheap row of every
// results/<scene>/summary.csv is re-run from its (problem, method, dt, t_end) and must reproduce
// the committed status, counters and metrics, so a change that alters a published number fails
// until the scene is regenerated with `make reproduce-figures`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "harness/shard.hpp"
#include "harness/sweep.hpp"
#include "harness/table.hpp"

namespace geomint {
namespace committed_results_test {
namespace {

namespace fs = std::filesystem;

// A row is re-run when its committed timing pass took at most this long; rows without wall_s
// (timing disabled) are skipped, since their cost is unknown.
constexpr double kMaxRowWallSeconds = 0.02;
// Per-scene budget of committed wall time, so a scene with many cheap rows stays quick.
constexpr double kSceneBudgetSeconds = 2.0;

std::vector<std::string> scenes_with_summary() {
  std::vector<std::string> scenes;
  for (const auto& entry : fs::directory_iterator(fs::path(GEOMINT_SOURCE_DIR) / "results")) {
    if (fs::exists(entry.path() / "summary.csv")) {
      scenes.push_back(entry.path().filename().string());
    }
  }
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

bool parse_number(const std::string& text, double& value) {
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return !text.empty() && *end == '\0';
}

// Same binary arithmetic gives identical numbers; the relative slack only absorbs the 17-digit
// round trip through the CSV and libm differences between Debian 12 machines. Values at the
// round-off level (below kRoundoffFloor) only have to stay at that level.
constexpr double kRelativeTolerance = 1e-9;
constexpr double kRoundoffFloor = 1e-12;

bool same_metric(double committed, double rerun) {
  if (std::isnan(committed) || std::isnan(rerun)) return std::isnan(committed) == std::isnan(rerun);
  if (std::abs(committed) < kRoundoffFloor && std::abs(rerun) < kRoundoffFloor) return true;
  return std::abs(committed - rerun) <=
         kRelativeTolerance * std::max(std::abs(committed), std::abs(rerun));
}

class CommittedScene : public ::testing::TestWithParam<std::string> {};

TEST_P(CommittedScene, CheapRowsReproduce) {
  const fs::path path = fs::path(GEOMINT_SOURCE_DIR) / "results" / GetParam() / "summary.csv";
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::vector<Row> rows = parse_csv(text.str());
  ASSERT_FALSE(rows.empty()) << path << " has no rows";
  double spent = 0;
  int checked = 0;
  for (const Row& committed : rows) {
    double wall = 0;
    if (!committed.count("wall_s") || !parse_number(committed.at("wall_s"), wall)) continue;
    if (wall > kMaxRowWallSeconds || spent + wall > kSceneBudgetSeconds) continue;
    // A timeout row (wall_budget_s spent) ends where the clock did: its metrics are not
    // reproducible, only its status (results/<scene>/gates.toml checks it).
    if (committed.count("status") && committed.at("status") == "timeout") continue;
    spent += wall;
    RunConfig config;
    double t_end = 0;
    if (committed.count("dt")) parse_number(committed.at("dt"), config.dt);
    ASSERT_TRUE(parse_number(committed.at("t_end"), t_end)) << committed.at("t_end");
    config.t_end = t_end;
    config.timing_repeats = 0;
    config.reference_dir = (fs::path(GEOMINT_SOURCE_DIR) / "results" / "references").string();
    const RunResult rerun = run_one(committed.at("problem"), committed.at("method"), config);
    ++checked;
    const std::string where = committed.at("problem") + " / " + committed.at("method") +
                              " / dt=" + (committed.count("dt") ? committed.at("dt") : "-");
    for (const auto& [column, value] : to_row(rerun.record)) {
      // Timing columns are machine noise; `family` is a label derived from the method's flags
      // that tables written before it do not have yet.
      if (column.find("wall") != std::string::npos || column == "family") continue;
      ASSERT_TRUE(committed.count(column))
          << where << ": column " << column << " is not in the committed table; regenerate";
      double committed_number = 0, rerun_number = 0;
      if (parse_number(committed.at(column), committed_number) &&
          parse_number(value, rerun_number)) {
        EXPECT_TRUE(same_metric(committed_number, rerun_number))
            << where << ": " << column << " committed " << committed.at(column) << ", now "
            << value;
      } else {
        EXPECT_EQ(committed.at(column), value) << where << ": " << column;
      }
    }
  }
  EXPECT_GT(checked, 0) << "no row of " << path << " is cheap enough to re-run";
}

// Named by scene (Results/CommittedScene.CheapRowsReproduce/fig1_pendulum), so a filter can pick
// one scene and a failure says which.
// The committed tables are of the scene file beside them: table.md's "How to cite" block records
// the scene hash (scene_content_hash of scene.toml, comments included, as `geomint merge` checks
// shards), so a scene edited without regenerating its tables fails here instead of being cited
// with a hash no scene file has.
TEST_P(CommittedScene, TablesAreOfTheSceneFileBesideThem) {
  const fs::path folder = fs::path(GEOMINT_SOURCE_DIR) / "results" / GetParam();
  ASSERT_TRUE(fs::exists(folder / "table.md")) << folder / "table.md"
                                               << " is missing";
  const std::string recorded = recorded_scene_hash((folder / "table.md").string());
  ASSERT_FALSE(recorded.empty()) << folder / "table.md"
                                 << " records no scene hash";
  const std::string current = scene_content_hash((folder / "scene.toml").string(), false);
  EXPECT_EQ(recorded, current) << "results/" << GetParam()
                               << "/scene.toml changed after its tables were written; "
                               << "regenerate them: bash scripts/reproduce.sh build/geomint "
                               << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Results, CommittedScene, ::testing::ValuesIn(scenes_with_summary()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name;
                           for (char c : info.param)
                             name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

}  // namespace
}  // namespace committed_results_test
}  // namespace geomint
