// Bit-identical reruns (docs/DESIGN.md §3 "accuracy runs may run in parallel"):
// the built `geomint sweep` on tests/scenes/rerun/scene.toml, run twice with --jobs 1 and once
// with --jobs 2, writes the same bytes in every CSV (summary, order, order_points, stability,
// series/), except the timing column wall_s and the provenance lines that may legitimately
// differ (date, command line). Parallel accuracy runs must not share mutable state, and a rerun
// must not depend on anything but its inputs.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "harness/paths.hpp"

namespace geomint {
namespace bit_identical_test {
namespace {

namespace fs = std::filesystem;

// `arguments` is shell text: a path in it is written as shell_quoted(path).
int run_geomint(const std::string& arguments, std::string* output) {
  // Appended, not `std::string(...) + " " + ...`: gcc 12 warns falsely (-Warray-bounds) on the
  // inlined rvalue operator+ when <string> comes from the precompiled header.
  std::string command = shell_quoted(GEOMINT_BINARY);
  command.append(" ").append(arguments).append(" 2>&1");
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) output->append(buffer.data(), n);
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Splits one CSV line into its raw fields (quotes kept), honouring quoted commas.
std::vector<std::string> raw_fields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

// The file's bytes without the date and command provenance lines and without the timing
// columns (wall_s*). Sets *timing_columns to the number of columns removed.
std::string comparable(const fs::path& file, int* timing_columns) {
  std::ifstream in(file, std::ios::binary);
  std::string line, out;
  bool header_seen = false;
  std::vector<bool> drop;
  *timing_columns = 0;
  while (std::getline(in, line)) {
    if (line.rfind("# date: ", 0) == 0 || line.rfind("# command: ", 0) == 0) continue;
    if (line.rfind("# ", 0) == 0) {
      out += line + "\n";
      continue;
    }
    const auto fields = raw_fields(line);
    if (!header_seen) {
      header_seen = true;
      for (const auto& name : fields) {
        // wall_s, wall_s_min, wall_s_iqr, wall_s_repeats: the timing pass's statistics.
        drop.push_back(name.rfind("wall_s", 0) == 0);
        *timing_columns += drop.back();
      }
    }
    EXPECT_EQ(fields.size(), drop.size()) << file << ": " << line;
    for (size_t i = 0; i < fields.size(); ++i) {
      if (i < drop.size() && drop[i]) continue;
      out += fields[i] + (i + 1 < fields.size() ? "," : "");
    }
    out += "\n";
  }
  return out;
}

// Every file under `folder` (relative path → absolute path), scene.toml excepted.
std::map<std::string, fs::path> outputs(const fs::path& folder) {
  std::map<std::string, fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file() || entry.path().filename() == "scene.toml") continue;
    files[fs::relative(entry.path(), folder).string()] = entry.path();
  }
  return files;
}

fs::path sweep(const std::string& name, int jobs) {
  // Every copy sits in a folder named like the scene ("rerun"), so the `# scene:` provenance
  // line — the scene's folder name — is compared too, not excused.
  // A space and parentheses above the scene folder, as in a clone's path: the command quotes it.
  const fs::path folder = fs::temp_directory_path() / "geomint bit identical (x)" / name / "rerun";
  fs::remove_all(folder);
  fs::create_directories(folder);
  fs::copy_file(fs::path(GEOMINT_SOURCE_DIR) / "tests/scenes/rerun/scene.toml",
                folder / "scene.toml");
  std::string output;
  const int code = run_geomint(
      "sweep " + shell_quoted((folder / "scene.toml").string()) + " --jobs " + std::to_string(jobs),
      &output);
  EXPECT_EQ(code, 0) << output;
  return folder;
}

TEST(BitIdentical, ComparisonDropsOnlyTimingAndVolatileProvenance) {
  const fs::path dir = fs::temp_directory_path() / "geomint_bit_identical_test";
  fs::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name, std::ios::binary) << text;
    return dir / name;
  };
  const std::string head = "# geomint: 0.1.0 (abc)\n# date: 2026-01-01T00:00:00Z\n";
  const auto a = write("a.csv", head + "# command: x\nm,wall_s,e\n\"p:a=1,b=2\",0.5,1e-3\n");
  const auto b = write("b.csv", head + "# command: y\nm,wall_s,e\n\"p:a=1,b=2\",0.7,1e-3\n");
  const auto c = write("c.csv", head + "# command: x\nm,wall_s,e\n\"p:a=1,b=2\",0.5,2e-3\n");
  int removed = 0;
  EXPECT_EQ(comparable(a, &removed), "# geomint: 0.1.0 (abc)\nm,e\n\"p:a=1,b=2\",1e-3\n");
  EXPECT_EQ(removed, 1);
  EXPECT_EQ(comparable(a, &removed), comparable(b, &removed));
  EXPECT_NE(comparable(a, &removed), comparable(c, &removed));
}

TEST(BitIdentical, RerunsAndJobsOneOrTwoWriteTheSameNonTimingBytes) {
  const fs::path first = sweep("jobs1_a", 1);
  const fs::path second = sweep("jobs1_b", 1);
  const fs::path parallel = sweep("jobs2", 2);
  const auto reference = outputs(first);

  // The comparison must not be vacuous: every kind of table, several series, timing columns.
  for (const char* table : {"summary.csv", "order.csv", "order_points.csv", "stability.csv"}) {
    EXPECT_TRUE(reference.count(table)) << table << " was not written";
  }
  int series = 0;
  for (const auto& [name, path] : reference) series += name.rfind("series/", 0) == 0;
  EXPECT_GE(series, 30) << "series files";
  int timing_columns = 0;
  const std::string summary = comparable(reference.at("summary.csv"), &timing_columns);
  EXPECT_EQ(timing_columns, 4) << "summary.csv should have wall_s, wall_s_min, wall_s_iqr and "
                                  "wall_s_repeats columns";
  EXPECT_GE(std::count(summary.begin(), summary.end(), '\n'), 35) << summary;

  for (const fs::path& other : {second, parallel}) {
    const auto files = outputs(other);
    std::vector<std::string> names, other_names;
    for (const auto& [name, path] : reference) names.push_back(name);
    for (const auto& [name, path] : files) other_names.push_back(name);
    EXPECT_EQ(names, other_names) << other;
    for (const auto& [name, path] : reference) {
      if (path.extension() != ".csv" || !files.count(name)) continue;
      int ignored = 0;
      EXPECT_EQ(comparable(path, &ignored), comparable(files.at(name), &ignored))
          << name << ": " << first.filename() << " against " << other.filename();
    }
  }
}

}  // namespace
}  // namespace bit_identical_test
}  // namespace geomint
