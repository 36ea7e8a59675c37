// Every CSV table the harness writes is read back by the one reader (read_csv_file) and its
// numbers compared bit for bit with what the writer was given: a writer that prints fewer than
// 17 significant digits (a gate then compares a rounded value; a merge or --timing-only rewrite
// loses the digits for good) fails here. Values are chosen so that no shorter print survives:
// 1/3, 1e-300, the smallest subnormal 2^-1074, 0.1 + 0.2. Also: the reader's refusal of damaged
// tables and the removal of stale temporaries (harness/table.hpp).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "harness/record.hpp"
#include "harness/reference.hpp"
#include "harness/reference_generator.hpp"
#include "harness/run.hpp"
#include "harness/run_spec.hpp"
#include "harness/shard_files.hpp"
#include "harness/stability.hpp"
#include "harness/table.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace table_roundtrip_test {
namespace {

namespace fs = std::filesystem;

const double kThird = 1.0 / 3.0;
const double kSubnormal = std::numeric_limits<double>::denorm_min();  // 2^-1074

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) /
                       ("geomint_roundtrip_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The cell, parsed as the gates and the merge parse it, must be the very double written.
void expect_bits(double expected, const Row& row, const std::string& column,
                 const std::string& table) {
  const auto found = row.find(column);
  ASSERT_NE(found, row.end()) << table << ": no cell '" << column << "'";
  char* end = nullptr;
  const double read = std::strtod(found->second.c_str(), &end);
  ASSERT_EQ(*end, '\0') << table << ": '" << column << "' = '" << found->second << "'";
  EXPECT_EQ(std::bit_cast<std::uint64_t>(read), std::bit_cast<std::uint64_t>(expected))
      << table << ": column '" << column << "' reads back " << found->second << ", written "
      << fmt::format("{:.17g}", expected);
}

// The metric columns of the run record: standard_columns() from energy_err_max to
// perihelion_err (harness/record.cpp spells them there).
std::vector<std::string> metric_names() {
  const auto& all = standard_columns();
  const auto first = std::find(all.begin(), all.end(), "energy_err_max");
  const auto last = std::find(all.begin(), all.end(), "perihelion_err");
  return {first, last + 1};
}

// A run record whose every real-valued field holds a value that needs all 17 digits.
RunRecord hard_record(std::map<std::string, double>& expected) {
  RunRecord record;
  record.label = "a";
  record.problem = "harmonic";
  record.method = "stormer_verlet";
  record.status = "ok";
  record.steps = 3;
  record.dt = expected["dt"] = kThird;
  record.t_end = expected["t_end"] = kSubnormal;
  record.t_reached = expected["t_reached"] = 1e-300 / 3;
  record.wall_s = expected["wall_s"] = 0.1 + 0.2;
  int k = 0;
  for (const auto& name : metric_names()) {
    const double value = (1 + k) / 3.0 * std::pow(10.0, 11 * k - 150);
    record.metrics[name] = expected[name] = value;
    ++k;
  }
  record.counters = Counters{};
  return record;
}

// Columns of the run record that are not real numbers (text, integers, counters).
bool is_text_or_integer(const std::string& column) {
  static const std::set<std::string> names = {"label",       "problem",   "method",
                                              "status",      "message",   "steps",
                                              "order_level", "reference", "canonical_index"};
  const auto& all = standard_columns();
  const auto counters = std::find(all.begin(), all.end(), "force_evals");
  return names.count(column) || std::find(counters, all.end(), column) != all.end();
}

void expect_record_columns(const CsvTable& table, const std::map<std::string, double>& expected) {
  ASSERT_EQ(table.rows.size(), 1u) << table.path;
  for (const auto& [column, cell] : table.rows.front()) {
    if (is_text_or_integer(column)) continue;
    const auto value = expected.find(column);
    ASSERT_NE(value, expected.end())
        << table.path << ": real column '" << column
        << "' is not covered by this test: give it a value in hard_record()";
    expect_bits(value->second, table.rows.front(), column, table.path);
  }
  for (const auto& [column, value] : expected) {
    expect_bits(value, table.rows.front(), column, table.path);
  }
}

TEST(TableRoundTrip, SummaryAndRunOutRows) {
  const fs::path dir = scratch("summary");
  std::map<std::string, double> expected;
  const std::vector<RunRecord> records = {hard_record(expected)};
  const std::string path = (dir / "summary.csv").string();
  write_file_atomic(path, records_to_csv(records, provenance("test")));
  expect_record_columns(read_csv_file(path), expected);
  fs::remove_all(dir);
}

TEST(TableRoundTrip, OrderAndOrderPoints) {
  const fs::path dir = scratch("order");
  OrderRecord order;
  order.label = "o";
  order.problem = "harmonic";
  order.method = "rk4";
  order.ran = true;
  order.order = 4;  // the fitted orders are shown to 3 decimals by design (record.cpp)
  order.declared_order = 4;
  order.points_used = {kThird, 1e-300, kSubnormal};
  order.status = "ok";
  order.t_end = 0.1 + 0.2;
  const std::string path = (dir / "order.csv").string();
  write_file_atomic(path, to_csv(to_rows(std::vector<OrderRecord>{order}),
                                 columns_of(order_schema(), std::vector<OrderRecord>{order}), {}));
  const CsvTable table = read_csv_file(path);
  ASSERT_EQ(table.rows.size(), 1u);
  expect_bits(*order.t_end, table.rows.front(), "t_end", path);
  std::vector<std::string> points;
  for (std::string rest = table.rows.front().at("points_used"); !rest.empty();) {
    const auto space = rest.find(' ');
    points.push_back(rest.substr(0, space));
    rest = space == std::string::npos ? "" : rest.substr(space + 1);
  }
  ASSERT_EQ(points.size(), order.points_used.size());
  for (size_t i = 0; i < points.size(); ++i) {
    expect_bits(order.points_used[i], {{"dt", points[i]}}, "dt", path + " points_used");
  }

  std::map<std::string, double> expected;
  RunRecord point = hard_record(expected);
  point.order_level = 2;
  const std::string points_path = (dir / "order_points.csv").string();
  write_file_atomic(points_path,
                    to_csv(to_rows(std::vector<RunRecord>{point}),
                           record_columns(std::vector<RunRecord>{point}), provenance("test")));
  expect_record_columns(read_csv_file(points_path), expected);
  fs::remove_all(dir);
}

TEST(TableRoundTrip, ShardTablesAndHosts) {
  const fs::path dir = scratch("shards");
  std::map<std::string, double> expected;
  const std::vector<RunRecord> records = {hard_record(expected)};
  write_shard_table(dir.string(), "summary", ShardId{1, 3}, "fnv1a64:0", to_rows(records), {4},
                    record_columns(records), provenance("test"));
  const CsvTable shard = read_csv_file(shard_file(dir.string(), "summary", ShardId{1, 3}));
  expect_record_columns(shard, expected);
  EXPECT_EQ(shard.rows.front().at(kCanonicalIndexColumn), "4");
  EXPECT_EQ(shard.value("shard"), "1/3");
  fs::remove_all(dir);
}

TEST(TableRoundTrip, StabilityRows) {
  StabilityOptions options;
  options.homega_min = 0.5;
  options.homega_max = 4;
  options.periods = 10;
  options.min_steps = 100;
  options.growth = 1 + kThird;
  const StabilityResult result =
      stability_search(*parse_problem("harmonic"), MethodFactory("stormer_verlet"), options);
  const fs::path dir = scratch("stability");
  const std::string path = (dir / "stability.csv").string();
  write_file_atomic(path, to_csv({result.row}, column_union({result.row}, stability_columns()),
                                 provenance("test")));
  const CsvTable table = read_csv_file(path);
  ASSERT_EQ(table.rows.size(), 1u);
  expect_bits(options.growth, table.rows.front(), "growth", path);
  expect_bits(result.homega_limit, table.rows.front(), "homega_max_measured", path);
  expect_bits(result.predicted, table.rows.front(), "predicted", path);
  expect_bits(result.homega_limit / result.predicted - 1, table.rows.front(), "rel_diff", path);
  fs::remove_all(dir);
}

// The series and the reference file start at the initial state, which the test knows exactly:
// q0 = 1/3 and its energy 1/18.
const std::string kHarmonicThird = "harmonic:q0=" + format_number(kThird);

TEST(TableRoundTrip, SeriesRows) {
  const fs::path dir = scratch("series");
  RunConfig config;
  config.dt = 0.1;
  config.t_end = 1;
  config.timing_repeats = 0;
  config.series_path = (dir / "series.csv").string();
  ASSERT_TRUE(run_one(kHarmonicThird, "stormer_verlet", config).ok);
  const CsvTable table = read_csv_file(config.series_path);
  ASSERT_GE(table.rows.size(), 2u);
  const auto problem = make_problem(kHarmonicThird);
  const State start = problem->initial_state();
  expect_bits(start.q[0], table.rows.front(), "q_0", config.series_path);
  expect_bits(problem->energy(start.q, start.p), table.rows.front(), "energy", config.series_path);
  fs::remove_all(dir);
}

TEST(TableRoundTrip, ReferenceFileRows) {
  const fs::path dir = scratch("reference");
  ReferenceOptions options;
  options.problem_spec = kHarmonicThird;
  options.t_end = 1;
  options.out_path = (dir / "reference.csv").string();
  generate_reference(options);
  const CsvTable table = read_csv_file(options.out_path);
  ASSERT_GE(table.rows.size(), 2u);
  const auto problem = make_problem(kHarmonicThird);
  expect_bits(problem->initial_state().q[0], table.rows.front(), "q_0", options.out_path);
  // And through the reference loader the runs use.
  const auto reference = load_reference(options.out_path, *problem);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(static_cast<double>(reference->q.front()[0])),
            std::bit_cast<std::uint64_t>(problem->initial_state().q[0]));
  // A reference file cut short is refused, not loaded with a last row read in part.
  std::string text;
  {
    std::ifstream in(options.out_path);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  text.resize(text.size() - 3);
  std::ofstream(options.out_path, std::ios::trunc) << text;
  try {
    load_reference(options.out_path, *problem);
    ADD_FAILURE() << "a reference file cut short was loaded";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("no terminating newline"), std::string::npos)
        << error.what();
  }
  fs::remove_all(dir);
}

