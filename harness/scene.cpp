// Scene loading (toml++) and the sweep driver (see scene.hpp).
#include "harness/scene.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>

#include "harness/order.hpp"
#include "harness/run.hpp"

namespace geomint {
namespace {

class BlockReader {
 public:
  BlockReader(const toml::table& table, std::string where)
      : table_(table), where_(std::move(where)) {}

  std::string string(const std::string& key, bool required, const std::string& fallback = "") {
    seen_.insert(key);
    const toml::node* node = table_.get(key);
    if (!node) return require(key, required), fallback;
    if (auto value = node->value<std::string>()) return *value;
    throw InputError(fmt::format("{}: key '{}' must be a string", where_, key));
  }
  double number(const std::string& key, bool required, double fallback = 0) {
    seen_.insert(key);
    const toml::node* node = table_.get(key);
    if (!node) return require(key, required), fallback;
    if (auto value = node->value<double>()) return *value;
    throw InputError(fmt::format("{}: key '{}' must be a number", where_, key));
  }
  // An integer in [min_value, max_value]: TOML integers are 64-bit, and a value outside the
  // range is an error, never a silent truncation to int.
  long integer(const std::string& key, bool required, long fallback, long min_value,
               long max_value) {
    seen_.insert(key);
    const toml::node* node = table_.get(key);
    if (!node) return require(key, required), fallback;
    const auto* value = node->as_integer();
    if (!value) throw InputError(fmt::format("{}: key '{}' must be an integer", where_, key));
    const std::int64_t number = value->get();
    if (number < min_value || number > max_value) {
      throw InputError(fmt::format("{}: key '{}' must be in {}..{} (got {})", where_, key,
                                   min_value, max_value, number));
    }
    return static_cast<long>(number);
  }
  bool has(const std::string& key) const { return table_.get(key) != nullptr; }
  bool boolean(const std::string& key, bool fallback) {
    seen_.insert(key);
    const toml::node* node = table_.get(key);
    if (!node) return fallback;
    if (auto value = node->value<bool>()) return *value;
    throw InputError(fmt::format("{}: key '{}' must be true or false", where_, key));
  }
  std::vector<std::string> strings(const std::string& key, bool required) {
    seen_.insert(key);
    std::vector<std::string> out;
    const toml::node* node = table_.get(key);
    if (!node) return require(key, required), out;
    const toml::array* array = node->as_array();
    if (!array)
      throw InputError(fmt::format("{}: key '{}' must be an array of strings", where_, key));
    for (const auto& item : *array) {
      auto value = item.value<std::string>();
      if (!value)
        throw InputError(fmt::format("{}: key '{}' must be an array of strings", where_, key));
      out.push_back(*value);
    }
    if (required && out.empty())
      throw InputError(fmt::format("{}: key '{}' is empty", where_, key));
    return out;
  }
  // A number or an array of numbers.
  std::vector<double> numbers(const std::string& key, bool required) {
    seen_.insert(key);
    std::vector<double> out;
    const toml::node* node = table_.get(key);
    if (!node) return require(key, required), out;
    if (auto value = node->value<double>()) return {*value};
    const toml::array* array = node->as_array();
    if (!array)
      throw InputError(
          fmt::format("{}: key '{}' must be a number or an array of numbers", where_, key));
    for (const auto& item : *array) {
      auto value = item.value<double>();
      if (!value)
        throw InputError(fmt::format("{}: key '{}' must be an array of numbers", where_, key));
      out.push_back(*value);
    }
    return out;
  }
  void known(const std::string& key) { seen_.insert(key); }
  void finish() const {
    for (const auto& [key, node] : table_) {
      if (!seen_.count(std::string(key.str()))) {
        throw InputError(fmt::format("{}: unknown key '{}' (allowed: {})", where_, key.str(),
                                     fmt::join(seen_, ", ")));
      }
    }
  }

 private:
  void require(const std::string& key, bool required) const {
    if (required) throw InputError(fmt::format("{}: missing required key '{}'", where_, key));
  }
  const toml::table& table_;
  std::string where_;
  std::set<std::string> seen_;
};

void check_positive(double value, const std::string& where, const std::string& key) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw InputError(
        fmt::format("{}: '{}' must be a finite number > 0 (got {})", where, key, value));
  }
}

std::vector<const toml::table*> tables_of(const toml::table& root, const std::string& key,
                                          const std::string& path) {
  std::vector<const toml::table*> out;
  const toml::node* node = root.get(key);
  if (!node) return out;
  const toml::array* array = node->as_array();
  if (!array)
    throw InputError(fmt::format("{}: '{}' must be an array of tables ([[{}]])", path, key, key));
  for (const auto& item : *array) {
    const toml::table* table = item.as_table();
    if (!table)
      throw InputError(fmt::format("{}: '{}' must be an array of tables ([[{}]])", path, key, key));
    out.push_back(table);
  }
  return out;
}

