// Shards, merge and Slurm scripts (see shard.hpp; docs/CLUSTER.md "Running on a cluster").
#include "harness/shard.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "harness/output_folder.hpp"
#include "harness/paths.hpp"
#include "harness/record.hpp"
#include "harness/shard_files.hpp"
#include "harness/stability.hpp"
#include "harness/sweep.hpp"
#include "problems/spec.hpp"

namespace geomint {

namespace fs = std::filesystem;

namespace {

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(fmt::format("cannot read '{}'", path.string()));
  return text.str();
}

// Non-negative integer of a whole string, or -1.
long parse_count(const std::string& text) {
  if (text.empty() || text.size() > 9 ||
      !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return -1;
  }
  return std::stol(text);
}

std::string this_version() { return provenance("").front().second; }

// A shard table as read back: its `# key: value` lines, its header and its rows.
struct ShardTable {
  fs::path path;
  std::map<std::string, std::string> header;
  std::vector<std::string> columns;
  std::vector<Row> rows;
  std::string error;  // unreadable: why
};

ShardTable read_shard_table(const fs::path& path) {
  ShardTable table;
  table.path = path;
  try {
    CsvTable csv = read_csv_file(path.string());
    for (auto& [key, value] : csv.provenance) table.header[key] = value;
    table.columns = std::move(csv.columns);
    table.rows = std::move(csv.rows);
  } catch (const std::exception& error) {
    table.error = error.what();
  }
  return table;
}

// The resubmission advice of a refused merge.
std::string resubmission(const std::set<int>& shards, const MergeOptions& options,
                         const std::string& sweep_command, int count) {
  std::vector<std::string> indices;
  for (int i : shards) indices.push_back(std::to_string(i));
  std::string text = fmt::format("resubmit only these shards:\n  sbatch --array={} {}\n",
                                 fmt::join(indices, ","), shell_quoted(options.sbatch_path));
  if (!sweep_command.empty()) {
    text += fmt::format("  (without Slurm: for i in {}; do {} --shard $i/{}; done)\n",
                        fmt::join(indices, " "), sweep_command, count);
  }
  return text + fmt::format("then merge again: {}",
                            options.merge_command.empty()
                                ? fmt::format("geomint merge {}", shell_quoted(options.out_dir))
                                : options.merge_command);
}

}  // namespace

ShardId parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  const long index = slash == std::string::npos ? -1 : parse_count(text.substr(0, slash));
  const long count = slash == std::string::npos ? -1 : parse_count(text.substr(slash + 1));
  if (index < 0 || count < 1 || index >= count || count > kMaxShards) {
    throw InputError(fmt::format(
        "--shard '{}': expected i/N with 0 <= i < N <= {} (e.g. --shard 3/8, the fourth of "
        "eight)",
        text, kMaxShards));
  }
  return {static_cast<int>(index), static_cast<int>(count)};
}

ShardId shard_from_env(int count) {
  const auto get = [](const char* name) {
    const char* value = std::getenv(name);
    return value ? std::string(value) : std::string();
  };
  const std::pair<const char*, const char*> sources[] = {
      {"SLURM_ARRAY_TASK_ID", nullptr},
      {"OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE"},
      {"PMI_RANK", "PMI_SIZE"}};
  for (const auto& [rank_name, size_name] : sources) {
    const std::string rank = get(rank_name);
    if (rank.empty()) continue;
    long size = count;
    if (size_name) {
      const long from_env = parse_count(get(size_name));
      if (count > 0 && from_env != count) {
        throw InputError(
            fmt::format("--shards {} disagrees with {}={}", count, size_name, get(size_name)));
      }
      size = from_env;
    } else if (count <= 0) {
      throw InputError(fmt::format(
          "--shard-from-env with {}: give the number of shards with --shards N (a resubmitted "
          "array task cannot tell it)",
          rank_name));
    }
    const long index = parse_count(rank);
    if (index < 0 || size < 1 || index >= size || size > kMaxShards) {
      throw InputError(
          fmt::format("--shard-from-env: {}={} is not a shard of {}", rank_name, rank, size));
    }
    return {static_cast<int>(index), static_cast<int>(size)};
  }
  throw InputError(
      "--shard-from-env: none of SLURM_ARRAY_TASK_ID, OMPI_COMM_WORLD_RANK, PMI_RANK is set "
      "(run it as a Slurm array task or under mpirun/srun, or give --shard i/N)");
}

