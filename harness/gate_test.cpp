// Accuracy gates: bands, canonical spec matching, gates that select nothing, malformed files,
// and the repository's own gates against the committed results.
#include "harness/gate.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "harness/metrics.hpp"
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

TEST(Gate, TableFilterRestrictsRowsToThatTable) {
  const auto outcomes = check(R"(
[[gate]]
name = "other table"
table = "order"
column = "status"
equals = "ok"
)");
  EXPECT_TRUE(outcomes[0].applicable);
  EXPECT_FALSE(outcomes[0].passed);
  EXPECT_EQ(outcomes[0].rows_checked, 0);
}

// A scene folder as `geomint sweep` writes it: results/<scene>/ and results/<scene>/quick/.
std::filesystem::path write_scene_tables(const std::string& scene, const std::string& variant,
                                         const std::string& energy_err_max) {
  const auto folder = std::filesystem::temp_directory_path() /
                      ("geomint_gate_" + std::to_string(::getpid())) / "elsewhere" / variant;
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "summary.csv")
      << "# geomint: provenance line\n# scene: " << scene << "\n# variant: " << variant
      << "\nlabel,method,status,energy_err_max\nshort,stormer_verlet,ok," << energy_err_max << "\n";
  return folder;
}

const char* kSceneGates = R"(
[[gate]]
name = "sv full and quick"
scene = "fig1"
table = "summary"
where = { method = "stormer_verlet" }
column = "energy_err_max"
max = 1e-3
quick_max = 1e-2
[[gate]]
name = "full only"
scene = "fig1"
variants = ["full"]
column = "status"
equals = "ok"
[[gate]]
name = "another scene"
scene = "momentum"
column = "status"
equals = "ok"
)";

TEST(Gate, ScenesAndVariantsComeFromProvenanceAndQuickBandsApplyToQuickRuns) {
  static std::vector<Gate> gates;
  gates = load_gates(write_temp("scene_gates.toml", kSceneGates));
  // 5e-3: outside the full band, inside the quick one.
  const auto quick = write_scene_tables("fig1", "quick", "5e-3");
  auto outcomes = check_gates(gates, load_result_files({quick.string()}));
  ASSERT_EQ(outcomes.size(), 3u);
  EXPECT_TRUE(outcomes[0].applicable);
  EXPECT_TRUE(outcomes[0].passed) << outcomes[0].lines.front();
  EXPECT_FALSE(outcomes[1].applicable);  // full only
  EXPECT_FALSE(outcomes[2].applicable);  // scene not given: not a failure
  EXPECT_TRUE(outcomes[2].passed);
  const auto full = write_scene_tables("fig1", "full", "5e-3");
  outcomes = check_gates(gates, load_result_files({full.string()}));
  EXPECT_FALSE(outcomes[0].passed);
  EXPECT_TRUE(outcomes[1].applicable);
  EXPECT_TRUE(outcomes[1].passed);
  // A quick band that the value leaves fails the quick run too.
  outcomes =
      check_gates(gates, load_result_files({write_scene_tables("fig1", "quick", "0.05").string()}));
  EXPECT_FALSE(outcomes[0].passed);
}

