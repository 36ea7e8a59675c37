// Accuracy gates (DESIGN.md §4, `geomint gate GATES.toml RESULTS.csv...`): thresholds on the
// columns of result CSVs, so a CI pipeline fails when a published number leaves its band.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "harness/table.hpp"

namespace geomint {

// One [[gate]] block. Every row that matches `where` must satisfy the check, and at least one
// row must match (a gate that selects nothing fails: a renamed run must not pass silently).
struct Gate {
  std::string name;
  std::string file;  // only rows from CSV files whose path ends with this ("" = any file)
  std::vector<std::pair<std::string, std::string>> where;  // column = value
  std::string column;
  std::optional<double> min, max;     // inclusive bounds on the numeric value of `column`
  std::optional<std::string> equals;  // exact text of `column` (e.g. status = "ok")
};

// Parses a gates file; InputError names the file, block and key for malformed input (unknown
// or missing keys, wrong types, min > max, a gate with neither bounds nor `equals`).
std::vector<Gate> load_gates(const std::string& path);

// A CSV file's rows with the file they came from.
struct ResultFile {
  std::string path;
  std::vector<Row> rows;
};

// Reads result CSVs (InputError for a missing or unparsable file).
std::vector<ResultFile> load_result_files(const std::vector<std::string>& paths);

struct GateOutcome {
  const Gate* gate = nullptr;
  bool passed = false;
  int rows_checked = 0;
  std::vector<std::string> lines;  // one per checked row (value and verdict), or why none
};

// Checks every gate against every row. The `method` and `problem` columns are compared as
// canonical specs (defaults filled in, keys sorted), so `method = "implicit_euler"` matches the
// row "implicit_euler:max_iter=50,tol=1e-12"; numeric columns compare as numbers.
std::vector<GateOutcome> check_gates(const std::vector<Gate>& gates,
                                     const std::vector<ResultFile>& files);

}  // namespace geomint
