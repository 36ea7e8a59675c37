// Accuracy gates (docs/DESIGN.md §4, `geomint gate GATES.toml RESULTS...`): thresholds on the
// columns of result tables, selected by scene and table, so a CI pipeline fails when a published
// number leaves its band — on the full scenes and on their CI-sized `--quick` variant alike.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "harness/table.hpp"

namespace geomint {

// Bounds of a numeric gate, or the exact text of a text gate.
struct GateCheck {
  std::optional<double> min, max;     // inclusive bounds on the numeric value of `column`
  std::optional<std::string> equals;  // exact text of `column` (e.g. status = "ok")
};

// One [[gate]] block. Every row of the selected tables that matches `where` must satisfy the
// check, and at least one row must match when the gate applies (a gate that selects nothing
// fails: a renamed run must not pass silently). A gate applies to the results given when their
// scenes include `scene` (or it names no scene) in one of its `variants`; otherwise it is
// reported as not applicable, so one gates file serves any subset of the scenes.
struct Gate {
  std::string name;
  std::string file;   // the gates file it was read from (an included one, as resolved)
  std::string scene;  // results/<scene>/ ("" = every scene given)
  std::string table;  // "summary", "order", "stability", ... ("" = every table)
  std::vector<std::string> variants = {"full", "quick"};   // which sweeps it gates
  std::vector<std::pair<std::string, std::string>> where;  // column = value
  std::string column;
  GateCheck full;                  // min/max/equals
  std::optional<GateCheck> quick;  // quick_min/quick_max/quick_equals, where the CI-sized run
                                   // differs (unset keys fall back to the full bounds)
  const GateCheck& check_for(const std::string& variant) const {
    return variant == "quick" && quick ? *quick : full;
  }
};

// Parses a gates file and the files it includes (`include = ["<scene>/gates.toml",
// "*/gates.toml"]`, paths relative to the including file's folder, a * ? [...] component matching
// names; read in the order listed, matches sorted), its own gates first. Which tables a gate checks
// does not depend on the file it sits in: `scene` and `table` are names matched against the results
// given. InputError names the file, block and key for malformed input (unknown or missing keys,
// wrong types, NaN bounds, min > max, a gate with neither bounds nor `equals`), an include of a
// missing file or a pattern matching none, an include cycle, a file included twice, a gate name
// used twice (in one file or across files), a file with neither gates nor includes, and a gate in a
// scene's folder (beside its scene.toml) that names another scene.
std::vector<Gate> load_gates(const std::string& path);

// A result table with where it came from. The scene and variant come from the `# scene:` and
// `# variant:` provenance lines that `geomint sweep` writes; for older files, from the path
// (results/<scene>/<table>.csv, results/<scene>/quick/<table>.csv).
struct ResultFile {
  std::string path;
  std::string scene;
  std::string table;    // file name without .csv
  std::string variant;  // "full" or "quick"
  std::vector<Row> rows;
};

// The gates' view of a result table in memory (a sweep's, harness/sweep.hpp): the scene and
// variant from its provenance lines (else from `path`, as for a file), `path` naming it in the
// verdicts. Every file the gates read goes through here. InputError as for a file.
ResultFile result_file(const ResultTable& table, const std::string& path);

// The tables of a sweep in memory as if read from `folder` (load_result_files of the folder its
// CSVs are written to gives the same files, in the same order): check_gates on them gives the
// verdicts `geomint gate` gives on the written folder, line for line.
std::vector<ResultFile> result_files(const std::vector<ResultTable>& tables,
                                     const std::string& folder);

// Reads result CSVs; a directory stands for the tables in it (summary.csv, order.csv,
// stability.csv, ...; not series/). InputError for a missing, unreadable or unparsable path, a
// directory without tables, or a file whose scene cannot be told.
std::vector<ResultFile> load_result_files(const std::vector<std::string>& paths);

struct GateOutcome {
  const Gate* gate = nullptr;
  bool applicable = true;  // false: none of the given results is of the gate's scene/variant
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
