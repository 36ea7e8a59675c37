// Scenes (docs/DESIGN.md §3, §5): results/<scene>/scene.toml describes blocks of runs (problems ×
// methods × dt), of order studies and of stability searches; `sweep` runs them (accuracy runs in
// parallel, timing runs one at a time) and writes summary.csv, order.csv, stability.csv, series/
// and table.md into the folder.
#pragma once

#include <string>
#include <vector>

#include "harness/run.hpp"
#include "harness/stability.hpp"

namespace geomint {

struct RunBlock {
  std::string label;
  std::vector<std::string> problems, methods;
  std::vector<double> dts;  // empty only when every method is adaptive
  double t_end = 0;
  long series_every = 0;  // 0 = no series
  bool series_state = false;
  int timing_repeats = 3;                         // 0 = no timing pass
  double diverge_factor = kDefaultDivergeFactor;  // RunConfig::diverge_factor; 0 or inf = off
};

struct OrderBlock {
  std::string label;
  std::vector<std::string> problems, methods;
  double dt0 = 0;
  int levels = 0;
  double t_end = 0;
  double diverge_factor = kDefaultDivergeFactor;  // RunConfig::diverge_factor; 0 or inf = off
};

struct Scene {
  std::string title;
  std::string description;
  std::vector<std::string> table_columns;  // summary columns for table.md; empty = automatic
  std::vector<RunBlock> runs;
  std::vector<OrderBlock> orders;
  std::vector<StabilityBlock> stability;  // [[stability]]: largest stable h*omega per method
};

// Parses and validates a scene file: unknown or missing keys, wrong types, integers out of range,
// bad specs, bad numbers, labels that are not plain names, more than 1e10 steps in a run and
// stability searches over their budget throw InputError naming the file, block and key — so a
// sweep that starts never stops on its input. `quick` applies the quick_* keys; both the full
// and the quick configuration are validated either way.
Scene load_scene(const std::string& path, bool quick);

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

// File-name-safe form of a spec ("hp:alpha=0.5" → "hp_alpha_0.5").
std::string sanitize_for_path(const std::string& text);

}  // namespace geomint
