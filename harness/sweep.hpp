// The sweep executor (docs/DESIGN.md §3, §5): runs a loaded Scene (accuracy runs in parallel,
// timing runs one at a time) and writes summary.csv, order.csv, stability.csv, series/ and
// table.md into the output folder.
#pragma once

#include <string>
#include <vector>

#include "harness/scene.hpp"
#include "harness/table.hpp"

namespace geomint {

struct SweepOptions {
  int jobs = 1;
  std::string out_dir;  // where outputs go
  std::string command_line;
  // Written as `# scene:` and `# variant:` provenance lines, which `geomint gate` selects by.
  std::string scene_name;
  std::string variant = "full";  // "full" or "quick"
  // Progress on stderr: a line redrawn in place on a terminal, elsewhere a heartbeat line every
  // progress_interval seconds (--quiet: none).
  bool progress = true;
  double progress_interval = 10;
  bool timing = true;  // false: accuracy runs only (--no-timing)
  // Sharded sweep (--shard i/N, docs/CLUSTER.md "Running on a cluster"): only the units k of the
  // canonical expansion (runs, then order studies, then stability searches) with k mod N == i,
  // written to <out_dir>/shards/<table>.i-of-N.csv with a canonical_index column; never timed.
  // shard_count 0: an ordinary sweep.
  int shard_index = 0, shard_count = 0;
  std::string scene_hash;  // scene_content_hash() of the scene file, for the shard provenance
};

struct SceneTables;

// A sweep's results in memory (docs/DESIGN.md §5 "Tables in memory"): the scene's tables
// (summary, order, order_points, stability: those the scene has, in that order), each with the
// provenance lines its CSV starts with, and the number of failed runs. to_csv(table) is the text
// of <out_dir>/<table.name>.csv, byte for byte.
struct SweepResult {
  int failed = 0;
  std::vector<ResultTable> tables;
  // The table of that name, or nullptr when the scene has none.
  const ResultTable* table(const std::string& name) const;
  // The rows table.md shows.
  SceneTables scene_tables() const;
};

// Runs the scene and returns its tables. With an output folder (options.out_dir) it also writes
// what `geomint sweep` writes there: the CSVs from the returned tables, table.md and the series;
// without one it writes nothing (no series files either). A sharded sweep (shard_count > 0)
// writes its shard files and returns no tables. Failure rows are results, not errors. Throws
// InputError before any computing when the output folder cannot be written, two runs would write
// the same series file, or a sharded sweep has no folder. No exception escapes a worker thread: a
// run that throws becomes a row with status `error` and the exception's text as message.
SweepResult sweep(const Scene& scene, const SweepOptions& options);

// sweep() into options.out_dir (empty: the working directory); returns the number of failed runs.
int run_sweep(const Scene& scene, const SweepOptions& options);

// How many units of each kind the scene expands to (the canonical order of a sharded sweep).
struct SceneUnits {
  size_t runs = 0, orders = 0, stability = 0;
  size_t total() const { return runs + orders + stability; }
};
SceneUnits scene_units(const Scene& scene);

// The expected steps of each unit of the scene in the canonical order (runs, order studies,
// stability searches), the weights of the sweep's ETA: t_end/dt for a fixed-step run, the sum
// over the ladder for an order study, scan and bisection runs for a stability search.
std::vector<double> expected_unit_steps(const Scene& scene);

// `geomint sweep --timing-only`: reads the summary.csv of <out_dir> (a merge or a --no-timing
// sweep of this scene), runs the timing passes one at a time, writes wall_s into it and the
// command, CPU and date of this node into every table's provenance, and rewrites table.md, so
// the tables equal those of a timed single-machine sweep. InputError when summary.csv is missing
// or does not list the scene's runs in order.
void run_timing_only(const Scene& scene, const SweepOptions& options);

// Removes the temporary files (`<output>.<pid>.<n>.tmp`) that a killed sweep, shard or merge of
// this scene left in <out_dir>, <out_dir>/shards and the series folders, when their process is
// gone. run_sweep and run_timing_only call it; so does `geomint merge`.
void remove_stale_temporaries(const Scene& scene, const std::string& out_dir);

// The rows of a scene's tables, as run_sweep produces them or parse_csv reads them back.
struct SceneTables {
  std::vector<Row> summary, order, stability;
};

// order_points.csv's columns: the record columns with the ladder level moved after the label.
std::vector<std::string> order_points_columns(std::vector<std::string> record_columns);

// Rows with their method and problem specs as table.md shows them (only the options that differ
// from the defaults); `geomint report` shows its tables the same way.
std::vector<Row> rows_with_short_specs(std::vector<Row> rows);

// What table.md's "How to cite" block names (docs/REPORT.md "Citing a table"): the geomint
// version and git SHA of the tables' `# geomint: VERSION (SHA)` line, the scene and its variant,
// the scene hash (scene_content_hash of scene.toml, the one `geomint merge` checks shards
// against) and the tables' `# date:`.
struct TableCitation {
  std::string geomint;  // "VERSION (SHA)"
  std::string scene, variant, scene_hash, date;
};
// The citation of tables with these provenance lines (geomint, date, scene, variant) and hash.
TableCitation table_citation(const std::vector<std::pair<std::string, std::string>>& lines,
                             const std::string& scene_hash);

// The scene hash a table.md's "How to cite" block records ("fnv1a64:..."); "" when the file or
// the row is absent. `geomint report` and the committed-results test compare it with the
// scene_content_hash of the scene.toml beside it, so tables of an edited scene are flagged.
std::string recorded_scene_hash(const std::string& table_md_path);

// table.md: the scene's title and description, a Markdown table per non-empty table, the
// command that produced them and the "How to cite" block.
std::string scene_markdown(const Scene& scene, const SceneTables& tables,
                           const std::string& command_line, const TableCitation& citation);

// Rewrites <out_dir>/table.md from the CSVs a sweep wrote there, without running anything
// (`geomint sweep --markdown-only`); the `Produced by` line keeps the CSVs' `# command:`.
// InputError when the folder holds none of the tables, or a table of another scene or variant
// (its `# scene:`/`# variant:` lines, or rows that are not the scene's blocks in order).
void rewrite_scene_markdown(const Scene& scene, const SweepOptions& options);

}  // namespace geomint
