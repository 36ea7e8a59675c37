// The sweep executor (see sweep.hpp): jobs from a loaded scene, the thread pool, progress and
// the writers of the scene's tables.
#include "harness/sweep.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string_view>
#include <thread>

#include "harness/order.hpp"
#include "harness/output_folder.hpp"
#include "harness/paths.hpp"
#include "harness/run.hpp"
#include "harness/run_spec.hpp"
#include "harness/shard_files.hpp"
#include "harness/structure_metrics.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"

namespace geomint {

namespace {

// One accuracy run of a [[runs]] block, with everything the sweep needs later: its config for
// the accuracy pass and the number of repeats of its timing pass (0 = not timed).
struct Job {
  std::string label, problem, method;
  RunConfig config;
  int timing_repeats = 0;
  RunRecord record;
  bool ok = true;
  // The parsed run, kept from the accuracy pass for the timing pass of a timed job.
  std::optional<RunSpec> spec = std::nullopt;
};

// The sweep's progress on stderr, counted in expected steps (expected_steps()), not in units: a
// scene's runs differ in length by orders of magnitude, so a count of runs says little of the
// time left. On a terminal one line is redrawn after every unit; elsewhere (a Slurm or CI log,
// where `\r` piles up) a background thread prints a heartbeat line every `interval` seconds,
// so a log shows life during a long run instead of staying empty until the sweep ends.
class Progress {
 public:
  Progress(std::vector<double> unit_steps, const SweepOptions& options)
      : unit_steps_(std::move(unit_steps)),
        enabled_(options.progress),
        terminal_(::isatty(2) != 0),
        interval_(options.progress_interval) {
    for (double steps : unit_steps_) total_steps_ += steps;
    if (enabled_ && !terminal_ && !unit_steps_.empty()) {
      heartbeat_ = std::thread([this] { beat(); });
    }
  }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    if (heartbeat_.joinable()) heartbeat_.join();
  }
  // Unit `unit` (an index into unit_steps) is done.
  void tick(size_t unit) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++done_;
    if (unit < unit_steps_.size()) done_steps_ += unit_steps_[unit];
    if (!enabled_ || !terminal_) return;
    std::fprintf(stderr, "\r%s   ", line().c_str());
    if (done_ == unit_steps_.size()) std::fprintf(stderr, "\n");
  }

 private:
  // "[sweep] 3/12 runs, 41% of expected steps, 12.0 s elapsed, ETA 17.3 s"; mutex_ held.
  std::string line() const {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double fraction = total_steps_ > 0 ? done_steps_ / total_steps_ : 0;
    const std::string eta = fraction > 0
                                ? fmt::format("ETA {:.1f} s", elapsed * (1 - fraction) / fraction)
                                : std::string("ETA unknown");
    return fmt::format("[sweep] {}/{} runs, {:.0f}% of expected steps, {:.1f} s elapsed, {}", done_,
                       unit_steps_.size(), 100 * fraction, elapsed, eta);
  }
  void beat() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stopping_ && done_ < unit_steps_.size()) {
      const auto period = std::chrono::duration<double>(interval_);
      if (wake_.wait_for(lock, period, [this] { return stopping_; })) break;
      std::fprintf(stderr, "%s\n", line().c_str());
      std::fflush(stderr);
    }
  }

  std::vector<double> unit_steps_;
  double total_steps_ = 0, done_steps_ = 0;
  size_t done_ = 0;
  bool enabled_, terminal_;
  double interval_;
  bool stopping_ = false;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread heartbeat_;
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

// The record of a run or study that threw instead of returning a status (a defect or an input
// the scene check missed): it is reported like any failure, never crashes the sweep.
template <typename Record = RunRecord>
Record error_record(const std::string& problem, const std::string& method,
                    const std::string& what) {
  Record record;
  record.problem = problem;
  record.method = method;
  record.status = "error";
  record.message = what;
  return record;
}

// Why the run's method cannot run on its problem (applicable(): constraints, a needed Hessian),
// if so.
std::optional<std::string> inapplicable(const RunSpec& spec) {
  const Applicability fit = applicable(spec.method.prototype(), *spec.problem);
  if (fit.ok) return std::nullopt;
  return fit.reason;
}

std::string series_name(const RunBlock& block, const std::string& problem,
                        const std::string& method, double dt) {
  std::string name = sanitize_for_path(method);
  if (block.problems.size() > 1) name = sanitize_for_path(problem) + "__" + name;
  if (block.dts.size() > 1) name += "__dt" + format_number(dt);
  return name + ".csv";
}

