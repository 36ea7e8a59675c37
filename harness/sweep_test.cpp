// Tests of the sweep writers (harness/sweep.hpp, docs/DESIGN.md §5): table.md shows short method
// and problem labels while the CSV keeps canonical specs, and `--markdown-only` rebuilds table.md
// from the CSVs byte for byte.
#include "harness/sweep.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>

#include "harness/report.hpp"
#include "harness/table.hpp"
#include "harness/toml_reader.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace sweep_test {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class SweepTables : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / "geomint_sweep_tables";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "scene.toml")
        << "title = \"t\"\n[[runs]]\nlabel = \"a\"\nproblems = [\"harmonic:omega=2\"]\n"
           "methods = [\"hp:alpha=0\", \"hp\", \"stormer_verlet\"]\ndt = 0.1\nt_end = 1.0\n"
           "timing_repeats = 0\n";
    scene_ = load_scene((dir_ / "scene.toml").string(), false);
    SweepOptions options;
    options.out_dir = dir_.string();
    options.progress = false;
    options.command_line = "geomint sweep scene.toml";
    options.scene_name = "tables_scene";
    options.scene_hash = "fnv1a64:00000000deadbeef";
    ASSERT_EQ(run_sweep(scene_, options), 0);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  Scene scene_;
};