std::string scene_content_hash(const std::string& scene_path, bool quick) {
  std::string text = read_text(scene_path);
  text += quick ? "\nvariant=quick" : "\nvariant=full";
  // FNV-1a: stable across compilers and machines, which std::hash is not.
  std::uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return fmt::format("fnv1a64:{:016x}", hash);
}

std::string merged_sweep_command(const std::string& shard_command) {
  std::vector<std::string> words;
  try {
    words = shell_words(shard_command);
  } catch (const InputError&) {
    return shard_command;  // a provenance line, not input: shown as it was written
  }
  std::vector<std::string> kept;
  bool no_timing = false;
  for (size_t i = 0; i < words.size(); ++i) {
    const std::string& word = words[i];
    if (word == "--shard" || word == "--shards") {
      ++i;  // its value
    } else if (word.rfind("--shard=", 0) == 0 || word.rfind("--shards=", 0) == 0 ||
               word == "--shard-from-env") {
    } else {
      no_timing = no_timing || word == "--no-timing";
      kept.push_back(shell_quoted(word));
    }
  }
  if (!no_timing) kept.push_back("--no-timing");
  return fmt::format("{}", fmt::join(kept, " "));
}

bool shard_complete(const std::string& out_dir, const std::vector<std::string>& tables, ShardId id,
                    const std::string& scene_hash) {
  for (const auto& table : tables) {
    const fs::path path = shard_file(out_dir, table, id);
    if (!fs::exists(path)) return false;
    const ShardTable shard = read_shard_table(path);
    const auto value = [&](const char* key) {
      const auto found = shard.header.find(key);
      return found == shard.header.end() ? std::string() : found->second;
    };
    if (!shard.error.empty() || value("shard") != shard_text(id) ||
        value("scene_hash") != scene_hash || value("geomint") != this_version()) {
      return false;
    }
  }
  return true;
}

bool shard_fails_on_purpose(ShardId id) {
  const char* value = std::getenv("GEOMINT_FAIL_SHARD");
  return value && parse_count(value) == id.index;
}

std::string shards_variant(const std::string& out_dir) {
  const fs::path dir = fs::path(out_dir) / "shards";
  if (fs::is_directory(dir)) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".csv") continue;
      const ShardTable table = read_shard_table(entry.path());
      const auto found = table.header.find("variant");
      if (found != table.header.end()) return found->second;
    }
  }
  throw InputError(fmt::format(
      "'{}' holds no shard: run `geomint sweep SCENE --shard i/N --no-timing` (or sbatch "
      "sweep.sbatch from `geomint slurm`) first",
      dir.string()));
}