// A method or problem spec as table.md shows it: the name and only the options that differ from
// the name's defaults ("hp:alpha=0" for the canonical "hp:alpha=0,force_at=midpoint,..."). The
// label must name the same configuration: when it does not rebuild the canonical spec (a
// default that depends on another option), or the spec is unknown to this build, the canonical
// spec is shown as it is. `specs` holds the objects already parsed (the scene's).
std::string short_spec(const std::string& column, const std::string& canonical, SpecBook& specs) {
  const auto canonical_of = [&](const std::string& text) {
    return column == "method" ? specs.method(text).spec() : specs.problem(text)->spec();
  };
  try {
    const Spec spec = Spec::parse(canonical);
    const Spec defaults = Spec::parse(canonical_of(spec.name));
    std::vector<std::string> changed;
    for (const auto& [key, value] : spec.values) {
      const auto found = defaults.values.find(key);
      if (found == defaults.values.end() || found->second != value) {
        changed.push_back(key + "=" + value);
      }
    }
    const std::string label =
        changed.empty() ? spec.name : fmt::format("{}:{}", spec.name, fmt::join(changed, ","));
    return canonical_of(label) == canonical ? label : canonical;
  } catch (const InputError&) {
    return canonical;
  }
}

std::vector<Row> with_short_specs(std::vector<Row> rows, SpecBook& specs) {
  for (Row& row : rows) {
    for (const char* column : {"method", "problem"}) {
      const auto found = row.find(column);
      if (found != row.end()) found->second = short_spec(column, found->second, specs);
    }
  }
  return rows;
}

// A message that quotes the method's canonical spec, with the short label table.md shows
// instead: the reason a row was skipped reads "method 'hp'", not every default of hp.
std::string short_specs_in(std::string message, const MethodFactory& method, SpecBook& specs) {
  const std::string& canonical = method.spec();
  const std::string from = "'" + canonical + "'";
  const std::string to = "'" + short_spec("method", canonical, specs) + "'";
  for (auto at = message.find(from); at != std::string::npos; at = message.find(from, at)) {
    message.replace(at, from.size(), to);
    at += to.size();
  }
  return message;
}

struct OrderJob {
  std::string label, problem, method;
  const OrderBlock* block;
  OrderStudy study;
};

struct StabilityJob {
  std::string label, problem, method;
  const StabilityOptions* options;
  Row row;
};

// The scene's units in the canonical expansion order: [[runs]] blocks × problems × methods × dt,
// then [[orders]] blocks × problems × methods, then [[stability]] blocks × problems × methods.
// A shard and a merge count units in this order, so it must not depend on anything but the scene.
struct Plan {
  std::vector<Job> jobs;
  std::vector<OrderJob> order_jobs;
  std::vector<StabilityJob> stability_jobs;
};

Plan expand_scene(const Scene& scene, const SweepOptions& options) {
  namespace fs = std::filesystem;
  std::set<std::string> series_paths;
  Plan plan;
  auto& jobs = plan.jobs;
  // Optional metrics are computed in a scene when its table lists them (structure_metrics.hpp).
  std::vector<std::string> requested_metrics;
  for (const auto& name : optional_metric_names()) {
    if (std::find(scene.table_columns.begin(), scene.table_columns.end(), name) !=
        scene.table_columns.end()) {
      requested_metrics.push_back(name);
    }
  }
  for (const auto& block : scene.runs) {
    const std::vector<double> dts = block.dts.empty() ? std::vector<double>{0.0} : block.dts;
    for (const auto& problem : block.problems) {
      for (const auto& method : block.methods) {
        for (double dt : dts) {
          Job job{block.label, problem, method, {}, block.timing_repeats, {}, true};
          job.config.dt = dt;
          job.config.t_end = block.t_end;
          job.config.timing_repeats = 0;
          job.config.timing_budget_s = block.timing_budget_s;
          job.config.diverge_factor = block.diverge_factor;
          job.config.max_steps = block.max_steps;
          job.config.wall_budget_s = block.wall_budget_s;
          job.config.extra_metrics = requested_metrics;
          job.config.command_line = options.command_line;
          if (block.series_every > 0) {
            job.config.series_every = block.series_every;
            job.config.series_state = block.series_state;
            job.config.series_section = block.series_section;
            if (block.series_section >= 0) {
              try {
                check_series_section(*scene.specs->problem(problem), block.series_section);
              } catch (const InputError& error) {
                throw InputError(fmt::format("[[runs]] '{}': {}", block.label, error.what()));
              }
            }
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
            // A sweep in memory (no output folder) writes no series files.
            if (!options.out_dir.empty()) {
              job.config.series_path = (fs::path(options.out_dir) / normal).string();
            }
          }
          jobs.push_back(std::move(job));
        }
      }
    }
  }
  auto& order_jobs = plan.order_jobs;
  for (const auto& block : scene.orders) {
    for (const auto& problem : block.problems) {
      for (const auto& method : block.methods) {
        order_jobs.push_back({block.label, problem, method, &block, {}});
      }
    }
  }
  auto& stability_jobs = plan.stability_jobs;
  for (const auto& block : scene.stability) {
    for (const auto& problem : block.problems) {
      for (const auto& method : block.methods) {
        stability_jobs.push_back({block.label, problem, method, &block.options, {}});
      }
    }
  }
  return plan;
}

