// Sharded sweeps and `geomint merge` (harness/shard.hpp, docs/CLUSTER.md "Running on a cluster"):
// a scene swept in 4 shards and merged writes the bytes of a single-machine sweep (date
// line aside; after --timing-only, wall_s too), and merge refuses a missing, a foreign and a
// duplicated shard, naming them and the resubmission command.
#include "harness/shard.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "harness/paths.hpp"
#include "harness/sweep.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace shard_test {
namespace {

namespace fs = std::filesystem;

const char* const kTables[] = {"summary.csv", "order.csv", "order_points.csv", "stability.csv",
                               "table.md"};

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The text without the lines that name when (and, for timed tables, where) it ran.
std::string without_date(const std::string& text) {
  std::istringstream lines(text);
  std::string out;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("# date: ", 0) != 0 && line.rfind("| date | ", 0) != 0 &&
        line.rfind("> geomint ", 0) != 0) {
      out += line + "\n";
    }
  }
  return out;
}

// The text with every cell of the column `name` emptied, in CSV (cells may be quoted) and in
// Markdown tables (cells between '|').
std::string without_column(const std::string& text, const std::string& name) {
  std::istringstream lines(text);
  std::string out;
  long csv_index = -1, markdown_index = -1;
  const auto split = [](const std::string& line, char separator) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      if (c == separator && !quoted) {
        cells.emplace_back();
      } else {
        cells.back() += c;
      }
    }
    return cells;
  };
  for (std::string line; std::getline(lines, line);) {
    const bool markdown = !line.empty() && line[0] == '|';
    if (line.empty() || line[0] == '#') {
      markdown_index = -1;
      out += line + "\n";
      continue;
    }
    auto cells = split(line, markdown ? '|' : ',');
    long& index = markdown ? markdown_index : csv_index;
    for (size_t i = 0; index < 0 && i < cells.size(); ++i) {
      if (cells[i] == name || cells[i] == " " + name + " ") index = static_cast<long>(i);
    }
    if (index >= 0 && index < static_cast<long>(cells.size())) cells[index] = "";
    std::string joined;
    for (size_t i = 0; i < cells.size(); ++i)
      joined += (i ? std::string(1, markdown ? '|' : ',') : "") + cells[i];
    out += joined + "\n";
  }
  return out;
}

class ShardedSweep : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    // CTest runs each test in its own process, in parallel: one folder per process.
    root_ = fs::path(testing::TempDir()) / fmt::format("geomint_sharded_sweep_{}", ::getpid());
    fs::remove_all(root_);
    for (const char* folder : {"plain", "timed", "sharded"}) {
      fs::create_directories(root_ / folder);
      fs::copy_file(fs::path(GEOMINT_SOURCE_DIR) / "tests/scenes/rerun/scene.toml",
                    root_ / folder / "scene.toml");
    }
    scene_ = new Scene(load_scene((root_ / "plain/scene.toml").string(), false));
    hash_ = scene_content_hash((root_ / "plain/scene.toml").string(), false);
    for (int i = 0; i < 4; ++i) run_shard(root_ / "sharded", i, hash_);
  }
  static void TearDownTestSuite() {
    delete scene_;
    scene_ = nullptr;
    fs::remove_all(root_);
  }
  // The single-machine sweep into `folder`, with or without its timing passes.
  static void sweep(const char* folder, bool timing) {
    SweepOptions options;
    options.out_dir = (root_ / folder).string();
    options.jobs = 2;
    options.progress = false;
    options.scene_name = "rerun";
    options.scene_hash = hash_;
    options.timing = timing;
    options.command_line =
        timing ? "geomint sweep scene.toml" : "geomint sweep scene.toml --no-timing";
    run_sweep(*scene_, options);
  }
  static void run_shard(const fs::path& out, int index, const std::string& hash) {
    SweepOptions options;
    options.out_dir = out.string();
    options.progress = false;
    options.scene_name = "rerun";
    options.shard_index = index;
    options.shard_count = 4;
    options.scene_hash = hash;
    options.command_line = fmt::format("geomint sweep scene.toml --shard {}/4 --no-timing", index);
    run_sweep(*scene_, options);
  }
  static MergeOptions merge_options(const fs::path& out) {
    MergeOptions options;
    options.out_dir = out.string();
    options.scene_hash = hash_;
    options.scene_name = "rerun";
    options.variant = "full";
    options.sbatch_path = "results/rerun/sweep.sbatch";
    return options;
  }
  // A copy of the four shards in its own folder, for a test to damage.
  static fs::path copy_of_shards(const std::string& name) {
    const fs::path out = root_ / name;
    fs::remove_all(out);
    fs::create_directories(out);
    fs::copy(root_ / "sharded/shards", out / "shards");
    return out;
  }
  // The refusal's message (empty when merge did not refuse).
  static std::string refusal(const fs::path& out) {
    try {
      merge_shards(*scene_, merge_options(out));
    } catch (const MergeRefused& refused) {
      return refused.what();
    }
    return "";
  }
  static inline fs::path root_;
  static inline Scene* scene_ = nullptr;
  static inline std::string hash_;
};