TEST_F(SweepTables, MarkdownShowsShortLabelsAndCsvCanonicalSpecs) {
  const std::string csv = read_text(dir_ / "summary.csv");
  const std::string markdown = read_text(dir_ / "table.md");
  const std::string canonical_hp =
      "hp:alpha=0.5,force_at=midpoint,force_slot=split,max_iter=50,solver=minimize,tol=1e-12";
  EXPECT_NE(csv.find(canonical_hp), std::string::npos) << csv;
  EXPECT_NE(csv.find("harmonic:mass=1,omega=2"), std::string::npos) << csv;
  EXPECT_EQ(markdown.find("force_slot"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("| harmonic:omega=2 | hp:alpha=0 |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("| harmonic:omega=2 | hp |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("| harmonic:omega=2 | stormer_verlet |"), std::string::npos) << markdown;
}

// table.md ends with the "How to cite" block (docs/REPORT.md "Citing a table"): version and
// SHA of the tables' `# geomint:` line, scene, scene hash and date, none of them missing.
TEST_F(SweepTables, MarkdownEndsWithTheHowToCiteBlock) {
  const std::string markdown = read_text(dir_ / "table.md");
  const auto block = markdown.find("\n## How to cite\n");
  ASSERT_NE(block, std::string::npos) << markdown;
  const std::string cite = markdown.substr(block);
  const CsvTable summary = read_csv_file((dir_ / "summary.csv").string());
  const std::string geomint = summary.value("geomint");  // "VERSION (SHA)"
  const std::string version = geomint.substr(0, geomint.find(' '));
  const std::string sha =
      geomint.substr(geomint.find('(') + 1, geomint.size() - 2 - geomint.find('('));
  ASSERT_FALSE(version.empty());
  ASSERT_FALSE(sha.empty());
  for (const std::string& row :
       {"| geomint version | " + version + " |", "| git SHA | " + sha + " |",
        std::string("| scene | tables_scene (full variant) |"),
        std::string("| scene hash | fnv1a64:00000000deadbeef |"),
        "| date | " + summary.value("date") + " |"}) {
    EXPECT_NE(cite.find(row + "\n"), std::string::npos) << row << " in\n" << cite;
  }
  EXPECT_EQ(cite.find("(not recorded)"), std::string::npos) << cite;
  EXPECT_NE(cite.find("> geomint " + version + " (git " + sha + "), scene tables_scene"),
            std::string::npos)
      << cite;
}

// The description is plain text: rendered as Markdown (GitHub, the results site) it reads as
// written, with no emphasis, code, HTML or heading made of its punctuation.
TEST(SceneMarkdown, DescriptionIsTextNotMarkup) {
  Scene scene;
  scene.title = "t";
  scene.description =
      "h*omega < 2 for q_k *and* _p_ [x](y) `c` a|b ~~d~~ \\n\n# not a heading\n- nor a list";
  const std::string html = markdown_to_html(scene_markdown(scene, {}, "geomint sweep", {}));
  EXPECT_NE(html.find("<p>h*omega &lt; 2 for q_k *and* _p_ [x](y) `c` a|b ~~d~~ \\n\n# not a "
                      "heading\n- nor a list</p>"),
            std::string::npos)
      << html;
}

TEST_F(SweepTables, MarkdownOnlyRebuildsTheSameTableFromTheCsvs) {
  const std::string written = read_text(dir_ / "table.md");
  fs::remove(dir_ / "table.md");
  SweepOptions options;
  options.out_dir = dir_.string();
  options.scene_name = "tables_scene";
  options.scene_hash = "fnv1a64:00000000deadbeef";
  rewrite_scene_markdown(scene_, options);
  EXPECT_EQ(read_text(dir_ / "table.md"), written);
  fs::remove(dir_ / "summary.csv");
  EXPECT_THROW(rewrite_scene_markdown(scene_, options), InputError);
}

// A scene with every kind of table: runs (one diverging, one skipped), order studies (ladder
// points, fits, "n/a" multiplier orders) and a stability search.
constexpr const char* kAllTablesScene =
    "title = \"all tables\"\n"
    "[[runs]]\nlabel = \"runs\"\nproblems = [\"pendulum:theta0=1.5\", \"van_der_pol\"]\n"
    "methods = [\"stormer_verlet\", \"explicit_euler\", \"hp:alpha=0\"]\ndt = [0.1, 0.7]\n"
    "t_end = 20.0\ntiming_repeats = 0\n"
    "[[orders]]\nlabel = \"ladder\"\nproblems = [\"pendulum:theta0=1.5\"]\n"
    "methods = [\"stormer_verlet\", \"rk4\"]\ndt0 = 0.1\nlevels = 4\nt_end = 1.0\n"
    "[[stability]]\nlabel = \"limit\"\nproblems = [\"harmonic\"]\nmethods = [\"stormer_verlet\"]\n"
    "homega_min = 0.5\nhomega_max = 10.0\nmin_steps = 200\nperiods = 5.0\nrel_tol = 1e-2\n";

Scene write_all_tables_scene(const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "scene.toml") << kAllTablesScene;
  return load_scene((dir / "scene.toml").string(), false);
}

// sweep() returns the scene's tables in memory and writes every CSV from them: each file is
// to_csv() of its table byte for byte, the columns carry their types, and a real cell reads back
// as a number. Without an output folder the same rows come back and nothing is written.
TEST(SweepResult, InMemoryTablesAreTheWrittenFilesByteForByte) {
  const fs::path dir = fs::path(testing::TempDir()) / "geomint_sweep_in_memory";
  const Scene scene = write_all_tables_scene(dir);
  SweepOptions options;
  options.out_dir = (dir / "out").string();
  options.progress = false;
  options.command_line = "geomint sweep scene.toml";
  options.scene_name = "all_tables";
  options.jobs = 2;
  const SweepResult result = sweep(scene, options);
  EXPECT_GE(result.failed, 1);  // the diverging and skipped runs
  std::vector<std::string> names, files;
  for (const auto& table : result.tables) {
    names.push_back(table.name);
    EXPECT_EQ(to_csv(table), read_text(fs::path(options.out_dir) / (table.name + ".csv")))
        << table.name;
    EXPECT_EQ(table.value("scene"), "all_tables");
  }
  for (const auto& entry : fs::directory_iterator(options.out_dir)) {
    if (entry.path().extension() == ".csv") files.push_back(entry.path().stem().string());
  }
  std::sort(files.begin(), files.end());
  EXPECT_EQ(names, (std::vector<std::string>{"summary", "order", "order_points", "stability"}));
  EXPECT_EQ(files, (std::vector<std::string>{"order", "order_points", "stability", "summary"}));

  const ResultTable& summary = *result.table("summary");
  EXPECT_EQ(summary.column("dt")->type, ColumnType::kReal);
  EXPECT_EQ(summary.column("steps")->type, ColumnType::kInteger);
  EXPECT_EQ(summary.column("status")->type, ColumnType::kText);
  EXPECT_EQ(summary.number(0, "dt"), 0.1);
  const ResultTable& order = *result.table("order");
  EXPECT_EQ(order.column("declared_order")->type, ColumnType::kInteger);
  EXPECT_EQ(order.column("order")->type, ColumnType::kReal);
  EXPECT_EQ(order.rows[0].at("order_multiplier"), "n/a");
  EXPECT_EQ(order.number(0, "order_multiplier"), std::nullopt);
  EXPECT_EQ(result.table("stability")->column("runs")->type, ColumnType::kInteger);
  bool diverged = false;
  for (size_t row = 0; row < summary.rows.size(); ++row) {
    for (const auto& column : summary.columns) {
      const auto cell = summary.rows[row].find(column.name);
      if (column.type == ColumnType::kText || cell == summary.rows[row].end()) continue;
      // A number cell reads back as the double it was formatted from.
      ASSERT_TRUE(summary.number(row, column.name)) << column.name << " = " << cell->second;
      EXPECT_EQ(real_cell(*summary.number(row, column.name)), cell->second);
    }
    diverged = diverged || summary.rows[row].at("status") != "ok";
  }
  EXPECT_TRUE(diverged);

  SweepOptions in_memory = options;
  in_memory.out_dir.clear();
  const SweepResult again = sweep(scene, in_memory);
  ASSERT_EQ(again.tables.size(), result.tables.size());
  for (size_t i = 0; i < again.tables.size(); ++i) {
    EXPECT_EQ(again.tables[i].column_names(), result.tables[i].column_names());
    EXPECT_EQ(again.tables[i].rows, result.tables[i].rows) << again.tables[i].name;
  }
  EXPECT_EQ(again.failed, result.failed);
  fs::remove_all(dir);
}

// A skipped row says why with the short label table.md shows, not the canonical spec with
// every default: "method 'hp' integrates Lagrangian systems ...".
TEST(SweepSkippedRows, MessageNamesTheMethodByItsShortLabel) {
  const fs::path dir = fs::path(testing::TempDir()) / "geomint_sweep_skipped";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "scene.toml")
      << "title = \"t\"\n[[runs]]\nlabel = \"a\"\nproblems = [\"van_der_pol\"]\n"
         "methods = [\"hp:alpha=0\", \"rk4\"]\ndt = 0.1\nt_end = 0.5\ntiming_repeats = 0\n";
  const Scene scene = load_scene((dir / "scene.toml").string(), false);
  SweepOptions options;
  options.out_dir = dir.string();
  options.progress = false;
  options.command_line = "geomint sweep scene.toml";
  EXPECT_GE(run_sweep(scene, options), 1);  // the skipped row counts as failed
  const CsvTable summary = read_csv_file((dir / "summary.csv").string());
  ASSERT_EQ(summary.rows.size(), 2u);
  EXPECT_EQ(summary.rows[0].at("status"), "skipped");
  const std::string& message = summary.rows[0].at("message");
  EXPECT_EQ(message.rfind("method 'hp:alpha=0' integrates Lagrangian systems", 0), 0u) << message;
  EXPECT_EQ(message.find("force_slot"), std::string::npos) << message;
  fs::remove_all(dir);
}