// Expected steps of a fixed-step run; an adaptive one (dt 0) is assumed to take the steps of
// the scene's finest fixed step, or 100 per unit of time in a scene without one: an estimate
// that only weighs the ETA.
double run_steps(double t_end, double dt, double adaptive_dt) {
  return std::max(1.0, t_end / (dt > 0 ? dt : adaptive_dt));
}

std::vector<double> plan_unit_steps(const Plan& plan) {
  double finest_dt = 0.01;
  bool any_fixed = false;
  for (const auto& job : plan.jobs) {
    if (job.config.dt > 0) {
      finest_dt = any_fixed ? std::min(finest_dt, job.config.dt) : job.config.dt;
      any_fixed = true;
    }
  }
  std::vector<double> steps;
  for (const auto& job : plan.jobs) {
    steps.push_back(run_steps(job.config.t_end, job.config.dt, finest_dt));
  }
  for (const auto& job : plan.order_jobs) {
    // Levels dt0, dt0/2, ...: t_end/dt0 · (1 + 2 + ... + 2^(levels-1)).
    steps.push_back(run_steps(job.block->t_end, job.block->dt0, finest_dt) *
                    (std::ldexp(1.0, job.block->levels) - 1));
  }
  for (const auto& job : plan.stability_jobs) {
    // A geometric scan over the range, then a bisection to rel_tol, each run at least
    // min_steps long.
    const StabilityOptions& options = *job.options;
    const double low = options.h_min > 0 ? options.h_min : options.homega_min;
    const double high = options.h_min > 0 ? options.h_max : options.homega_max;
    const double scan = options.scan_points_per_decade * std::log10(std::max(high / low, 10.0));
    const double bisection = std::log2(1 / std::max(options.rel_tol, 1e-16));
    steps.push_back((scan + bisection) * static_cast<double>(options.min_steps));
  }
  return steps;
}

// A shard's tables (see SweepOptions::shard_count): the rows of its units with their canonical
// index, each table over the columns its own rows set; `geomint merge` unites them.
int write_shard(const Plan& plan, const std::vector<size_t>& accuracy_units,
                const std::vector<size_t>& stability_units,
                const std::vector<std::pair<std::string, std::string>>& lines,
                const SweepOptions& options) {
  const ShardId id{options.shard_index, options.shard_count};
  const size_t runs = plan.jobs.size(), orders = plan.order_jobs.size();
  int failed = 0;
  std::vector<RunRecord> summary, points;
  std::vector<OrderRecord> order;
  std::vector<size_t> summary_k, points_k, order_k, stability_k;
  for (size_t k : accuracy_units) {
    if (k < runs) {
      summary.push_back(plan.jobs[k].record);
      summary_k.push_back(k);
      failed += !plan.jobs[k].ok;
      continue;
    }
    const OrderJob& job = plan.order_jobs[k - runs];
    order.push_back(job.study.record);
    order.back().label = job.label;
    order_k.push_back(k);
    failed += job.study.record.status == "error";
    for (const auto& point : job.study.runs) {
      points.push_back(point.record);
      points.back().label = job.label;
      points_k.push_back(k);
    }
  }
  std::vector<Row> stability;
  for (size_t s : stability_units) {
    stability.push_back(plan.stability_jobs[s].row);
    stability_k.push_back(runs + orders + s);
  }
  const std::string& out = options.out_dir;
  const std::string& hash = options.scene_hash;
  if (runs) {
    write_shard_table(out, "summary", id, hash, to_rows(summary), summary_k,
                      record_columns(summary), lines);
  }
  if (orders) {
    write_shard_table(out, "order", id, hash, to_rows(order), order_k,
                      columns_of(order_schema(), order), lines);
    write_shard_table(out, "order_points", id, hash, to_rows(points), points_k,
                      record_columns(points), lines);
  }
  if (!plan.stability_jobs.empty()) {
    write_shard_table(out, "stability", id, hash, stability, stability_k,
                      column_union(stability, stability_columns()), lines);
  }
  return failed;
}

std::string read_table_text(const std::filesystem::path& path) {
  std::ifstream stream(path);
  std::stringstream text;
  text << stream.rdbuf();
  if (!stream) throw InputError(fmt::format("cannot read '{}'", path.string()));
  return text.str();
}

// The CSV text after its `#` provenance lines.
std::string without_provenance(const std::string& text) {
  size_t start = 0;
  while (start < text.size() && text[start] == '#') {
    const size_t end = text.find('\n', start);
    if (end == std::string::npos) return "";
    start = end + 1;
  }
  return text.substr(start);
}