void merge_shards(const Scene& scene, const MergeOptions& options) {
  const SceneUnits units = scene_units(scene);
  const OutputFolderLock lock(options.out_dir, OutputFolderLock::Mode::kExclusive, "geomint merge");
  check_folder_scene(options.out_dir, options.scene_name);
  remove_stale_temporaries(scene, options.out_dir);
  const fs::path dir = fs::path(options.out_dir) / "shards";
  static const std::regex kName(R"(^([a-z_]+)\.([0-9]+)-of-([0-9]+)\.csv$)");
  // count → the file names of that count
  std::map<int, std::vector<std::string>> by_count;
  if (fs::is_directory(dir)) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      const std::string name = entry.path().filename().string();
      std::smatch match;
      if (std::regex_match(name, match, kName)) {
        by_count[static_cast<int>(parse_count(match[3]))].push_back(name);
      }
    }
  }
  if (by_count.empty()) {
    throw MergeRefused(fmt::format("no shard in '{}'\nsubmit the sweep: sbatch {}", dir.string(),
                                   options.sbatch_path));
  }
  if (by_count.size() > 1) {
    std::vector<std::string> sets;
    for (const auto& [count, names] : by_count) {
      sets.push_back(fmt::format("{} file(s) of {} shards", names.size(), count));
    }
    throw MergeRefused(fmt::format(
        "'{}' holds shards of different counts ({}): every unit would be merged twice; remove "
        "the stale set and merge again",
        dir.string(), fmt::join(sets, ", ")));
  }
  // Merge walks every shard id of the set: a count the file names claim is checked against the
  // cap and the scene before it sizes any loop or list.
  const int count = by_count.begin()->first;
  if (count < 1 || count > kMaxShards || static_cast<size_t>(count) > units.total()) {
    throw InputError(fmt::format(
        "'{}' holds shard files of {} shards ({}...): a sweep has 1 to {} shards, at most one "
        "per unit of the scene ({} units); remove them and run the sweep's shards again",
        dir.string(), count, by_count.begin()->second.front(), kMaxShards, units.total()));
  }
  const auto tables = shard_tables(units.runs, units.orders, units.stability);
  // The first index of each table's units in the canonical order, and how many it has.
  const std::map<std::string, std::pair<size_t, size_t>> ranges = {
      {"summary", {0, units.runs}},
      {"order", {units.runs, units.orders}},
      {"order_points", {units.runs, units.orders}},
      {"stability", {units.runs + units.orders, units.stability}}};
  const std::string version = this_version();
  std::vector<std::string> problems;
  std::set<int> bad;
  std::map<std::string, std::vector<std::pair<size_t, Row>>> rows;
  std::map<std::string, std::set<std::string>> columns;
  std::string sweep_command;
  std::vector<Row> hosts;
  for (int i = 0; i < count; ++i) {
    const ShardId id{i, count};
    for (const auto& table : tables) {
      const fs::path path = shard_file(options.out_dir, table, id);
      const std::string name = path.filename().string();
      if (!fs::exists(path)) {
        if (bad.insert(i).second) {
          problems.push_back(fmt::format("shard {}: {} is missing", shard_text(id), name));
        }
        continue;
      }
      const ShardTable shard = read_shard_table(path);
      const auto value = [&](const char* key) {
        const auto found = shard.header.find(key);
        return found == shard.header.end() ? std::string("(none)") : found->second;
      };
      std::string problem;
      if (!shard.error.empty()) {
        problem = fmt::format("{} cannot be read: {}", name, shard.error);
      } else if (value("shard") != shard_text(id)) {
        problem = fmt::format("{} holds shard {} (a duplicate of that shard's file)", name,
                              value("shard"));
      } else if (value("scene_hash") != options.scene_hash) {
        problem = fmt::format("{} is of another scene version (scene hash {}; the scene is now {})",
                              name, value("scene_hash"), options.scene_hash);
      } else if (value("geomint") != version) {
        problem = fmt::format("{} was written by geomint {}; this is geomint {}", name,
                              value("geomint"), version);
      }
      // Each shard must hold exactly its units (order_points: only its units, as a study
      // that threw has no points).
      const auto [first, size] = ranges.at(table);
      std::multiset<size_t> seen;
      for (const auto& row : shard.rows) {
        if (!problem.empty()) break;
        const auto found = row.find(kCanonicalIndexColumn);
        const long k = found == row.end() ? -1 : parse_count(found->second);
        if (k < static_cast<long>(first) || k >= static_cast<long>(first + size) ||
            k % count != i || (table != "order_points" && seen.count(k))) {
          problem = fmt::format("{} holds a row of unit {}, not one of shard {}'s", name,
                                found == row.end() ? "(none)" : found->second, shard_text(id));
        }
        seen.insert(static_cast<size_t>(k));
      }
      if (problem.empty() && table != "order_points") {
        size_t expected = 0;
        for (size_t k = first; k < first + size; ++k) expected += k % count == size_t(i);
        if (seen.size() != expected) {
          problem = fmt::format("{} holds {} of its {} units", name, seen.size(), expected);
        }
      }
      if (sweep_command.empty() && shard.header.count("command")) {
        sweep_command = merged_sweep_command(value("command"));
      }
      if (!problem.empty()) {
        // One line per shard: its other tables are rerun with it.
        if (bad.insert(i).second)
          problems.push_back(fmt::format("shard {}: {}", shard_text(id), problem));
        continue;
      }
      if (table == tables.front()) {
        hosts.push_back({{"shard", std::to_string(i)},
                         {"host", value("host")},
                         {"cpu", value("cpu")},
                         {"date", value("date")}});
      }
      for (const auto& column : shard.columns) {
        if (column != kCanonicalIndexColumn) columns[table].insert(column);
      }
      for (auto row : shard.rows) {
        const size_t k = std::stoul(row.at(kCanonicalIndexColumn));
        row.erase(kCanonicalIndexColumn);
        rows[table].emplace_back(k, std::move(row));
      }
    }
  }
  if (!problems.empty()) {
    throw MergeRefused(fmt::format("cannot merge {} of {} shard(s) in '{}':\n  {}\n{}", bad.size(),
                                   count, dir.string(), fmt::join(problems, "\n  "),
                                   resubmission(bad, options, sweep_command, count)));
  }

  // The tables, as run_sweep writes them: same rows, column order and provenance lines.
  auto lines = provenance(sweep_command);
  if (!options.scene_name.empty()) lines.emplace_back("scene", options.scene_name);
  lines.emplace_back("variant", options.variant);
  SceneTables merged;
  const auto table_rows = [&](const std::string& table) {
    auto& list = rows[table];
    std::stable_sort(list.begin(), list.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<Row> out;
    for (auto& [k, row] : list) out.push_back(std::move(row));
    return out;
  };
  const auto schema_columns = [&](const std::string& table, const auto& schema) {
    std::vector<std::string> out;
    for (const auto& column : schema) {
      if (columns[table].count(column.name)) out.push_back(column.name);
    }
    return out;
  };
  const fs::path out(options.out_dir);
  if (units.runs) {
    merged.summary = table_rows("summary");
    write_file_atomic((out / "summary.csv").string(),
                      to_csv(merged.summary, schema_columns("summary", record_schema()), lines));
  }
  if (units.orders) {
    merged.order = table_rows("order");
    write_file_atomic((out / "order.csv").string(),
                      to_csv(merged.order, schema_columns("order", order_schema()), lines));
    write_file_atomic(
        (out / "order_points.csv").string(),
        to_csv(table_rows("order_points"),
               order_points_columns(schema_columns("order_points", record_schema())), lines));
  }
  if (units.stability) {
    merged.stability = table_rows("stability");
    Row present;
    for (const auto& column : columns["stability"]) present[column];
    write_file_atomic(
        (out / "stability.csv").string(),
        to_csv(merged.stability, column_union({present}, stability_columns()), lines));
  }
  write_file_atomic(
      (out / "table.md").string(),
      scene_markdown(scene, merged, sweep_command, table_citation(lines, options.scene_hash)));
  write_file_atomic((out / "hosts.csv").string(),
                    to_csv(hosts, {"shard", "host", "cpu", "date"}, {}));
}