// Scene and gates files share one reader: its messages name the block and the key.
// The heartbeat's ETA weighs units by expected steps (docs/CLI.md "sweep"): t_end/dt for a
// fixed-step run (at a non-unit scale), the ladder's sum for an order study, the scene's finest
// fixed step for an adaptive run.
TEST(SweepProgress, UnitsWeighExpectedSteps) {
  const fs::path dir = fs::path(testing::TempDir()) / "geomint_sweep_steps";
  fs::create_directories(dir);
  std::ofstream(dir / "scene.toml")
      << "title = \"t\"\n[[runs]]\nlabel = \"a\"\nproblems = [\"harmonic\"]\n"
         "methods = [\"stormer_verlet\"]\ndt = [0.004, 0.25]\nt_end = 7.0\n"
         "[[runs]]\nlabel = \"b\"\nproblems = [\"harmonic\"]\nmethods = [\"odeint_dopri5\"]\n"
         "t_end = 3.0\n"
         "[[orders]]\nlabel = \"c\"\nproblems = [\"harmonic\"]\nmethods = [\"rk4\"]\n"
         "dt0 = 0.5\nlevels = 3\nt_end = 2.0\n";
  const std::vector<double> steps =
      expected_unit_steps(load_scene((dir / "scene.toml").string(), false));
  ASSERT_EQ(steps.size(), 4u);
  EXPECT_DOUBLE_EQ(steps[0], 7.0 / 0.004);
  EXPECT_DOUBLE_EQ(steps[1], 7.0 / 0.25);
  EXPECT_DOUBLE_EQ(steps[2], 3.0 / 0.004);
  EXPECT_DOUBLE_EQ(steps[3], 2.0 / 0.5 * (1 + 2 + 4));
  fs::remove_all(dir);
}