// The temporaries a killed sweep, merge or shard of this scene left in the folders they write
// (the tables, shards/, the series folders), removed by the next of them (table.hpp).
void remove_stale_outputs(const Plan& plan, const std::string& out_dir) {
  namespace fs = std::filesystem;
  static const std::set<std::string> tables = {"summary.csv",   "order.csv", "order_points.csv",
                                               "stability.csv", "table.md",  "hosts.csv"};
  geomint::remove_stale_temporaries(out_dir,
                                    [](const std::string& name) { return tables.count(name) > 0; });
  static const std::regex shard_name(R"(^[a-z_]+\.[0-9]+-of-[0-9]+\.csv$)");
  geomint::remove_stale_temporaries(
      (fs::path(out_dir) / "shards").string(),
      [](const std::string& name) { return std::regex_match(name, shard_name); });
  std::map<std::string, std::set<std::string>> series;
  for (const auto& job : plan.jobs) {
    if (job.config.series_path.empty()) continue;
    const fs::path path(job.config.series_path);
    series[path.parent_path().string()].insert(path.filename().string());
  }
  for (const auto& [folder, names] : series) {
    geomint::remove_stale_temporaries(
        folder, [&names = names](const std::string& name) { return names.count(name) > 0; });
  }
}

// Every file the sweep will write, checked before its first run: a folder where summary.csv
// goes, a file named `series`, a name too long are bad input, not an error after the runs.
void check_sweep_outputs(const Plan& plan, const SweepOptions& options) {
  const auto tables =
      shard_tables(plan.jobs.size(), plan.order_jobs.size(), plan.stability_jobs.size());
  const std::filesystem::path out(options.out_dir);
  for (const auto& table : tables) {
    check_output_file(
        options.shard_count > 0
            ? shard_file(options.out_dir, table, {options.shard_index, options.shard_count})
            : (out / (table + ".csv")).string(),
        "output");
  }
  if (options.shard_count == 0) check_output_file((out / "table.md").string(), "output");
  for (const auto& job : plan.jobs) {
    if (!job.config.series_path.empty()) check_output_file(job.config.series_path, "output");
  }
}

}  // namespace

void remove_stale_temporaries(const Scene& scene, const std::string& out_dir) {
  SweepOptions options;
  options.out_dir = out_dir;
  remove_stale_outputs(expand_scene(scene, options), out_dir);
}

const ResultTable* SweepResult::table(const std::string& name) const {
  for (const auto& table : tables) {
    if (table.name == name) return &table;
  }
  return nullptr;
}

SceneTables SweepResult::scene_tables() const {
  SceneTables rows;
  if (const ResultTable* summary = table("summary")) rows.summary = summary->rows;
  if (const ResultTable* order = table("order")) rows.order = order->rows;
  if (const ResultTable* stability = table("stability")) rows.stability = stability->rows;
  return rows;
}

int run_sweep(const Scene& scene, const SweepOptions& options) {
  // An empty folder is the working directory, as it always was for the program.
  SweepOptions writing = options;
  if (writing.out_dir.empty()) writing.out_dir = ".";
  return sweep(scene, writing).failed;
}