TEST(Gate, ScenesComeFromThePathWhenTheFileHasNoSceneLine) {
  const auto root =
      std::filesystem::temp_directory_path() / ("geomint_gate_path_" + std::to_string(::getpid()));
  for (const char* folder : {"order_basic", "order_basic/quick", "basic"}) {
    std::filesystem::create_directories(root / folder);
    std::ofstream(root / folder / "order.csv") << "label,method,order\npendulum,rk4,4.0\n";
  }
  const auto files = load_result_files(
      {(root / "order_basic" / "order.csv").string(), (root / "order_basic" / "quick").string()});
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].scene, "order_basic");
  EXPECT_EQ(files[0].variant, "full");
  EXPECT_EQ(files[0].table, "order");
  EXPECT_EQ(files[1].scene, "order_basic");
  EXPECT_EQ(files[1].variant, "quick");
  // The legacy `file` key names a scene and a table: "basic/order.csv" is not
  // "order_basic/order.csv" (a path-suffix match took it for one).
  static std::vector<Gate> gates;
  gates = load_gates(write_temp("legacy.toml", R"(
[[gate]]
name = "basic"
file = "basic/order.csv"
column = "order"
min = 3.5
)"));
  auto outcomes = check_gates(gates, files);
  EXPECT_FALSE(outcomes[0].applicable);
  outcomes = check_gates(gates, load_result_files({(root / "basic").string()}));
  EXPECT_TRUE(outcomes[0].applicable);
  EXPECT_TRUE(outcomes[0].passed);
  EXPECT_EQ(outcomes[0].rows_checked, 1);
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
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\nmin = nan\n", "NaN"},
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\nmax = 1\nquick_min = 2\n", "quick_min"},
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\nmax = 1\nvariants = [\"ci\"]\n", "variants"},
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\nmax = 1\nfile = \"order.csv\"\n", "scene"},
      // A summary or order gate names a column of that table's schema (a metric of the table).
      {"[[gate]]\nname = \"a\"\ntable = \"summary\"\ncolumn = \"energy_error_max\"\nmax = 1\n",
       "'energy_error_max' is not a column of table 'summary'"},
      {"[[gate]]\nname = \"a\"\ntable = \"order\"\ncolumn = \"energy_err_max\"\nmax = 1\n",
       "'energy_err_max' is not a column of table 'order'"},
      {"[[gate]]\nname = \"a\"\ncolumn = \"x\"\nmax = 1\n[[gate]]\nname = \"a\"\ncolumn = "
       "\"x\"\nmax = 1\n",
       "twice"},
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
  // Every metric of the table is a column a summary gate may name.
  for (const auto& name : metric_names()) {
    EXPECT_NO_THROW(load_gates(write_temp(
        "metric.toml",
        "[[gate]]\nname = \"a\"\ntable = \"summary\"\ncolumn = \"" + name + "\"\nmax = 1\n")))
        << name;
  }
  EXPECT_THROW(load_result_files({"/nonexistent/summary.csv"}), InputError);
  // A folder without tables is an input error naming it, not a gate that "selects no row".
  const auto empty =
      std::filesystem::temp_directory_path() / ("geomint_gate_empty_" + std::to_string(::getpid()));
  std::filesystem::create_directories(empty);
  EXPECT_THROW(load_result_files({empty.string()}), InputError);
  EXPECT_THROW(load_gates(empty.string()), InputError);
}

TEST(Gate, RepositoryGatesPassOnTheCommittedResults) {
  const std::filesystem::path root = GEOMINT_SOURCE_DIR;
  std::vector<std::string> folders;
  for (const auto& entry : std::filesystem::directory_iterator(root / "results")) {
    // Every scene folder, the LONG_SCENES of `make reproduce-all` included: a scene committed
    // without its tables fails here (its gates would find no rows).
    if (std::filesystem::exists(entry.path() / "scene.toml")) {
      folders.push_back(entry.path().string());
    }
  }
  const auto gates = load_gates((root / "results" / "gates.toml").string());
  int applicable = 0;
  for (const auto& outcome : check_gates(gates, load_result_files(folders))) {
    std::string detail;
    for (const auto& line : outcome.lines) detail += "\n  " + line;
    EXPECT_TRUE(outcome.passed) << outcome.gate->name << detail;
    applicable += outcome.applicable;
  }
  // Every gate gates the committed (full) tables, except those written for the quick runs only.
  int quick_only = 0;
  for (const auto& gate : gates) quick_only += gate.variants == std::vector<std::string>{"quick"};
  EXPECT_EQ(applicable + quick_only, static_cast<int>(gates.size()));
}

}  // namespace
}  // namespace geomint