// The reader refuses what no writer produces, naming the source and the line.
TEST(CsvReader, RefusesDamagedTablesNamingTheLine) {
  const auto message = [](const std::string& text) {
    try {
      parse_csv(text, "t.csv");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message("# a: b\nx,y\n1,2\n"), "accepted");
  EXPECT_EQ(message("x,y\n\"1,5\",\"a \"\"b\"\"\"\n"), "accepted");
  EXPECT_NE(message("x,y\n1,2\n3").find("'t.csv' line 3: "), std::string::npos);
  EXPECT_NE(message("x,y\n1\n").find("'t.csv' line 2: 1 fields, the header has 2"),
            std::string::npos);
  EXPECT_NE(message("x,y\n1,2,3\n").find("line 2"), std::string::npos);
  EXPECT_NE(message("x,y\n\"1,2\n").find("not closed"), std::string::npos);
  EXPECT_NE(message("x,y\n\"1\"2,3\n").find("after the closing quote"), std::string::npos);
  EXPECT_NE(message("# a: b\n").find("no header"), std::string::npos);
  EXPECT_NE(message("").find("no header"), std::string::npos);
  const auto rows = parse_csv("x,y\r\n\"1,5\",\"a \"\"b\"\"\"\r\n,2\r\n");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("x"), "1,5");
  EXPECT_EQ(rows[0].at("y"), "a \"b\"");
  EXPECT_EQ(rows[1].count("x"), 0u);
}

