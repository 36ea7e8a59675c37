// The scene-file reader (see scene.hpp): TOML → Scene through the shared key readers of
// harness/toml_reader.hpp, with every check a sweep needs before it starts.
#include "harness/scene.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>

#include "harness/order.hpp"
#include "harness/record.hpp"
#include "harness/reference.hpp"
#include "harness/run.hpp"
#include "harness/toml_reader.hpp"

namespace geomint {
namespace {

void check_positive(double value, const std::string& where, const std::string& key) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw InputError(
        fmt::format("{}: '{}' must be a finite number > 0 (got {})", where, key, value));
  }
}

// Parses every spec into the scene's book (once: the sweep runs these objects) so that a typo
// fails before any run starts.
void validate_specs(const std::vector<std::string>& problems,
                    const std::vector<std::string>& methods, const std::string& where,
                    SpecBook& specs, bool* all_adaptive) {
  try {
    for (const auto& spec : problems) specs.problem(spec);
    *all_adaptive = true;
    for (const auto& spec : methods) {
      // Every spec is parsed (a `&&` here once skipped the specs after the first
      // fixed-step method, and a typo then aborted the sweep in a worker thread).
      const bool adaptive = specs.method(spec).adaptive();
      *all_adaptive = *all_adaptive && adaptive;
    }
  } catch (const InputError& error) {
    throw InputError(fmt::format("{}: {}", where, error.what()));
  }
}

// Labels name folders (series/<label>/) and rows: letters, digits, '_', '-' and '.', at most
// 64 characters, no "..", so every path derived from a label stays inside the output folder.
void check_label(const std::string& label, const std::string& where) {
  bool ok = !label.empty() && label.size() <= 64 && label.find("..") == std::string::npos &&
            label != "." && label.front() != '-';
  for (char c : label) {
    ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.');
  }
  if (!ok) {
    throw InputError(fmt::format(
        "{}: label '{}' is not allowed: use 1 to 64 letters, digits, '_', '-' or '.', no '..' "
        "and no path separator (labels name folders inside the output folder)",
        where, label));
  }
}

// The reference files the runs and order studies will read (harness/run.cpp), loaded now: a
// malformed one is bad input of the scene, not an error row in every run that meets it.
void validate_references(const std::vector<std::string>& problems, const std::string& where,
                         SpecBook& specs, std::set<std::string>& checked) {
  for (const auto& spec : problems) {
    const auto problem = specs.problem(spec);
    if (problem->has(kExact)) continue;
    const std::string path = reference_path(RunConfig{}.reference_dir, *problem);
    if (!checked.insert(path).second || !std::filesystem::exists(path)) continue;
    try {
      load_reference(path, *problem);
    } catch (const InputError& error) {
      throw InputError(fmt::format("{}: {}", where, error.what()));
    }
  }
}

void check_diverge_factor(double factor, const std::string& where) {
  if (!(factor >= 0)) {
    throw InputError(fmt::format(
        "{}: 'diverge_factor' must be >= 0 (0 or inf: no divergence rule; got {})", where, factor));
  }
}

// The fixed-step methods of a block run t_end/dt steps; more than kMaxFixedSteps is an error at
// load, not an exception in a worker thread.
void check_step_count(double t_end, double dt, const std::string& where, const char* dt_key) {
  if (t_end / dt > kMaxFixedSteps) {
    throw InputError(
        fmt::format("{}: t_end/{} = {:g}/{:g} = {:g} steps is more than the allowed {:g}", where,
                    dt_key, t_end, dt, t_end / dt, kMaxFixedSteps));
  }
}

// An optional quick_* override: when present it must be a finite number > 0, also when --quick
// is not given (a typo there would otherwise surface only in CI).
bool quick_number(TomlBlock& reader, const std::string& key, const std::string& where,
                  double* value) {
  if (!reader.has(key)) {
    reader.known(key);
    return false;
  }
  *value = reader.number(key, true);
  check_positive(*value, where, key);
  return true;
}

// table_columns picks summary.csv columns for table.md: each must be a column of the run record
// schema, so a misspelt name is an error instead of an empty column.
void check_table_columns(const std::vector<std::string>& columns, const std::string& where) {
  std::vector<std::string> known;
  for (const auto& column : record_schema()) known.push_back(column.name);
  for (const auto& name : columns) {
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      throw InputError(
          fmt::format("{}: table_columns: '{}' is not a column of summary.csv (one of: {})", where,
                      name, fmt::join(known, ", ")));
    }
  }
}

}  // namespace