SweepResult sweep(const Scene& scene, const SweepOptions& options) {
  namespace fs = std::filesystem;
  const bool sharded = options.shard_count > 0;
  const bool writes = !options.out_dir.empty();
  if (sharded && !writes) {
    throw InputError("a sharded sweep writes shard files: give it an output folder");
  }
  if (writes) check_output_dir(options.out_dir, "output folder");
  Plan plan = expand_scene(scene, options);
  if (writes) check_sweep_outputs(plan, options);
  auto& jobs = plan.jobs;
  auto& order_jobs = plan.order_jobs;
  auto& stability_jobs = plan.stability_jobs;
  SpecBook& specs = *scene.specs;
  const ShardId shard{options.shard_index, options.shard_count};
  // The shards of one sweep write disjoint files and share the folder; anything else owns it.
  // A sweep in memory writes nothing and takes no folder.
  std::optional<OutputFolderLock> lock;
  if (writes) {
    lock.emplace(
        options.out_dir,
        sharded ? OutputFolderLock::Mode::kShared : OutputFolderLock::Mode::kExclusive,
        sharded ? fmt::format("geomint sweep --shard {}", shard_text(shard)) : "geomint sweep");
    check_folder_scene(options.out_dir, options.scene_name);
    remove_stale_outputs(plan, options.out_dir);
  }
  // The units of this sweep by canonical index k (runs, order studies, stability searches):
  // all of them, or a shard's k mod N == i (round-robin, so long runs spread over the shards).
  const auto mine = [&](size_t k) {
    return !sharded || k % static_cast<size_t>(shard.count) == static_cast<size_t>(shard.index);
  };
  std::vector<size_t> accuracy_units, stability_units;
  for (size_t k = 0; k < jobs.size() + order_jobs.size(); ++k) {
    if (mine(k)) accuracy_units.push_back(k);
  }
  for (size_t s = 0; s < stability_jobs.size(); ++s) {
    if (mine(jobs.size() + order_jobs.size() + s)) stability_units.push_back(s);
  }
  const bool timing = options.timing && !sharded;
  // Progress units: this sweep's accuracy units, its stability searches, its timing passes.
  const std::vector<double> all_steps = plan_unit_steps(plan);
  std::vector<double> unit_steps;
  for (size_t k : accuracy_units) unit_steps.push_back(all_steps[k]);
  for (size_t s : stability_units) {
    unit_steps.push_back(all_steps[jobs.size() + order_jobs.size() + s]);
  }
  for (size_t k = 0; k < jobs.size(); ++k) {
    if (timing && jobs[k].timing_repeats > 0) {
      unit_steps.push_back(jobs[k].timing_repeats * all_steps[k]);
    }
  }
  Progress progress(unit_steps, options);

  // Accuracy runs (parallel); specs were validated when the scene was loaded.
  parallel_for(accuracy_units.size(), options.jobs, [&](size_t unit) {
    const size_t i = accuracy_units[unit];
    if (i < jobs.size()) {
      Job& job = jobs[i];
      try {
        // The objects load_scene parsed (a Scene built in code: parsed here, once per spec).
        RunSpec spec{specs.problem(job.problem), specs.method(job.method), job.config};
        if (const auto reason = inapplicable(spec)) {
          // A scene's problems × methods product may pair an unconstrained method with a
          // constrained problem (or the reverse): a row that says why, not a run.
          job.record =
              error_record(job.problem, job.method, short_specs_in(*reason, spec.method, specs));
          job.record.status = "skipped";
          job.ok = false;
          job.record.label = job.label;
          progress.tick(unit);
          return;
        }
        RunResult result = run_one(spec);
        job.record = std::move(result.record);
        job.ok = result.ok;
        if (timing && job.timing_repeats > 0 && job.ok) job.spec = std::move(spec);
      } catch (const std::exception& error) {
        job.record = error_record(job.problem, job.method, error.what());
        job.ok = false;
      }
      job.record.label = job.label;
    } else {
      OrderJob& job = order_jobs[i - jobs.size()];
      try {
        job.study =
            order_study(specs.problem(job.problem), specs.method(job.method), job.block->dt0,
                        job.block->levels, job.block->t_end, job.block->diverge_factor);
      } catch (const std::exception& error) {
        job.study = OrderStudy{};
        job.study.record = error_record<OrderRecord>(job.problem, job.method, error.what());
      }
    }
    progress.tick(unit);
  });
  // Stability searches (parallel; each is a sequence of short runs without observers).
  parallel_for(stability_units.size(), options.jobs, [&](size_t unit) {
    StabilityJob& job = stability_jobs[stability_units[unit]];
    try {
      job.row =
          stability_search(*specs.problem(job.problem), specs.method(job.method), *job.options).row;
    } catch (const std::exception& error) {
      // E.g. a problem without omega_max given an h*omega range: a row, not a crashed thread.
      job.row = to_row(error_record(job.problem, job.method, error.what()));
    }
    job.row["label"] = job.label;
    progress.tick(accuracy_units.size() + unit);
  });
  // Timing runs, one at a time so they do not compete for cores.
  size_t timing_unit = accuracy_units.size() + stability_units.size();
  for (auto& job : jobs) {
    if (!timing || job.timing_repeats == 0) continue;
    if (job.ok) {
      try {
        record_timing(time_run(*job.spec, job.timing_repeats), job.record);
        job.ok = job.record.status != kTimeoutStatus;  // a timeout is a failure row
      } catch (const std::exception& error) {
        job.record.message = fmt::format("timing pass failed: {}", error.what());
      }
    }
    progress.tick(timing_unit++);
  }

  auto lines = provenance(options.command_line);
  if (!options.scene_name.empty()) lines.emplace_back("scene", options.scene_name);
  lines.emplace_back("variant", options.variant);
  SweepResult result;
  if (sharded) {
    result.failed = write_shard(plan, accuracy_units, stability_units, lines, options);
    return result;
  }
  int& failed = result.failed;
  std::vector<RunRecord> summary_records, order_point_records;
  std::vector<OrderRecord> order_records;
  for (const auto& job : jobs) {
    summary_records.push_back(job.record);
    failed += !job.ok;
  }
  for (auto& job : order_jobs) {
    order_records.push_back(job.study.record);
    order_records.back().label = job.label;
    failed += job.study.record.status == "error";
    for (const auto& point : job.study.runs) {
      order_point_records.push_back(point.record);
      order_point_records.back().label = job.label;
    }
  }
  // The tables the scene has, in memory; the files below are written from them alone.
  if (!summary_records.empty()) {
    result.tables.push_back(record_table("summary", summary_records, lines));
  }
  if (!order_records.empty()) {
    result.tables.push_back(order_table(order_records, lines));
    ResultTable points = record_table("order_points", order_point_records, lines);
    points.columns.clear();
    for (const auto& name : order_points_columns(record_columns(order_point_records))) {
      points.columns.push_back({name, record_column_type(name)});
    }
    result.tables.push_back(std::move(points));
  }
  if (!stability_jobs.empty()) {
    std::vector<Row> rows;
    for (const auto& job : stability_jobs) rows.push_back(job.row);
    std::vector<TableColumn> columns;
    for (const auto& name : column_union(rows, stability_columns())) {
      columns.push_back({name, stability_column_type(name)});
    }
    result.tables.push_back({"stability", lines, std::move(columns), std::move(rows)});
  }
  if (writes) {
    const fs::path out(options.out_dir);
    for (const auto& table : result.tables) {
      write_file_atomic((out / (table.name + ".csv")).string(), to_csv(table));
    }
    write_file_atomic((out / "table.md").string(),
                      scene_markdown(scene, result.scene_tables(), options.command_line,
                                     table_citation(lines, options.scene_hash)));
  }
  return result;
}

