// Accuracy gates: bands, canonical spec matching, gates that select nothing, malformed files,
// and the repository's own gates against the committed results.
#include "harness/gate.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "harness/metrics.hpp"
#include "harness/scene.hpp"
#include "harness/sweep.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace gate_test {
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

// A scratch folder of gates files: relative path → text.
std::filesystem::path write_tree(const std::string& name,
                                 const std::vector<std::pair<std::string, std::string>>& files) {
  const auto root = std::filesystem::temp_directory_path() /
                    ("geomint_gate_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(root);
  for (const auto& [path, text] : files) {
    std::filesystem::create_directories((root / path).parent_path());
    std::ofstream(root / path) << text;
  }
  return root;
}

std::string gate_block(const std::string& name, const std::string& scene) {
  return "[[gate]]\nname = '" + name + "'\nscene = '" + scene + "'\ncolumn = 'x'\nmin = 0\n";
}

// Includes resolve against the including file's folder, patterns match sorted names, a file's
// own gates come before those it includes, and each gate records the file it came from.
TEST(Gate, IncludesResolveBesideTheIncludingFileInOrder) {
  const auto root = write_tree(
      "include",
      {{"all.toml", "include = ['results/*/gates.toml', 'extra.toml']\n" + gate_block("top", "")},
       {"extra.toml", gate_block("extra", "b")},
       {"results/b/gates.toml", gate_block("b1", "b") + gate_block("b2", "b")},
       {"results/a/gates.toml", gate_block("a1", "a")},
       {"results/a/notes.toml", gate_block("not included", "a")}});
  const auto gates = load_gates((root / "all.toml").string());
  std::vector<std::string> names, files;
  for (const auto& gate : gates) {
    names.push_back(gate.name);
    files.push_back(std::filesystem::relative(gate.file, root).generic_string());
  }
  EXPECT_EQ(names, (std::vector<std::string>{"top", "a1", "b1", "b2", "extra"}));
  EXPECT_EQ(files,
            (std::vector<std::string>{"all.toml", "results/a/gates.toml", "results/b/gates.toml",
                                      "results/b/gates.toml", "extra.toml"}));
  // A scene's own file read directly gives the same gates as through the include.
  const auto own = load_gates((root / "results" / "b" / "gates.toml").string());
  ASSERT_EQ(own.size(), 2u);
  EXPECT_EQ(own[0].name, "b1");
  std::filesystem::remove_all(root);
}

// Each malformed include is an input error naming the file at fault.
TEST(Gate, BadIncludesAreInputErrorsNamingTheFile) {
  const auto expect_error = [](const std::filesystem::path& path, const std::string& words) {
    try {
      load_gates(path.string());
      ADD_FAILURE() << path << ": no error, expected one with '" << words << "'";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
    }
  };
  auto root = write_tree("missing", {{"g.toml", "include = ['a/gates.toml']\n"}});
  expect_error(root / "g.toml", "g.toml': include 'a/gates.toml': no such file");
  root = write_tree("nomatch", {{"g.toml", "include = ['*/gates.toml']\n"}});
  expect_error(root / "g.toml", "matches no file");
  root = write_tree("cycle", {{"g.toml", "include = ['a/g.toml']\n"},
                              {"a/g.toml", "include = ['../b.toml']\n" + gate_block("x", "")},
                              {"b.toml", "include = ['./g.toml']\n"}});
  expect_error(root / "g.toml", "b.toml': include './g.toml' is a cycle");
  root = write_tree("self", {{"g.toml", "include = ['g.toml']\n" + gate_block("x", "")}});
  expect_error(root / "g.toml", "is a cycle");
  root = write_tree(
      "diamond", {{"g.toml", "include = ['a.toml', '*.toml']\n"}, {"a.toml", gate_block("a", "")}});
  expect_error(root / "g.toml", "which is already included");
  root = write_tree("twice", {{"g.toml", "include = ['a.toml', 'b.toml']\n"},
                              {"a.toml", gate_block("same", "a")},
                              {"b.toml", gate_block("same", "b")}});
  expect_error(root / "g.toml", "b.toml', gate 'same': name used twice (also in gates file");
  root = write_tree("empty", {{"g.toml", "include = ['a.toml']\n"}, {"a.toml", "# nothing\n"}});
  expect_error(root / "g.toml", "a.toml': no [[gate]] blocks and no 'include'");
  root = write_tree("type", {{"g.toml", "include = 'a.toml'\n"}, {"a.toml", gate_block("a", "")}});
  expect_error(root / "g.toml", "include");
  root = write_tree("scene", {{"s/scene.toml", "title = 's'\n"},
                              {"s/gates.toml", gate_block("a", "s") + gate_block("b", "t")}});
  expect_error(root / "s" / "gates.toml", "gate 'b': scene 't' is not the scene of the folder");
  std::filesystem::remove_all(root);
}

// The repository's gates sit beside their scenes: results/gates.toml includes every
// results/<scene>/gates.toml, each of whose gates is of that scene, and every scene has one.
TEST(Gate, RepositoryGatesLiveInTheirScenesFolders) {
  const std::filesystem::path results = std::filesystem::path(GEOMINT_SOURCE_DIR) / "results";
  std::map<std::string, int> per_file;
  for (const auto& gate : load_gates((results / "gates.toml").string())) {
    const std::filesystem::path file(gate.file);
    EXPECT_EQ(file.filename(), "gates.toml") << gate.name;
    EXPECT_EQ(gate.scene, file.parent_path().filename().string()) << gate.name;
    ++per_file[gate.scene];
  }
  for (const auto& entry : std::filesystem::directory_iterator(results)) {
    if (!std::filesystem::exists(entry.path() / "scene.toml")) continue;
    const std::string scene = entry.path().filename().string();
    EXPECT_TRUE(std::filesystem::exists(entry.path() / "gates.toml")) << scene << " has no gates";
    EXPECT_GT(per_file[scene], 0) << scene;
    EXPECT_EQ(load_gates((entry.path() / "gates.toml").string()).size(),
              static_cast<std::size_t>(per_file[scene]))
        << scene;
  }
}

// The gates on a sweep's tables in memory give the verdicts they give on the files the sweep
// wrote, line for line: one passing, one failing, one on the order table, one not applicable.
TEST(Gate, VerdictsOnInMemoryTablesAreThoseOnTheWrittenFiles) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("geomint_gate_in_memory_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "scene.toml")
      << "title = \"t\"\n[[runs]]\nlabel = \"short\"\nproblems = [\"pendulum:theta0=0.5\"]\n"
         "methods = [\"stormer_verlet\", \"explicit_euler\"]\ndt = 0.05\nt_end = 2.0\n"
         "timing_repeats = 0\n[[orders]]\nlabel = \"ladder\"\nproblems = [\"pendulum\"]\n"
         "methods = [\"stormer_verlet\"]\ndt0 = 0.1\nlevels = 4\nt_end = 1.0\n";
  const Scene scene = load_scene((dir / "scene.toml").string(), true);
  SweepOptions options;
  options.out_dir = (dir / "quick").string();
  options.progress = false;
  options.command_line = "geomint sweep scene.toml --quick";
  options.scene_name = "mem";
  options.variant = "quick";
  const SweepResult result = sweep(scene, options);
  static std::vector<Gate> gates;  // outcomes point into it
  gates = load_gates(write_temp("in_memory_gates.toml", R"(
[[gate]]
name = "verlet keeps energy"
scene = "mem"
table = "summary"
where = { method = "stormer_verlet" }
column = "energy_err_max"
max = 1e-2
[[gate]]
name = "euler fails a tight band"
scene = "mem"
where = { method = "explicit_euler" }
column = "energy_err_max"
max = 1e-12
[[gate]]
name = "second order"
scene = "mem"
table = "order"
column = "order"
min = 1.9
max = 2.1
[[gate]]
name = "another scene"
scene = "other"
column = "status"
equals = "ok"
)"));
  const auto from_files = check_gates(gates, load_result_files({options.out_dir}));
  const auto in_memory = check_gates(gates, result_files(result.tables, options.out_dir));
  ASSERT_EQ(in_memory.size(), 4u);
  ASSERT_EQ(from_files.size(), 4u);
  for (size_t i = 0; i < in_memory.size(); ++i) {
    EXPECT_EQ(in_memory[i].applicable, from_files[i].applicable) << gates[i].name;
    EXPECT_EQ(in_memory[i].passed, from_files[i].passed) << gates[i].name;
    EXPECT_EQ(in_memory[i].rows_checked, from_files[i].rows_checked) << gates[i].name;
    EXPECT_EQ(in_memory[i].lines, from_files[i].lines) << gates[i].name;
  }
  EXPECT_TRUE(in_memory[0].passed);
  EXPECT_FALSE(in_memory[1].passed);
  EXPECT_TRUE(in_memory[2].passed) << in_memory[2].lines.front();
  EXPECT_FALSE(in_memory[3].applicable);
  std::filesystem::remove_all(dir);
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
}  // namespace gate_test
}  // namespace geomint