TEST_F(ShardedSweep, MergeOfFourShardsWritesTheBytesOfAPlainSweep) {
  sweep("plain", false);
  const fs::path out = copy_of_shards("merged");
  merge_shards(*scene_, merge_options(out));
  for (const char* table : kTables) {
    const std::string merged = read_text(out / table);
    ASSERT_FALSE(merged.empty()) << table;
    EXPECT_EQ(without_date(merged), without_date(read_text(root_ / "plain" / table))) << table;
  }
  // Every shard's host is listed apart from the tables.
  EXPECT_EQ(std::count(std::istreambuf_iterator<char>(std::ifstream(out / "hosts.csv").rdbuf()), {},
                       '\n'),
            5);
}

TEST_F(ShardedSweep, TimingOnlyAfterMergeWritesTheBytesOfATimedSweepButWallTimes) {
  sweep("timed", true);
  const fs::path out = copy_of_shards("timed_after_merge");
  fs::copy_file(root_ / "plain/scene.toml", out / "scene.toml");
  merge_shards(*scene_, merge_options(out));
  SweepOptions options;
  options.out_dir = out.string();
  options.progress = false;
  options.scene_name = "rerun";
  options.scene_hash = hash_;
  options.command_line = "geomint sweep scene.toml --timing-only";
  run_timing_only(*scene_, options);
  for (const char* table : kTables) {
    const std::string timed = read_text(root_ / "timed" / table);
    if (table == std::string("summary.csv")) {
      ASSERT_NE(timed.find(",wall_s"), std::string::npos);
    }
    // The timing statistics differ from run to run; their count does not.
    const auto untimed = [](std::string text) {
      for (const char* column : {"wall_s", "wall_s_min", "wall_s_iqr"}) {
        text = without_column(text, column);
      }
      return text;
    };
    EXPECT_EQ(untimed(without_date(read_text(out / table))), untimed(without_date(timed))) << table;
  }
}

TEST_F(ShardedSweep, ACompleteShardIsSkippedAndAForeignOneIsNot) {
  const auto tables = shard_tables(scene_units(*scene_).runs, scene_units(*scene_).orders,
                                   scene_units(*scene_).stability);
  EXPECT_EQ(tables.size(), 4u);
  EXPECT_TRUE(shard_complete((root_ / "sharded").string(), tables, {1, 4}, hash_));
  EXPECT_FALSE(shard_complete((root_ / "sharded").string(), tables, {1, 4}, "fnv1a64:other"));
  EXPECT_FALSE(shard_complete((root_ / "sharded").string(), tables, {1, 8}, hash_));
}