namespace {

// `text`, refused when it cannot stay on one line: an #SBATCH line ends at a newline, which no
// quoting carries, and a newline in a comment line would start a line of code.
const std::string& one_line(const std::string& text, const std::string& what) {
  for (char c : text) {
    if (std::iscntrl(static_cast<unsigned char>(c))) {
      throw InputError(
          fmt::format("slurm: {} '{}' holds a control character (a newline, tab, ...), which a "
                      "line of a Slurm script cannot carry; rename it",
                      what, text));
    }
  }
  return text;
}

// A value of an `#SBATCH --key=value` line. sbatch, not bash, reads these lines: it groups by
// quotes, takes a backslash as an escape even inside quotes and starts a comment at a bare `#`.
std::string sbatch_quoted(const std::string& text, const std::string& what) {
  if (plain_word(one_line(text, what))) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// A file name pattern of --output: Slurm expands `%` sequences, `%%` is a literal `%`, and a
// backslash anywhere turns the expansion off (the %A_%a of the log names with it).
std::string sbatch_output_path(const std::string& path) {
  if (path.find('\\') != std::string::npos) {
    throw InputError(fmt::format(
        "slurm: the log folder '{}' holds a backslash, which Slurm reads in --output as \"no "
        "file name patterns\"; rename the folder",
        path));
  }
  std::string out;
  for (char c : path) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

}  // namespace

std::vector<std::string> write_slurm_scripts(const SlurmOptions& options) {
  const fs::path folder = fs::absolute(options.scene_path).parent_path();
  const std::string scene_name = folder.filename().string();
  const bool own_out = !options.out_dir.empty();
  const fs::path out_dir = own_out         ? fs::absolute(options.out_dir).lexically_normal()
                           : options.quick ? folder / "quick"
                                           : folder;
  const fs::path scripts_dir = own_out ? out_dir : folder;
  // The sweep, merge and timing lines name the folder when it is not the scene's default.
  const std::string out_words =
      own_out ? " --out " + shell_quoted(one_line(out_dir.string(), "--out")) : "";
  const std::string cwd = fs::current_path().string();
  const std::string quick = options.quick ? " --quick" : "";
  const fs::path logs = out_dir / "slurm-logs";
  // Every path and value reaches the scripts through these, refused before any file is written.
  // The comment lines carry the paths too: a newline there would start a line of code.
  const std::string scene_comment = shell_quoted(one_line(options.scene_path, "the scene path"));
  const std::string sweep_comment = shell_quoted((scripts_dir / "sweep.sbatch").string());
  const std::string logs_value = sbatch_output_path(logs.string());
  one_line(cwd, "the working folder");
  const std::string partition =
      options.partition.empty() ? "" : sbatch_quoted(options.partition, "--partition");
  const std::string time_limit =
      options.time_limit.empty() ? "" : sbatch_quoted(options.time_limit, "--time");
  const auto header = [&](const std::string& what, const std::string& job) {
    std::string text = fmt::format(
        "#!/bin/bash\n# {} job of {} (written by `geomint slurm`; docs/CLUSTER.md \"Running on a "
        "cluster\").\n# {}\n#SBATCH --job-name={}\n#SBATCH --output={}\n",
        job, scene_comment, what,
        sbatch_quoted(fmt::format("geomint-{}-{}", job, scene_name), "the scene folder"),
        sbatch_quoted(fmt::format("{}/{}-{}.out", logs_value, job, job == "sweep" ? "%A_%a" : "%j"),
                      "the log folder"));
    if (!partition.empty()) text += fmt::format("#SBATCH --partition={}\n", partition);
    if (!time_limit.empty()) text += fmt::format("#SBATCH --time={}\n", time_limit);
    return text;
  };
  fs::create_directories(logs);  // Slurm does not create the folder of --output
  const std::string body_start = fmt::format("set -euo pipefail\ncd {}\n", shell_quoted(cwd));
  const std::string geomint = shell_quoted(options.geomint_path);
  const std::string scene = shell_quoted(options.scene_path);
  const std::string array = options.max_parallel > 0
                                ? fmt::format("0-{}%{}", options.shards - 1, options.max_parallel)
                                : fmt::format("0-{}", options.shards - 1);
  const std::string sweep =
      header(fmt::format("Accuracy runs in {} shards: array task i runs the units k with k mod {} "
                         "== i.\n# A complete shard on disk is skipped, so requeued tasks are "
                         "safe; resubmit single shards with\n#   sbatch --array=3,7 {}",
                         options.shards, options.shards, sweep_comment),
             "sweep") +
      fmt::format(
          "#SBATCH --array={}\n#SBATCH --requeue\n#SBATCH --ntasks=1\n"
          "#SBATCH --cpus-per-task={}\n",
          array, options.jobs) +
      body_start +
      fmt::format("exec {} sweep {}{}{} --shard-from-env --shards {} --no-timing{}\n", geomint,
                  scene, quick, out_words, options.shards,
                  options.jobs > 1 ? fmt::format(" --jobs {}", options.jobs) : "");
  const std::string merge =
      header(
          "Merge of the shards into the scene's tables (submit with "
          "--dependency=afterok:<sweep job>)",
          "merge") +
      "#SBATCH --ntasks=1\n" + body_start +
      fmt::format("exec {} merge {}{}\n", geomint, shell_quoted(out_dir.string()),
                  own_out ? " --scene " + scene : "");
  const std::string timing =
      header(
          "Timing passes, one at a time on one whole node, pinned (submit with "
          "--dependency=afterok:<merge job>)",
          "timing") +
      "#SBATCH --exclusive\n#SBATCH --nodes=1\n#SBATCH --ntasks=1\n" + body_start +
      fmt::format("exec srun --cpu-bind=cores --ntasks=1 {} sweep {}{}{} --timing-only\n", geomint,
                  scene, quick, out_words);
  std::vector<std::string> paths;
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"sweep.sbatch", sweep}, {"merge.sbatch", merge}, {"timing.sbatch", timing}}) {
    paths.push_back((scripts_dir / name).string());
    write_file_atomic(paths.back(), text);
  }
  return paths;
}

std::string submit_sbatch(const std::string& script, const std::string& after) {
  const std::string command = fmt::format(
      "sbatch --parsable{} {} 2>&1",
      after.empty() ? "" : fmt::format(" --dependency=afterok:{}", after), shell_quoted(script));
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) throw InputError(fmt::format("cannot run '{}'", command));
  std::string output;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = ::pclose(pipe);
  while (!output.empty() && (output.back() == '\n' || output.back() == '\r')) output.pop_back();
  const std::string id = output.substr(0, output.find(';'));  // "id;cluster" on multi-cluster
  if (status != 0 || id.empty() || parse_count(id) < 0) {
    throw InputError(
        fmt::format("`{}` failed: {}", command, output.empty() ? "no output" : output));
  }
  return id;
}

}  // namespace geomint
