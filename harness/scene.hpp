// Scene files (docs/DESIGN.md §3, §5): results/<scene>/scene.toml describes blocks of runs
// (problems × methods × dt), of order studies and of stability searches. This is the reader
// (TOML → Scene, through harness/toml_reader.hpp); harness/sweep.hpp runs a Scene.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "harness/run_spec.hpp"
#include "harness/stability.hpp"

namespace geomint {

struct RunBlock {
  std::string label;
  std::vector<std::string> problems, methods;
  std::vector<double> dts;  // empty only when every method is adaptive
  double t_end = 0;
  long series_every = 0;  // 0 = no series
  bool series_state = false;
  long series_section = -1;  // RunConfig::series_section; -1 = every series_every-th step point
  int timing_repeats = 5;    // 0 = no timing pass
  double timing_budget_s = kDefaultTimingBudgetSeconds;  // RunConfig::timing_budget_s
  double diverge_factor = kDefaultDivergeFactor;  // RunConfig::diverge_factor; 0 or inf = off
  long max_steps = kDefaultMaxSteps;              // RunConfig::max_steps
  double wall_budget_s = 0;                       // RunConfig::wall_budget_s; 0 = none
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
  // The problem and method objects of the blocks' specs, each parsed once (load_scene fills it;
  // a Scene built in code gets its specs parsed on first use by the sweep). Shared by copies.
  std::shared_ptr<SpecBook> specs = std::make_shared<SpecBook>();
};

// Parses and validates a scene file: unknown or missing keys, wrong types, integers out of range,
// bad specs, bad numbers, labels that are not plain names, more than 1e10 steps in a run and
// stability searches over their budget throw InputError naming the file, block and key — so a
// sweep that starts never stops on its input. `quick` applies the quick_* keys; both the full
// and the quick configuration are validated either way.
Scene load_scene(const std::string& path, bool quick);

}  // namespace geomint