TEST_F(ShardedSweep, MergeRefusesAMissingShardNamingItAndTheResubmission) {
  const fs::path out = copy_of_shards("missing");
  fs::remove(out / "shards/order.2-of-4.csv");
  const std::string message = refusal(out);
  EXPECT_NE(message.find("shard 2/4: order.2-of-4.csv is missing"), std::string::npos) << message;
  EXPECT_NE(message.find("sbatch --array=2 results/rerun/sweep.sbatch"), std::string::npos)
      << message;
  EXPECT_FALSE(fs::exists(out / "summary.csv"));
}

TEST_F(ShardedSweep, MergeRefusesAShardOfAnotherSceneVersion) {
  const fs::path out = copy_of_shards("foreign");
  run_shard(out, 1, "fnv1a64:0000000000000000");
  const std::string message = refusal(out);
  EXPECT_NE(message.find("shard 1/4: summary.1-of-4.csv is of another scene version"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("sbatch --array=1 "), std::string::npos) << message;
}

// A shard cut short (a node lost while copying, a full disk) is refused like a missing one,
// naming the file and the line, never merged with its last row cut inside a number.
TEST_F(ShardedSweep, MergeRefusesAShardCutShortNamingTheLine) {
  const fs::path out = copy_of_shards("cut_short");
  const fs::path shard = out / "shards/summary.2-of-4.csv";
  std::string text = read_text(shard);
  ASSERT_GT(text.size(), 10u);
  text.resize(text.size() - 5);
  std::ofstream(shard, std::ios::trunc) << text;
  const std::string message = refusal(out);
  EXPECT_NE(message.find("shard 2/4: summary.2-of-4.csv cannot be read"), std::string::npos)
      << message;
  EXPECT_NE(message.find("no terminating newline"), std::string::npos) << message;
  EXPECT_NE(message.find("sbatch --array=2 "), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(out / "summary.csv"));
  // Nor is such a shard complete: a requeued task runs it again.
  const auto tables = shard_tables(scene_units(*scene_).runs, scene_units(*scene_).orders,
                                   scene_units(*scene_).stability);
  EXPECT_FALSE(shard_complete(out.string(), tables, {2, 4}, hash_));
}

TEST_F(ShardedSweep, MergeRefusesADuplicatedShard) {
  const fs::path out = copy_of_shards("duplicated");
  fs::copy_file(out / "shards/summary.0-of-4.csv", out / "shards/summary.3-of-4.csv",
                fs::copy_options::overwrite_existing);
  const std::string message = refusal(out);
  EXPECT_NE(message.find("shard 3/4: summary.3-of-4.csv holds shard 0/4"), std::string::npos)
      << message;
  EXPECT_NE(message.find("sbatch --array=3 "), std::string::npos) << message;
  // A stale set of another shard count would merge every unit twice.
  fs::copy_file(out / "shards/summary.0-of-4.csv", out / "shards/summary.0-of-2.csv");
  EXPECT_NE(refusal(out).find("different counts"), std::string::npos);
}

TEST(Shard, ParsesShardIdsAndRejectsOthers) {
  EXPECT_EQ(parse_shard("3/8").index, 3);
  EXPECT_EQ(parse_shard("3/8").count, 8);
  for (const char* bad : {"8/8", "-1/8", "3", "3/0", "a/b", "3/8x", ""}) {
    EXPECT_THROW(parse_shard(bad), InputError) << bad;
  }
}

TEST(Shard, TakesTheShardFromSlurmOrMpiEnvironments) {
  for (const char* name : {"SLURM_ARRAY_TASK_ID", "OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE",
                           "PMI_RANK", "PMI_SIZE"}) {
    ::unsetenv(name);
  }
  EXPECT_THROW(shard_from_env(8), InputError);
  ::setenv("PMI_RANK", "2", 1);
  ::setenv("PMI_SIZE", "5", 1);
  EXPECT_EQ(shard_from_env(0).index, 2);
  EXPECT_EQ(shard_from_env(0).count, 5);
  EXPECT_THROW(shard_from_env(4), InputError);  // --shards disagrees with the launcher
  // A resubmitted array task (--array=3) must take N from the script, not from Slurm.
  ::setenv("SLURM_ARRAY_TASK_ID", "3", 1);
  EXPECT_THROW(shard_from_env(0), InputError);
  EXPECT_EQ(shard_from_env(8).index, 3);
  EXPECT_EQ(shard_from_env(8).count, 8);
  ::setenv("SLURM_ARRAY_TASK_ID", "8", 1);
  EXPECT_THROW(shard_from_env(8), InputError);
  for (const char* name : {"SLURM_ARRAY_TASK_ID", "PMI_RANK", "PMI_SIZE"}) ::unsetenv(name);
}

TEST(Shard, MergedCommandIsTheSingleMachineSweepWithoutTiming) {
  EXPECT_EQ(merged_sweep_command("geomint sweep s.toml --shard 3/8 --no-timing"),
            "geomint sweep s.toml --no-timing");
  EXPECT_EQ(merged_sweep_command("geomint sweep s.toml --quick --shard-from-env --shards 8"),
            "geomint sweep s.toml --quick --no-timing");
  EXPECT_EQ(merged_sweep_command("geomint sweep s.toml --shard=1/2 --jobs 4"),
            "geomint sweep s.toml --jobs 4 --no-timing");
  // A quoted scene path stays one word, quoted again, through the split and the join.
  EXPECT_EQ(merged_sweep_command("geomint sweep 'x$(touch PWNED)/my s.toml' --shard 0/2"),
            "geomint sweep 'x$(touch PWNED)/my s.toml' --no-timing");
}

// Every word survives shell_quoted, a join with spaces and shell_words, and bash reads the
// joined line back as the same words: the property the provenance line and the resubmission
// advice rely on.
TEST(Shell, QuotedWordsSplitBackAndBashAgrees) {
  const std::vector<std::string> words = {"plain", "my results", "x$(touch PWNED)", "it's", "a\\b",
                                          "\"q\"", "`id`",       "semi;colon",      "*"};
  std::string line;
  for (const auto& word : words) line += (line.empty() ? "" : " ") + shell_quoted(word);
  EXPECT_EQ(shell_words(line), words);
  EXPECT_EQ(shell_words("a \"b c\" 'd e' f\\ g"),
            (std::vector<std::string>{"a", "b c", "d e", "f g"}));
  EXPECT_THROW(shell_words("a 'b"), InputError);
  const std::string script = "printf '%s\\n' " + line;
  FILE* pipe = ::popen(("bash -c " + shell_quoted(script)).c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  ASSERT_EQ(::pclose(pipe), 0);
  std::string expected;
  for (const auto& word : words) expected += word + "\n";
  EXPECT_EQ(output, expected);
}

// A message about an output keeps the file's name however deep its folder: CI runners put
// TMPDIR 100+ bytes deep, where a message cut after its first 100 bytes lost the name (a CI
// failure of the bad-input case SweepShardIsADirectory). A 100 kB path is still not printed whole.
TEST(Paths, MessageNamesTheFileUnderADeepFolder) {
  const fs::path deep = fs::temp_directory_path() / ("geomint_deep_" + std::to_string(::getpid())) /
                        std::string(150, 'd') / "shards";
  fs::create_directories(deep / "summary.0-of-1.csv");
  try {
    check_output_file((deep / "summary.0-of-1.csv").string(), "output");
    ADD_FAILURE() << "a folder was accepted as an output file";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("shards/summary.0-of-1.csv"), std::string::npos) << message;
    EXPECT_NE(message.find("is a directory"), std::string::npos) << message;
  }
  try {
    check_output_file(std::string(100000, 'x') + "/summary.csv", "output");
    ADD_FAILURE() << "a 100 kB path was accepted";
  } catch (const InputError& error) {
    EXPECT_LT(std::string(error.what()).size(), 1000u);
  }
  fs::remove_all(deep.parent_path().parent_path());
}

}  // namespace
}  // namespace shard_test
}  // namespace geomint