std::vector<std::string> order_points_columns(std::vector<std::string> columns) {
  // order_points.csv lists the ladder level right after the label, where a reader looks first.
  const auto level = std::find(columns.begin(), columns.end(), "order_level");
  if (level != columns.end()) {
    columns.erase(level);
    columns.insert(columns.begin() + (columns.front() == "label"), "order_level");
  }
  return columns;
}

std::vector<double> expected_unit_steps(const Scene& scene) {
  return plan_unit_steps(expand_scene(scene, SweepOptions{}));
}

SceneUnits scene_units(const Scene& scene) {
  const Plan plan = expand_scene(scene, SweepOptions{});
  return {plan.jobs.size(), plan.order_jobs.size(), plan.stability_jobs.size()};
}

void run_timing_only(const Scene& scene, const SweepOptions& options) {
  namespace fs = std::filesystem;
  check_output_dir(options.out_dir, "output folder");
  Plan plan = expand_scene(scene, options);
  const fs::path out(options.out_dir);
  const fs::path summary_path = out / "summary.csv";
  if (!fs::exists(summary_path)) {
    throw InputError(fmt::format(
        "--timing-only: '{}' does not exist: run `geomint merge {}` (or a --no-timing sweep) "
        "first",
        summary_path.string(), options.out_dir));
  }
  const OutputFolderLock lock(options.out_dir, OutputFolderLock::Mode::kExclusive,
                              "geomint sweep --timing-only");
  check_folder_scene(options.out_dir, options.scene_name);
  remove_stale_outputs(plan, options.out_dir);
  CsvTable summary = read_csv_file(summary_path.string());
  SceneTables tables;
  tables.summary = std::move(summary.rows);
  const std::vector<std::string> columns = std::move(summary.columns);
  const std::string command = summary.value("command");
  if (tables.summary.size() != plan.jobs.size()) {
    throw InputError(fmt::format(
        "--timing-only: '{}' has {} rows, the scene {} runs: merge or sweep this scene again",
        summary_path.string(), tables.summary.size(), plan.jobs.size()));
  }
  for (size_t k = 0; k < plan.jobs.size(); ++k) {
    const auto label = tables.summary[k].find("label");
    if (label == tables.summary[k].end() || label->second != plan.jobs[k].label) {
      throw InputError(fmt::format(
          "--timing-only: row {} of '{}' is not the scene's run {} (block '{}'): merge or sweep "
          "this scene again",
          k + 1, summary_path.string(), k + 1, plan.jobs[k].label));
    }
  }
  // Timing runs one at a time on this node, as in a single-machine sweep.
  const std::vector<double> all_steps = plan_unit_steps(plan);
  std::vector<double> unit_steps;
  for (size_t k = 0; k < plan.jobs.size(); ++k) {
    if (plan.jobs[k].timing_repeats > 0) {
      unit_steps.push_back(plan.jobs[k].timing_repeats * all_steps[k]);
    }
  }
  Progress progress(unit_steps, options);
  size_t timing_unit = 0;
  std::set<std::string> present(columns.begin(), columns.end());
  for (size_t k = 0; k < plan.jobs.size(); ++k) {
    const Job& job = plan.jobs[k];
    if (job.timing_repeats == 0) continue;
    Row& row = tables.summary[k];
    const auto status = row.find("status");
    if (status != row.end() && status->second == "ok") {
      RunRecord timing;
      try {
        record_timing(time_run(job.problem, job.method, job.config, job.timing_repeats), timing);
      } catch (const std::exception& error) {
        timing.message = fmt::format("timing pass failed: {}", error.what());
      }
      for (const auto& [column, cell] : to_row(timing)) {
        // The status changes only when the timing pass ran out of wall-clock budget.
        if (column != "problem" && column != "method" &&
            (column != "status" || cell == kTimeoutStatus)) {
          row[column] = cell;
          present.insert(column);
        }
      }
    }
    progress.tick(timing_unit++);
  }
  std::vector<std::string> ordered;
  for (const auto& column : record_schema()) {
    if (present.count(column.name)) ordered.push_back(column.name);
  }
  // The tables now hold what a timed single-machine sweep writes: its command, this node's CPU.
  const std::string timed_command = [&] {
    const std::string flag = " --no-timing";
    const auto at = command.find(flag);
    return at == std::string::npos ? command
                                   : command.substr(0, at) + command.substr(at + flag.size());
  }();
  auto lines = provenance(timed_command);
  if (!options.scene_name.empty()) lines.emplace_back("scene", options.scene_name);
  lines.emplace_back("variant", options.variant);
  std::string header;
  for (const auto& [key, value] : lines) header += provenance_line(key, value);
  for (const char* name : {"order.csv", "order_points.csv", "stability.csv"}) {
    const fs::path path = out / name;
    if (!fs::exists(path)) continue;
    const std::string text = read_table_text(path);
    // Read for table.md and checked whole, as every table geomint reads back.
    const auto rows = parse_csv(text, path.string());
    if (std::string(name) == "order.csv") tables.order = rows;
    if (std::string(name) == "stability.csv") tables.stability = rows;
    write_file_atomic(path.string(), header + without_provenance(text));
  }
  write_file_atomic(summary_path.string(), to_csv(tables.summary, ordered, lines));
  write_file_atomic(
      (out / "table.md").string(),
      scene_markdown(scene, tables, timed_command, table_citation(lines, options.scene_hash)));
}

