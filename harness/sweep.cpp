// The sweep executor (see sweep.hpp): jobs from a loaded scene, the thread pool, progress and
// the writers of the scene's tables.
#include "harness/sweep.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "harness/order.hpp"
#include "harness/paths.hpp"
#include "harness/run.hpp"
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

// Why `method` cannot run on `problem` (applicable(): constraints, a needed Hessian), if so.
std::optional<std::string> inapplicable(const std::string& problem, const std::string& method) {
  const Applicability fit = applicable(*make_integrator(method), *make_problem(problem));
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
// spec is shown as it is.
std::string short_spec(const std::string& column, const std::string& canonical) {
  const auto canonical_of = [&](const std::string& text) {
    return column == "method" ? make_integrator(text)->spec() : make_problem(text)->spec();
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

std::vector<Row> with_short_specs(std::vector<Row> rows) {
  for (Row& row : rows) {
    for (const char* column : {"method", "problem"}) {
      const auto found = row.find(column);
      if (found != row.end()) found->second = short_spec(column, found->second);
    }
  }
  return rows;
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
          Job job{block.label, problem, method, {}, block.timing_repeats, {}, true};
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
  for (const auto& job : jobs) timed += job.timing_repeats > 0;
  Progress progress(jobs.size() + order_jobs.size() + stability_jobs.size() + timed,
                    options.progress);

  // Accuracy runs (parallel); specs were validated when the scene was loaded.
  parallel_for(jobs.size() + order_jobs.size(), options.jobs, [&](size_t i) {
    if (i < jobs.size()) {
      Job& job = jobs[i];
      try {
        if (const auto reason = inapplicable(job.problem, job.method)) {
          // A scene's problems × methods product may pair an unconstrained method with a
          // constrained problem (or the reverse): a row that says why, not a run.
          job.record = error_record(job.problem, job.method, *reason);
          job.record.status = "skipped";
          job.ok = false;
          job.record.label = job.label;
          progress.tick();
          return;
        }
        RunResult result = run_one(job.problem, job.method, job.config);
        job.record = std::move(result.record);
        job.ok = result.ok;
      } catch (const std::exception& error) {
        job.record = error_record(job.problem, job.method, error.what());
        job.ok = false;
      }
      job.record.label = job.label;
    } else {
      OrderJob& job = order_jobs[i - jobs.size()];
      try {
        job.study = order_study(job.problem, job.method, job.block->dt0, job.block->levels,
                                job.block->t_end, job.block->diverge_factor);
      } catch (const std::exception& error) {
        job.study = OrderStudy{};
        job.study.record = error_record<OrderRecord>(job.problem, job.method, error.what());
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
      job.row = to_row(error_record(job.problem, job.method, error.what()));
    }
    job.row["label"] = job.label;
    progress.tick();
  });
  // Timing runs, one at a time so they do not compete for cores.
  for (auto& job : jobs) {
    if (job.timing_repeats == 0) continue;
    if (job.ok) {
      try {
        job.record.wall_s = time_run(job.problem, job.method, job.config, job.timing_repeats);
      } catch (const std::exception& error) {
        job.record.message = fmt::format("timing pass failed: {}", error.what());
      }
    }
    progress.tick();
  }

  auto lines = provenance(options.command_line);
  if (!options.scene_name.empty()) lines.emplace_back("scene", options.scene_name);
  lines.emplace_back("variant", options.variant);
  int failed = 0;
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
  const fs::path out(options.out_dir);
  SceneTables tables;
  tables.summary = to_rows(summary_records);
  tables.order = to_rows(order_records);
  if (!summary_records.empty()) {
    write_file_atomic((out / "summary.csv").string(), records_to_csv(summary_records, lines));
  }
  if (!order_records.empty()) {
    write_file_atomic((out / "order.csv").string(),
                      to_csv(tables.order, columns_of(order_schema(), order_records), lines));
    // order_points.csv lists the ladder level right after the label, where a reader looks first.
    std::vector<std::string> point_columns = record_columns(order_point_records);
    const auto level = std::find(point_columns.begin(), point_columns.end(), "order_level");
    if (level != point_columns.end()) {
      point_columns.erase(level);
      point_columns.insert(point_columns.begin() + (point_columns.front() == "label"),
                           "order_level");
    }
    write_file_atomic((out / "order_points.csv").string(),
                      to_csv(to_rows(order_point_records), point_columns, lines));
  }
  if (!stability_jobs.empty()) {
    for (const auto& job : stability_jobs) tables.stability.push_back(job.row);
    write_file_atomic(
        (out / "stability.csv").string(),
        to_csv(tables.stability, column_union(tables.stability, stability_columns()), lines));
  }
  write_file_atomic((out / "table.md").string(),
                    scene_markdown(scene, tables, options.command_line));
  return failed;
}

std::string scene_markdown(const Scene& scene, const SceneTables& tables,
                           const std::string& command_line) {
  std::string markdown = fmt::format("# {}\n\n", scene.title);
  if (!scene.description.empty()) markdown += scene.description + "\n\n";
  if (!tables.summary.empty()) {
    const auto columns = scene.table_columns.empty()
                             ? column_union(tables.summary, standard_columns())
                             : scene.table_columns;
    markdown +=
        "## Runs (summary.csv)\n\n" + to_markdown(with_short_specs(tables.summary), columns) + "\n";
  }
  if (!tables.order.empty()) {
    markdown +=
        "## Fitted convergence orders (order.csv)\n\n" +
        to_markdown(with_short_specs(tables.order),
                    {"problem", "method", "order", "declared_order", "points_used", "message"}) +
        "\n";
  }
  if (!tables.stability.empty()) {
    markdown += "## Largest stable h*omega (stability.csv)\n\n" +
                to_markdown(with_short_specs(tables.stability),
                            {"label", "problem", "method", "homega_max_measured", "predicted",
                             "rel_diff", "status", "message"},
                            6) +
                "\n";
  }
  markdown += fmt::format("Produced by `{}`.\n", command_line);
  return markdown;
}

void rewrite_scene_markdown(const Scene& scene, const std::string& out_dir) {
  namespace fs = std::filesystem;
  SceneTables tables;
  std::string command_line;
  const auto read = [&](const char* name, std::vector<Row>& rows) {
    const fs::path path = fs::path(out_dir) / name;
    if (!fs::exists(path)) return;
    std::ifstream stream(path);
    std::stringstream text;
    text << stream.rdbuf();
    if (!stream) throw InputError(fmt::format("cannot read '{}'", path.string()));
    try {
      rows = parse_csv(text.str());
    } catch (const std::runtime_error& error) {
      throw InputError(fmt::format("'{}': {}", path.string(), error.what()));
    }
    const std::string key = "# command: ";
    for (std::string line; command_line.empty() && std::getline(text, line) && line[0] == '#';) {
      if (line.rfind(key, 0) == 0) command_line = line.substr(key.size());
    }
  };
  read("summary.csv", tables.summary);
  read("order.csv", tables.order);
  read("stability.csv", tables.stability);
  if (command_line.empty()) {
    throw InputError(fmt::format(
        "'{}' holds no table with a '# command:' line (summary.csv, order.csv, stability.csv): "
        "run the sweep first",
        out_dir));
  }
  write_file_atomic((fs::path(out_dir) / "table.md").string(),
                    scene_markdown(scene, tables, command_line));
}

}  // namespace geomint
