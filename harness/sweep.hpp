// The sweep executor (docs/DESIGN.md §3, §5): runs a loaded Scene (accuracy runs in parallel,
// timing runs one at a time) and writes summary.csv, order.csv, stability.csv, series/ and
// table.md into the output folder.
#pragma once

#include <string>
#include <vector>

#include "harness/scene.hpp"

namespace geomint {

struct SweepOptions {
  int jobs = 1;
  std::string out_dir;  // where outputs go
  std::string command_line;
  // Written as `# scene:` and `# variant:` provenance lines, which `geomint gate` selects by.
  std::string scene_name;
  std::string variant = "full";  // "full" or "quick"
  bool progress = true;          // progress on stderr when it is a terminal
};

// Runs the scene; returns the number of failed runs (failure rows are results, not errors).
// Throws InputError before any computing when the output folder cannot be written or two runs
// would write the same series file. No exception escapes a worker thread: a run that throws
// becomes a row with status `error` and the exception's text as message.
int run_sweep(const Scene& scene, const SweepOptions& options);

// The rows of a scene's tables, as run_sweep produces them or parse_csv reads them back.
struct SceneTables {
  std::vector<Row> summary, order, stability;
};

// table.md: the scene's title and description, then a Markdown table per non-empty table.
std::string scene_markdown(const Scene& scene, const SceneTables& tables,
                           const std::string& command_line);

// Rewrites <out_dir>/table.md from the CSVs a sweep wrote there, without running anything
// (`geomint sweep --markdown-only`); the `Produced by` line keeps the CSVs' `# command:`.
// InputError when the folder holds none of the tables.
void rewrite_scene_markdown(const Scene& scene, const std::string& out_dir);

}  // namespace geomint