std::vector<Row> rows_with_short_specs(std::vector<Row> rows) {
  SpecBook specs;
  return with_short_specs(std::move(rows), specs);
}

TableCitation table_citation(const std::vector<std::pair<std::string, std::string>>& lines,
                             const std::string& scene_hash) {
  TableCitation citation;
  citation.scene_hash = scene_hash;
  for (const auto& [key, value] : lines) {
    if (key == "geomint") citation.geomint = value;
    if (key == "scene") citation.scene = value;
    if (key == "variant") citation.variant = value;
    if (key == "date") citation.date = value;
  }
  return citation;
}

namespace {

// A scene's description is plain text ("h*omega", "q_k", "<= 1"): its Markdown punctuation is
// backslash-escaped so that table.md (and the results site) shows it as written, not as emphasis,
// code or HTML; a line that would open a heading, list or quote starts with its escaped mark.
std::string markdown_text(const std::string& text) {
  std::string out;
  bool line_start = true;
  for (const char c : text) {
    const bool inline_mark = std::string_view("\\`*_[]<>|~").find(c) != std::string_view::npos;
    const bool block_mark =
        line_start && std::string_view("#-+=").find(c) != std::string_view::npos;
    if (inline_mark || block_mark) out += '\\';
    out += c;
    if (c != ' ') line_start = c == '\n';
  }
  return out;
}

// "| name | value |" with an absent value shown as such, so a block is never half empty.
constexpr const char* kSceneHashField = "scene hash";

std::string citation_row(const std::string& name, const std::string& value) {
  return fmt::format("| {} | {} |\n", name, value.empty() ? "(not recorded)" : value);
}

std::string how_to_cite(const TableCitation& citation) {
  // "0.1.0 (cd4c0e47a208)": the version, then the commit in parentheses.
  std::string version = citation.geomint, sha;
  const auto open = citation.geomint.find(" (");
  if (open != std::string::npos && citation.geomint.back() == ')') {
    version = citation.geomint.substr(0, open);
    sha = citation.geomint.substr(open + 2, citation.geomint.size() - open - 3);
  }
  const std::string scene = citation.variant.empty() || citation.scene.empty()
                                ? citation.scene
                                : fmt::format("{} ({} variant)", citation.scene, citation.variant);
  std::string block = "## How to cite\n\n";
  block +=
      "Cite these tables by the geomint version and commit that computed them, the scene and "
      "the hash of its scene.toml (CITATION.cff cites geomint itself):\n\n";
  block += "| field | value |\n|---|---|\n";
  block += citation_row("geomint version", version);
  block += citation_row("git SHA", sha);
  block += citation_row("scene", scene);
  block += citation_row(kSceneHashField, citation.scene_hash);
  block += citation_row("date", citation.date);
  block += fmt::format("\n> geomint {}{}, scene {}, scene.toml {}, tables of {}.\n", version,
                       sha.empty() ? "" : " (git " + sha + ")",
                       citation.scene.empty() ? "?" : citation.scene,
                       citation.scene_hash.empty() ? "(hash not recorded)" : citation.scene_hash,
                       citation.date.empty() ? "(date not recorded)" : citation.date);
  return block;
}

}  // namespace