// Constructs every spec once so that a typo fails before any run starts.
void validate_specs(const std::vector<std::string>& problems,
                    const std::vector<std::string>& methods, const std::string& where,
                    bool* all_adaptive) {
  try {
    for (const auto& spec : problems) make_problem(spec);
    *all_adaptive = true;
    for (const auto& spec : methods) {
      // Every spec is constructed (a `&&` here once skipped the specs after the first
      // fixed-step method, and a typo then aborted the sweep in a worker thread).
      const bool adaptive = (make_integrator(spec)->info().flags & kAdaptive) != 0;
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
bool quick_number(BlockReader& reader, const std::string& key, const std::string& where,
                  double* value) {
  if (!reader.has(key)) {
    reader.known(key);
    return false;
  }
  *value = reader.number(key, true);
  check_positive(*value, where, key);
  return true;
}

}  // namespace

std::string sanitize_for_path(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-';
    if (keep) {
      out += c;
    } else if (out.empty() || out.back() != '_') {
      out += '_';
    }
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out;
}

Scene load_scene(const std::string& path, bool quick) {
  std::error_code filesystem_error;
  if (std::filesystem::is_directory(path, filesystem_error)) {
    throw InputError(fmt::format(
        "scene '{}' is a directory, not a scene file (expected e.g. results/<scene>/scene.toml)",
        path));
  }
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& error) {
    throw InputError(fmt::format("{}:{}:{}: malformed scene file: {}", path,
                                 error.source().begin.line, error.source().begin.column,
                                 error.description()));
  }
  Scene scene;
  BlockReader top(root, path);
  scene.title = top.string("title", true);
  scene.description = top.string("description", false);
  scene.table_columns = top.strings("table_columns", false);
  const auto run_tables = tables_of(root, "runs", path);
  const auto order_tables = tables_of(root, "orders", path);
  top.known("runs");
  top.known("orders");
  const auto stability_tables = tables_of(root, "stability", path);
  top.known("stability");
  if (run_tables.empty() && order_tables.empty() && stability_tables.empty()) {
    throw InputError(
        fmt::format("{}: no [[runs]], [[orders]] or [[stability]] block: nothing to run", path));
  }
  std::set<std::string> labels;
  for (size_t i = 0; i < run_tables.size(); ++i) {
    BlockReader reader(*run_tables[i], fmt::format("{}: [[runs]] #{}", path, i + 1));
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
    block.timing_repeats =
        static_cast<int>(reader.integer("timing_repeats", false, 3, 0, kMaxTimingRepeats));
    block.diverge_factor = reader.number("diverge_factor", false, kDefaultDivergeFactor);
    const auto quick_dts = reader.numbers("quick_dt", false);
    double quick_t_end = 0;
    const bool has_quick_t_end = quick_number(reader, "quick_t_end", where, &quick_t_end);
    const auto quick_problems = reader.strings("quick_problems", false);
    reader.finish();
    check_diverge_factor(block.diverge_factor, where);
    for (double dt : quick_dts) check_positive(dt, where, "quick_dt");
    // Both the full and the quick configuration are checked, whichever runs now.
    RunBlock quick_block = block;
    if (!quick_dts.empty()) quick_block.dts = quick_dts;
    if (has_quick_t_end) quick_block.t_end = quick_t_end;
    if (!quick_problems.empty()) quick_block.problems = quick_problems;
    for (const RunBlock* candidate : {&block, &quick_block}) {
      const char* prefix = candidate == &block ? "" : "quick_";
      bool all_adaptive = false;
      validate_specs(candidate->problems, candidate->methods, where, &all_adaptive);
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
    BlockReader reader(*order_tables[i], fmt::format("{}: [[orders]] #{}", path, i + 1));
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
    validate_specs(block.problems, block.methods, where, &all_adaptive);
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
    BlockReader reader(*stability_tables[i], fmt::format("{}: [[stability]] #{}", path, i + 1));
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
    validate_specs(block.problems, block.methods, where, &all_adaptive);
    for (const StabilityOptions* candidate : {&options, &quick_options}) {
      validate_stability_options(*candidate, where);
      for (const auto& problem : block.problems) {
        check_stability_budget(problem, *candidate, where);
      }
    }
    if (quick) options = quick_options;
    for (const auto& method : block.methods) {
      if (make_integrator(method)->info().flags & kAdaptive) {
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

namespace {

struct Job {
  std::string label, problem, method;
  RunConfig config;
  bool timed = false;
  Row row;
  bool ok = true;
};

class Progress {
 public:
  Progress(size_t total, bool enabled) : total_(total), enabled_(enabled && ::isatty(2)) {}
  void tick() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++done_;
    if (!enabled_) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = done_ ? elapsed * (total_ - done_) / done_ : 0;
    std::fprintf(stderr, "\r[sweep] %zu/%zu runs, %.1f s elapsed, ETA %.1f s   ", done_, total_,
                 elapsed, eta);
    if (done_ == total_) std::fprintf(stderr, "\n");
  }

 private:
  size_t total_, done_ = 0;
  bool enabled_;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// Runs fn(i) for i in [0, n) on `jobs` threads. The callers turn every exception of a run into
// a row; should one still escape fn, the workers stop taking new items and the first exception
// is rethrown here after every thread has joined (an exception leaving a std::thread would call
// std::terminate: SIGABRT, rc 134).
template <typename Fn>
void parallel_for(size_t n, int jobs, Fn&& fn) {
  std::atomic<size_t> next{0};
  std::mutex mutex;
  std::exception_ptr first_error;
  auto worker = [&] {
    for (size_t i = next++; i < n; i = next++) {
      try {
        fn(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!first_error) first_error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> threads;
  for (int j = 1; j < jobs; ++j) threads.emplace_back(worker);
  worker();
  for (auto& thread : threads) thread.join();
  if (first_error) std::rethrow_exception(first_error);
}

// The row of a run that threw instead of returning a status (a defect or an input the scene
// check missed): it is reported like any failure, never crashes the sweep.
Row error_row(const std::string& problem, const std::string& method, const std::string& what) {
  return {{"problem", problem}, {"method", method}, {"status", "error"}, {"message", what}};
}

std::string series_name(const RunBlock& block, const std::string& problem,
                        const std::string& method, double dt) {
  std::string name = sanitize_for_path(method);
  if (block.problems.size() > 1) name = sanitize_for_path(problem) + "__" + name;
  if (block.dts.size() > 1) name += "__dt" + format_number(dt);
  return name + ".csv";
}

}  // namespace

int run_sweep(const Scene& scene, const SweepOptions& options) {
  namespace fs = std::filesystem;
  check_output_dir(options.out_dir, "output folder");
  std::set<std::string> series_paths;
  std::vector<Job> jobs;
  for (const auto& block : scene.runs) {
    const std::vector<double> dts = block.dts.empty() ? std::vector<double>{0.0} : block.dts;
    for (const auto& problem : block.problems) {
      for (const auto& method : block.methods) {
        for (double dt : dts) {
          Job job{block.label, problem, method, {}, block.timing_repeats > 0, {}, true};
          job.config.dt = dt;
          job.config.t_end = block.t_end;
          job.config.timing_repeats = 0;
          job.config.diverge_factor = block.diverge_factor;
          job.config.command_line = options.command_line;
          if (block.series_every > 0) {
            job.config.series_every = block.series_every;
            job.config.series_state = block.series_state;
            // Labels are plain names (load_scene) and series names sanitized specs, so the
            // path stays inside out_dir; checked again here, with duplicates.
            const fs::path relative =
                fs::path("series") / block.label / series_name(block, problem, method, dt);
            const fs::path normal = relative.lexically_normal();
            if (normal.is_absolute() || normal.empty() || *normal.begin() != "series") {
              throw InputError(
                  fmt::format("[[runs]] '{}': series path '{}' leaves the output folder",
                              block.label, relative.string()));
            }
            if (!series_paths.insert(normal.string()).second) {
              throw InputError(fmt::format(
                  "[[runs]] '{}': two runs would write the same series file '{}' (give the "
                  "methods or problems distinct specs)",
                  block.label, normal.string()));
            }
            job.config.series_path = (fs::path(options.out_dir) / normal).string();
          }
          jobs.push_back(std::move(job));
        }
      }
    }
  }
  struct OrderJob {
    std::string label, problem, method;
    const OrderBlock* block;
    OrderStudy study;
  };
  std::vector<OrderJob> order_jobs;
  for (const auto& block : scene.orders) {
    for (const auto& problem : block.problems) {
      for (const auto& method : block.methods) {
        order_jobs.push_back({block.label, problem, method, &block, {}});
      }
    }
  }
  struct StabilityJob {
    std::string label, problem, method;
    const StabilityOptions* options;
    Row row;
  };
  std::vector<StabilityJob> stability_jobs;
  for (const auto& block : scene.stability) {
    for (const auto& problem : block.problems) {
      for (const auto& method : block.methods) {
        stability_jobs.push_back({block.label, problem, method, &block.options, {}});
      }
    }
  }
  size_t timed = 0;
  for (const auto& job : jobs) timed += job.timed;
  Progress progress(jobs.size() + order_jobs.size() + stability_jobs.size() + timed,
                    options.progress);

  // Accuracy runs (parallel); specs were validated when the scene was loaded.
  parallel_for(jobs.size() + order_jobs.size(), options.jobs, [&](size_t i) {
    if (i < jobs.size()) {
      Job& job = jobs[i];
      try {
        RunResult result = run_one(job.problem, job.method, job.config);
        job.row = std::move(result.row);
        job.ok = result.ok;
      } catch (const std::exception& error) {
        job.row = error_row(job.problem, job.method, error.what());
        job.ok = false;
      }
      job.row["label"] = job.label;
    } else {
      OrderJob& job = order_jobs[i - jobs.size()];
      try {
        job.study = order_study(job.problem, job.method, job.block->dt0, job.block->levels,
                                job.block->t_end, job.block->diverge_factor);
      } catch (const std::exception& error) {
        job.study = OrderStudy{};
        job.study.row = error_row(job.problem, job.method, error.what());
      }
    }
    progress.tick();
  });
  // Stability searches (parallel; each is a sequence of short runs without observers).
  parallel_for(stability_jobs.size(), options.jobs, [&](size_t i) {
    StabilityJob& job = stability_jobs[i];
    try {
      job.row = stability_search(job.problem, job.method, *job.options).row;
    } catch (const std::exception& error) {
      // E.g. a problem without omega_max given an h*omega range: a row, not a crashed thread.
      job.row = {{"problem", job.problem},
                 {"method", job.method},
                 {"status", "error"},
                 {"message", error.what()}};
    }
    job.row["label"] = job.label;
    progress.tick();
  });
  // Timing runs, one at a time so they do not compete for cores.
  for (auto& job : jobs) {
    if (!job.timed) continue;
    if (job.ok) {
      const int repeats = [&] {
        for (const auto& block : scene.runs) {
          if (block.label == job.label) return block.timing_repeats;
        }
        return 3;
      }();
      try {
        job.row["wall_s"] = format_number(time_run(job.problem, job.method, job.config, repeats));
      } catch (const std::exception& error) {
        job.row["message"] = fmt::format("timing pass failed: {}", error.what());
      }
    }
    progress.tick();
  }

  auto lines = provenance(options.command_line);
  if (!options.scene_name.empty()) lines.emplace_back("scene", options.scene_name);
  lines.emplace_back("variant", options.variant);
  int failed = 0;
  std::vector<Row> summary_rows, order_rows, order_point_rows;
  for (const auto& job : jobs) {
    summary_rows.push_back(job.row);
    failed += !job.ok;
  }
  for (auto& job : order_jobs) {
    Row row = job.study.row;
    failed += row.count("status") && row.at("status") == "error";
    row["label"] = job.label;
    order_rows.push_back(row);
    for (auto point : job.study.runs) {
      point.row["label"] = job.label;
      order_point_rows.push_back(point.row);
    }
  }
  const fs::path out(options.out_dir);
  std::vector<std::string> point_columns = standard_columns();
  point_columns.insert(point_columns.begin() + 1, "order_level");
  std::string markdown = fmt::format("# {}\n\n", scene.title);
  if (!scene.description.empty()) markdown += scene.description + "\n\n";
  if (!summary_rows.empty()) {
    write_file_atomic((out / "summary.csv").string(),
                      to_csv(summary_rows, column_union(summary_rows, standard_columns()), lines));
    auto columns = scene.table_columns.empty() ? column_union(summary_rows, standard_columns())
                                               : scene.table_columns;
    markdown += "## Runs (summary.csv)\n\n" + to_markdown(summary_rows, columns) + "\n";
  }
  if (!order_rows.empty()) {
    const std::vector<std::string> order_columns = {"label",  "problem",        "method",
                                                    "order",  "declared_order", "points_used",
                                                    "status", "message"};
    write_file_atomic((out / "order.csv").string(),
                      to_csv(order_rows, column_union(order_rows, order_columns), lines));
    write_file_atomic(
        (out / "order_points.csv").string(),
        to_csv(order_point_rows, column_union(order_point_rows, point_columns), lines));
    markdown += "## Fitted convergence orders (order.csv)\n\n" +
                to_markdown(order_rows, {"problem", "method", "order", "declared_order",
                                         "points_used", "message"}) +
                "\n";
  }
  if (!stability_jobs.empty()) {
    std::vector<Row> stability_rows;
    for (const auto& job : stability_jobs) stability_rows.push_back(job.row);
    write_file_atomic(
        (out / "stability.csv").string(),
        to_csv(stability_rows, column_union(stability_rows, stability_columns()), lines));
    markdown += "## Largest stable h*omega (stability.csv)\n\n" +
                to_markdown(stability_rows,
                            {"label", "problem", "method", "homega_max_measured", "predicted",
                             "rel_diff", "status", "message"},
                            6) +
                "\n";
  }
  markdown += fmt::format("Produced by `{}`.\n", options.command_line);
  write_file_atomic((out / "table.md").string(), markdown);
  return failed;
}

}  // namespace geomint