Scene load_scene(const std::string& path, bool quick) {
  const toml::table root = parse_toml_file(path, "scene file", "results/<scene>/scene.toml");
  Scene scene;
  TomlBlock top(root, path);
  scene.title = top.string("title", true);
  scene.description = top.string("description", false);
  scene.table_columns = top.strings("table_columns", false);
  check_table_columns(scene.table_columns, path);
  const auto run_tables = array_of_tables(root, "runs", path);
  const auto order_tables = array_of_tables(root, "orders", path);
  top.known("runs");
  top.known("orders");
  const auto stability_tables = array_of_tables(root, "stability", path);
  top.known("stability");
  if (run_tables.empty() && order_tables.empty() && stability_tables.empty()) {
    throw InputError(
        fmt::format("{}: no [[runs]], [[orders]] or [[stability]] block: nothing to run", path));
  }
  std::set<std::string> labels, references;
  for (size_t i = 0; i < run_tables.size(); ++i) {
    TomlBlock reader(*run_tables[i], fmt::format("{}: [[runs]] #{}", path, i + 1));
    RunBlock block;
    block.label = reader.string("label", true);
    const std::string where = fmt::format("{}: [[runs]] '{}'", path, block.label);
    check_label(block.label, where);
    block.problems = reader.strings("problems", true);
    block.methods = reader.strings("methods", true);
    block.dts = reader.numbers("dt", false);
    block.t_end = reader.number("t_end", true);
    block.series_every = reader.integer("series_every", false, 0, 0, 1000000000000L);
    block.series_state = reader.boolean("series_state", false);
    block.series_section = reader.integer("series_section", false, -1, -1, 1000000000L);
    block.timing_repeats =
        static_cast<int>(reader.integer("timing_repeats", false, 5, 0, kMaxTimingRepeats));
    block.timing_budget_s = reader.number("timing_budget_s", false, kDefaultTimingBudgetSeconds);
    block.diverge_factor = reader.number("diverge_factor", false, kDefaultDivergeFactor);
    block.max_steps =
        reader.integer("max_steps", false, kDefaultMaxSteps, 1, static_cast<long>(kMaxFixedSteps));
    block.wall_budget_s = reader.number("wall_budget_s", false, 0);
    const auto quick_dts = reader.numbers("quick_dt", false);
    double quick_t_end = 0;
    const bool has_quick_t_end = quick_number(reader, "quick_t_end", where, &quick_t_end);
    const auto quick_problems = reader.strings("quick_problems", false);
    reader.finish();
    check_diverge_factor(block.diverge_factor, where);
    if (!(block.timing_budget_s > 0 && block.timing_budget_s <= kMaxTimingBudgetSeconds)) {
      throw InputError(fmt::format("{}: 'timing_budget_s' must be in (0, {:g}] seconds (got {})",
                                   where, kMaxTimingBudgetSeconds, block.timing_budget_s));
    }
    if (!(block.wall_budget_s >= 0 && block.wall_budget_s <= kMaxWallBudgetSeconds)) {
      throw InputError(
          fmt::format("{}: 'wall_budget_s' must be in [0, {:g}] seconds (0: no budget; got {})",
                      where, kMaxWallBudgetSeconds, block.wall_budget_s));
    }
    for (double dt : quick_dts) check_positive(dt, where, "quick_dt");
    // Both the full and the quick configuration are checked, whichever runs now.
    RunBlock quick_block = block;
    if (!quick_dts.empty()) quick_block.dts = quick_dts;
    if (has_quick_t_end) quick_block.t_end = quick_t_end;
    if (!quick_problems.empty()) quick_block.problems = quick_problems;
    for (const RunBlock* candidate : {&block, &quick_block}) {
      const char* prefix = candidate == &block ? "" : "quick_";
      bool all_adaptive = false;
      validate_specs(candidate->problems, candidate->methods, where, *scene.specs, &all_adaptive);
      validate_references(candidate->problems, where, *scene.specs, references);
      if (candidate->dts.empty() && !all_adaptive) {
        throw InputError(
            fmt::format("{}: missing required key 'dt' (needed by fixed-step methods)", where));
      }
      for (double dt : candidate->dts) check_positive(dt, where, std::string(prefix) + "dt");
      check_positive(candidate->t_end, where, std::string(prefix) + "t_end");
      if (!all_adaptive) {
        for (double dt : candidate->dts) {
          check_step_count(candidate->t_end, dt, where, candidate == &block ? "dt" : "quick_dt");
        }
      }
    }
    if (quick) block = quick_block;
    if (!labels.insert(block.label).second)
      throw InputError(fmt::format("{}: label used twice", where));
    scene.runs.push_back(block);
  }
  for (size_t i = 0; i < order_tables.size(); ++i) {
    TomlBlock reader(*order_tables[i], fmt::format("{}: [[orders]] #{}", path, i + 1));
    OrderBlock block;
    block.label = reader.string("label", true);
    const std::string where = fmt::format("{}: [[orders]] '{}'", path, block.label);
    check_label(block.label, where);
    block.problems = reader.strings("problems", true);
    block.methods = reader.strings("methods", true);
    block.dt0 = reader.number("dt0", true);
    block.levels =
        static_cast<int>(reader.integer("levels", true, 0, kMinOrderLevels, kMaxOrderLevels));
    block.t_end = reader.number("t_end", true);
    block.diverge_factor = reader.number("diverge_factor", false, kDefaultDivergeFactor);
    const long quick_levels =
        reader.integer("quick_levels", false, block.levels, kMinOrderLevels, kMaxOrderLevels);
    double quick_t_end = block.t_end;
    quick_number(reader, "quick_t_end", where, &quick_t_end);
    reader.finish();
    check_diverge_factor(block.diverge_factor, where);
    bool all_adaptive = false;
    validate_specs(block.problems, block.methods, where, *scene.specs, &all_adaptive);
    validate_references(block.problems, where, *scene.specs, references);
    check_positive(block.dt0, where, "dt0");
    check_positive(block.t_end, where, "t_end");
    // The finest level of either configuration must respect the step limit.
    check_step_count(block.t_end, block.dt0 * std::ldexp(1.0, -(block.levels - 1)), where,
                     "(dt0*2^-(levels-1))");
    check_step_count(quick_t_end, block.dt0 * std::ldexp(1.0, -static_cast<int>(quick_levels - 1)),
                     where, "(dt0*2^-(quick_levels-1))");
    if (quick) {
      block.levels = static_cast<int>(quick_levels);
      block.t_end = quick_t_end;
    }
    if (!labels.insert(block.label).second)
      throw InputError(fmt::format("{}: label used twice", where));
    scene.orders.push_back(block);
  }
  for (size_t i = 0; i < stability_tables.size(); ++i) {
    TomlBlock reader(*stability_tables[i], fmt::format("{}: [[stability]] #{}", path, i + 1));
    StabilityBlock block;
    block.label = reader.string("label", true);
    const std::string where = fmt::format("{}: [[stability]] '{}'", path, block.label);
    check_label(block.label, where);
    block.problems = reader.strings("problems", true);
    block.methods = reader.strings("methods", true);
    StabilityOptions& options = block.options;
    options.homega_min = reader.number("homega_min", false, options.homega_min);
    options.homega_max = reader.number("homega_max", false, options.homega_max);
    options.h_min = reader.number("h_min", false, 0);
    options.h_max = reader.number("h_max", false, 0);
    options.periods = reader.number("periods", false, options.periods);
    options.t_end = reader.number("t_end", false, 0);
    options.min_steps =
        reader.integer("min_steps", false, options.min_steps, 1, kMaxStabilityStepsPerRun);
    options.growth = reader.number("growth", false, options.growth);
    options.scan_points_per_decade = static_cast<int>(
        reader.integer("scan_points_per_decade", false, options.scan_points_per_decade, 1, 100));
    options.rel_tol = reader.number("rel_tol", false, options.rel_tol);
    StabilityOptions quick_options = options;
    quick_number(reader, "quick_periods", where, &quick_options.periods);
    quick_options.min_steps =
        reader.integer("quick_min_steps", false, options.min_steps, 1, kMaxStabilityStepsPerRun);
    quick_number(reader, "quick_rel_tol", where, &quick_options.rel_tol);
    reader.finish();
    bool all_adaptive = false;
    validate_specs(block.problems, block.methods, where, *scene.specs, &all_adaptive);
    for (const StabilityOptions* candidate : {&options, &quick_options}) {
      validate_stability_options(*candidate, where);
      for (const auto& problem : block.problems) {
        check_stability_budget(*scene.specs->problem(problem), problem, *candidate, where);
      }
    }
    if (quick) options = quick_options;
    for (const auto& method : block.methods) {
      if (scene.specs->method(method).adaptive()) {
        throw InputError(
            fmt::format("{}: method '{}' is adaptive: a stability search needs a "
                        "fixed-step method",
                        where, method));
      }
    }
    if (!labels.insert(block.label).second)
      throw InputError(fmt::format("{}: label used twice", where));
    scene.stability.push_back(block);
  }
  top.finish();
  return scene;
}

}  // namespace geomint