std::string recorded_scene_hash(const std::string& table_md_path) {
  std::ifstream in(table_md_path);
  const std::string marker = fmt::format("| {} | ", kSceneHashField);
  std::string line, recorded;
  while (std::getline(in, line)) {
    if (line.rfind(marker, 0) == 0 && line.size() > marker.size() + 2 &&
        line.compare(line.size() - 2, 2, " |") == 0) {
      recorded = line.substr(marker.size(), line.size() - marker.size() - 2);
    }
  }
  return recorded == "(not recorded)" ? std::string() : recorded;
}

std::string scene_markdown(const Scene& scene, const SceneTables& tables,
                           const std::string& command_line, const TableCitation& citation) {
  std::string markdown = fmt::format("# {}\n\n", scene.title);
  if (!scene.description.empty()) markdown += markdown_text(scene.description) + "\n\n";
  if (!tables.summary.empty()) {
    const auto columns = scene.table_columns.empty()
                             ? column_union(tables.summary, standard_columns())
                             : scene.table_columns;
    markdown += "## Runs (summary.csv)\n\n" +
                to_markdown(with_short_specs(tables.summary, *scene.specs), columns) + "\n";
  }
  if (!tables.order.empty()) {
    markdown +=
        "## Fitted convergence orders (order.csv)\n\n" +
        to_markdown(with_short_specs(tables.order, *scene.specs),
                    {"problem", "method", "order", "declared_order", "points_used", "message"}) +
        "\n";
  }
  if (!tables.stability.empty()) {
    markdown += "## Largest stable h*omega (stability.csv)\n\n" +
                to_markdown(with_short_specs(tables.stability, *scene.specs),
                            {"label", "problem", "method", "homega_max_measured", "predicted",
                             "rel_diff", "status", "message"},
                            6) +
                "\n";
  }
  markdown += fmt::format("Produced by `{}`.\n\n", command_line);
  return markdown + how_to_cite(citation);
}

void rewrite_scene_markdown(const Scene& scene, const SweepOptions& options) {
  namespace fs = std::filesystem;
  const Plan plan = expand_scene(scene, options);
  std::vector<std::string> run_labels, order_labels, stability_labels;
  for (const auto& job : plan.jobs) run_labels.push_back(job.label);
  for (const auto& job : plan.order_jobs) order_labels.push_back(job.label);
  for (const auto& job : plan.stability_jobs) stability_labels.push_back(job.label);
  SceneTables tables;
  std::string command_line;
  std::vector<std::pair<std::string, std::string>> provenance_lines;
  // A table of another scene or variant (a copied folder, a wrong --out) would put this scene's
  // title over its rows: its provenance and its rows' blocks must be this scene's.
  const auto read = [&](const char* name, std::vector<Row>& rows,
                        const std::vector<std::string>& labels) {
    const fs::path path = fs::path(options.out_dir) / name;
    if (!fs::exists(path)) return;
    const CsvTable table = read_csv_file(path.string());
    const std::string scene_name = table.value("scene"), variant = table.value("variant");
    if (!options.scene_name.empty() && !scene_name.empty() && scene_name != options.scene_name) {
      throw InputError(fmt::format(
          "--markdown-only: '{}' is a table of scene '{}', not of scene '{}': sweep this scene "
          "into its own folder",
          path.string(), scene_name, options.scene_name));
    }
    if (!variant.empty() && variant != options.variant) {
      throw InputError(fmt::format(
          "--markdown-only: '{}' is a table of the {} variant, not of the {} one{}", path.string(),
          variant, options.variant, options.variant == "quick" ? "" : " (give --quick)"));
    }
    if (table.rows.size() != labels.size()) {
      throw InputError(
          fmt::format("--markdown-only: '{}' has {} rows, the scene {}: sweep this scene again",
                      path.string(), table.rows.size(), labels.size()));
    }
    for (size_t k = 0; k < labels.size(); ++k) {
      const auto label = table.rows[k].find("label");
      if (label == table.rows[k].end() || label->second != labels[k]) {
        throw InputError(fmt::format(
            "--markdown-only: row {} of '{}' is not of the scene's block '{}': sweep this scene "
            "again",
            k + 1, path.string(), labels[k]));
      }
    }
    rows = table.rows;
    if (command_line.empty()) {
      command_line = table.value("command");
      provenance_lines = table.provenance;
    }
  };
  read("summary.csv", tables.summary, run_labels);
  read("order.csv", tables.order, order_labels);
  read("stability.csv", tables.stability, stability_labels);
  if (command_line.empty()) {
    throw InputError(fmt::format(
        "'{}' holds no table with a '# command:' line (summary.csv, order.csv, stability.csv): "
        "run the sweep first",
        options.out_dir));
  }
  write_file_atomic((fs::path(options.out_dir) / "table.md").string(),
                    scene_markdown(scene, tables, command_line,
                                   table_citation(provenance_lines, options.scene_hash)));
}

}  // namespace geomint