// A rerun removes only the temporaries of its own outputs whose process is gone: a PID is looked
// up only on the machine and in the PID namespace that issued it (the tag in the name); another
// node's temporary on a shared file system is debris only once it is a day old.
TEST(StaleTemporaries, OnlyDeadWritersOfTheGivenOutputs) {
  const fs::path dir = scratch("stale");
  const std::string dead = "2147483646", self = std::to_string(::getpid()),
                    parent = std::to_string(::getppid()), here = ".h" + temporary_host_tag(),
                    elsewhere = ".h0123456789abcdef";
  ASSERT_NE(here, elsewhere);
  const std::vector<std::string> removed = {"summary.csv." + dead + ".0" + here + ".tmp",
                                            "table.md." + dead + ".12" + here + ".tmp"};
  const std::vector<std::string> removed_old = {
      "summary.csv." + dead + ".3" + elsewhere + ".tmp",  // another node's, a day old
      "summary.csv." + dead + ".4.tmp"};                  // untagged (older geomint), a day old
  const std::vector<std::string> kept = {
      "summary.csv." + self + ".0" + here + ".tmp",       // this process is writing it
      "summary.csv." + parent + ".1" + here + ".tmp",     // a live process is writing it
      "summary.csv." + dead + ".5" + elsewhere + ".tmp",  // another node's live writer
      "summary.csv." + dead + ".6.tmp",                   // untagged, fresh
      "other.csv." + dead + ".0" + here + ".tmp",         // not an output of this writer
      "summary.csv." + dead + ".x" + here + ".tmp",       // not the writer's pattern
      "summary.csv.tmp",
      "summary.csv"};
  for (const auto& name : removed) std::ofstream(dir / name) << "x";
  for (const auto& name : kept) std::ofstream(dir / name) << "x";
  for (const auto& name : removed_old) {
    std::ofstream(dir / name) << "x";
    fs::last_write_time(dir / name, fs::file_time_type::clock::now() - kForeignTemporaryAge -
                                        std::chrono::minutes(1));
  }
  const size_t count = remove_stale_temporaries(dir.string(), [](const std::string& name) {
    return name == "summary.csv" || name == "table.md";
  });
  EXPECT_EQ(count, removed.size() + removed_old.size());
  for (const auto& name : removed) EXPECT_FALSE(fs::exists(dir / name)) << name;
  for (const auto& name : removed_old) EXPECT_FALSE(fs::exists(dir / name)) << name;
  for (const auto& name : kept) EXPECT_TRUE(fs::exists(dir / name)) << name;
  fs::remove_all(dir);
}

// The writer's temporaries carry the tag the remover compares.
TEST(StaleTemporaries, WriterNamesCarryThisMachinesTag) {
  const fs::path dir = scratch("tagged");
  AtomicFileWriter writer((dir / "t.csv").string());
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  ASSERT_EQ(names.size(), 1u);
  const std::string suffix = ".h" + temporary_host_tag() + ".tmp";
  EXPECT_EQ(names[0].rfind("t.csv." + std::to_string(::getpid()) + ".", 0), 0u) << names[0];
  EXPECT_EQ(names[0].substr(names[0].size() - suffix.size()), suffix) << names[0];
  writer.commit();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace table_roundtrip_test
}  // namespace geomint