TEST(TomlReader, MessagesNameBlockAndKey) {
  const toml::table table = toml::parse("n = 'x'\nk = 1\nextra = true\n");
  TomlBlock block(table, "file.toml: [[runs]] 'a'");
  EXPECT_EQ(block.integer("k", true, 0, 0, 5), 1);
  try {
    block.number("n", true);
    FAIL() << "a string read as a number";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "file.toml: [[runs]] 'a': key 'n' must be a number");
  }
  try {
    block.finish();
    FAIL() << "unknown key accepted";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "file.toml: [[runs]] 'a': unknown key 'extra' (allowed: k, n)");
  }
  EXPECT_THROW(block.integer("k", true, 0, 2, 5), InputError);
  EXPECT_THROW(block.string("missing", true), InputError);
}

// Every spec text a sweep reads is parsed once (scene.hpp's SpecBook): checking the scene, its
// runs with the optional metrics whose observers step the method themselves, the timing pass,
// an order study, a stability search and table.md's short labels all read the same objects.
// Counted where the registries parse (problems/spec.hpp's test hook).
std::mutex parse_count_mutex;
std::map<std::string, int> parse_counts;

void count_parse(const std::string& text) {
  const std::lock_guard<std::mutex> lock(parse_count_mutex);
  ++parse_counts[text];
}

TEST(SweepSpecs, EachSpecIsParsedOncePerSweep) {
  const fs::path dir = fs::path(testing::TempDir()) / "geomint_sweep_parse_once";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "scene.toml")
      << "title = \"t\"\n"
         "table_columns = [\"label\", \"problem\", \"method\", \"symplecticity_defect\", "
         "\"mode_freq_err_max\", \"modified_energy_err_max\", \"symplecticity_defect_map\", "
         "\"lyapunov_max\", \"megno\", \"valid_time\"]\n"
         "[[runs]]\nlabel = \"a\"\nproblems = [\"harmonic:omega=2\", \"kepler:e=0.3\", "
         "\"henon_heiles\"]\n"
         "methods = [\"stormer_verlet\", \"implicit_midpoint\"]\ndt = 0.05\nt_end = 0.5\n"
         "timing_repeats = 1\nquick_t_end = 0.25\n"
         "[[orders]]\nlabel = \"o\"\nproblems = [\"harmonic:omega=2\"]\n"
         "methods = [\"stormer_verlet\"]\ndt0 = 0.1\nlevels = 3\nt_end = 1.0\n"
         "[[stability]]\nlabel = \"s\"\nproblems = [\"harmonic\"]\nmethods = [\"stormer_verlet\"]\n"
         "homega_max = 10.0\nperiods = 10.0\nmin_steps = 100\n";
  {
    const std::lock_guard<std::mutex> lock(parse_count_mutex);
    parse_counts.clear();
  }
  set_spec_parse_hook(&count_parse);
  const Scene scene = load_scene((dir / "scene.toml").string(), false);
  SweepOptions options;
  options.out_dir = dir.string();
  options.progress = false;
  options.jobs = 2;
  options.command_line = "geomint sweep scene.toml";
  const int failed = run_sweep(scene, options);
  set_spec_parse_hook(nullptr);
  EXPECT_EQ(failed, 0);
  const CsvTable summary = read_csv_file((dir / "summary.csv").string());
  ASSERT_EQ(summary.rows.size(), 6u);
  // The observers ran (their columns are filled), so their parses were counted too.
  EXPECT_NE(summary.rows[0].at("symplecticity_defect"), "");
  EXPECT_NE(summary.rows[0].at("modified_energy_err_max"), "");
  EXPECT_NE(summary.rows[0].at("symplecticity_defect_map"), "");
  EXPECT_NE(summary.rows[0].at("lyapunov_max"), "");
  const std::lock_guard<std::mutex> lock(parse_count_mutex);
  for (const std::string text : {"harmonic:omega=2", "kepler:e=0.3", "henon_heiles", "harmonic",
                                 "stormer_verlet", "implicit_midpoint"}) {
    EXPECT_EQ(parse_counts[text], 1) << "'" << text << "'";
  }
  for (const auto& [text, count] : parse_counts) EXPECT_LE(count, 1) << "'" << text << "'";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sweep_test
}  // namespace geomint
