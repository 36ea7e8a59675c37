// Per-step cost against problem size (docs/METHODS.md "Scale"): Störmer–Verlet and
// the HP midpoint step (Kharevych et al. 2006; hp:alpha=0.5) on spring_chain (10²…10⁶ dof) and on
// elastic_bar (10²…2·10⁵ tets, HP per linear solver), with the fitted exponent of cost against dof,
// the gradient's element throughput and the process's peak RSS. `--csv FILE` runs the reduced
// sizes that `make reproduce-figures` plots (scripts/scaling.sh) and writes them with provenance.
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "harness/table.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace {

using geomint::Problem;
using geomint::State;

// h as a multiple of the explicit stability limit 2/ω_max: inside it for Störmer–Verlet, far
// beyond it for the implicit step (the regime it is for; docs/METHODS.md "Scale" uses 20×).
constexpr double kExplicitStepOverLimit = 0.5;
constexpr double kImplicitStepOverLimit = 20;
constexpr long kImplicitRunSteps = 20;

struct Size {
  std::string problem;  // spec
  double elements;      // springs or tetrahedra
  bool quick;           // also in the --csv run of make reproduce-figures
};

struct Series {
  std::string label;
  std::string method;
  std::vector<Size> sizes;
};

std::vector<Size> chain_sizes(long largest) {
  std::vector<Size> sizes;
  for (long n = 100; n <= largest; n *= 10) {
    sizes.push_back(
        {"spring_chain:n=" + std::to_string(n), static_cast<double>(n + 1), n <= 100000});
  }
  return sizes;
}

// nx × n × n cells of 6 tetrahedra: 96 … 196 800 tets.
std::vector<Size> bar_sizes(double largest_tets) {
  struct Cells {
    int nx, n;
  };
  std::vector<Size> sizes;
  for (const Cells cells : {Cells{4, 2}, Cells{10, 4}, Cells{16, 6}, Cells{26, 8}, Cells{40, 11},
                            Cells{65, 16}, Cells{82, 20}}) {
    const double tets = 6.0 * cells.nx * cells.n * cells.n;
    if (tets > largest_tets) break;
    sizes.push_back({"elastic_bar:nx=" + std::to_string(cells.nx) +
                         ",ny=" + std::to_string(cells.n) + ",nz=" + std::to_string(cells.n),
                     tets, tets < 1.2e4});
  }
  return sizes;
}

// The simplicial LDLᵀ stops where one step takes minutes (343 s at 10⁵ tets), CHOLMOD
// at 10⁵ tets (10 s per step); CG goes to 2·10⁵.
std::vector<Series> all_series() {
  return {
      {"verlet_chain", "stormer_verlet", chain_sizes(1000000)},
      {"hp_chain", "hp:alpha=0.5", chain_sizes(1000000)},
      {"verlet_bar", "stormer_verlet", bar_sizes(2e5)},
      {"hp_bar_ldlt", "hp:alpha=0.5,linear_solver=ldlt", bar_sizes(1.2e4)},
      {"hp_bar_cholmod", "hp:alpha=0.5,linear_solver=cholmod", bar_sizes(1.2e5)},
      {"hp_bar_cg", "hp:alpha=0.5,linear_solver=cg", bar_sizes(2e5)},
  };
}

double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// One benchmark iteration = one step of `method` on `problem` from a state that has already
// taken one (untimed) step, so the once-per-run symbolic analysis is not in the per-step cost.
// Implicit runs restart (untimed) every kImplicitRunSteps steps: at 20× the explicit limit the
// smallest bar's Newton iteration fails after some thousand steps of tumbling, which would
// otherwise leave later iterations stepping from an unspecified state.
void per_step(benchmark::State& state, const std::string& problem_spec, const std::string& method,
              double elements) {
  const auto problem = geomint::make_problem(problem_spec);
  const auto integrator = geomint::make_integrator(method);
  const bool implicit = (integrator->info().flags & geomint::kImplicit) != 0;
  State current = problem->initial_state();
  const double h = (implicit ? kImplicitStepOverLimit : kExplicitStepOverLimit) * 2 /
                   problem->omega_max(current.q);
  long failures = 0, newton_iterations = 0, run_steps = 0;
  auto restart = [&] {
    current = problem->initial_state();
    integrator->reset(*problem, current, h);
    failures += !integrator->step(*problem, current, h).ok;
    run_steps = 0;
  };
  restart();
  for (auto _ : state) {
    if (implicit && run_steps == kImplicitRunSteps) {
      state.PauseTiming();
      restart();
      state.ResumeTiming();
    }
    const long newton_before = integrator->counters().newton_iters;
    failures += !integrator->step(*problem, current, h).ok;
    newton_iterations += integrator->counters().newton_iters - newton_before;
    ++run_steps;
    benchmark::DoNotOptimize(current.q.data());
  }
  // Gradient throughput at this size: elements per second of one ∇V evaluation.
  geomint::Vec gradient;
  const auto start = std::chrono::steady_clock::now();
  problem->gradient(current.q, gradient);
  const double gradient_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  state.counters["dof"] = problem->dof();
  state.counters["elements"] = elements;
  state.counters["h"] = h;
  state.counters["newton_per_step"] =
      static_cast<double>(newton_iterations) / static_cast<double>(state.iterations());
  state.counters["failed_steps"] = static_cast<double>(failures);
  state.counters["gradient_elements_per_s"] = elements / std::max(gradient_s, 1e-12);
  state.counters["peak_rss_mib"] = peak_rss_mib();
}

struct Result {
  std::string series, method, problem;
  double seconds_per_step = 0;
  std::map<std::string, double> counters;
};

// Console output plus the numbers of every run, for the exponents and the CSV.
class CollectingReporter : public benchmark::ConsoleReporter {
 public:
  explicit CollectingReporter(std::map<std::string, Result>* results) : results_(results) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration || run.error_occurred) continue;
      Result& result = (*results_)[run.run_name.function_name];
      // Per iteration, in the run's display unit.
      result.seconds_per_step =
          run.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(run.time_unit);
      for (const auto& [name, counter] : run.counters) result.counters[name] = counter.value;
    }
    ConsoleReporter::ReportRuns(runs);
  }

 private:
  std::map<std::string, Result>* results_;
};

// Least-squares slope of log(seconds per step) against log(dof).
double fitted_exponent(const std::vector<const Result*>& points) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const Result* point : points) {
    const double x = std::log(point->counters.at("dof")), y = std::log(point->seconds_per_step);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double n = static_cast<double>(points.size());
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

int main(int argc, char** argv) {
  // --csv FILE: the reduced sizes, written as a table (the other arguments go to the library).
  std::string csv_path, command_line;
  std::vector<char*> arguments;
  for (int i = 0; i < argc; ++i) {
    command_line += (i ? " " : "") + std::string(argv[i]);
    if (std::strcmp(argv[i], "--csv") == 0 && i + 1 < argc) {
      csv_path = argv[++i];
      command_line += " " + csv_path;
    } else {
      arguments.push_back(argv[i]);
    }
  }
  int library_argc = static_cast<int>(arguments.size());
  benchmark::Initialize(&library_argc, arguments.data());
  if (benchmark::ReportUnrecognizedArguments(library_argc, arguments.data())) return 1;

  std::map<std::string, Result> results;
  std::map<std::string, std::vector<std::string>> names_by_series;
  for (const Series& series : all_series()) {
    for (const Size& size : series.sizes) {
      if (!csv_path.empty() && !size.quick) continue;
      const std::string name = series.label + "/" + size.problem;
      benchmark::RegisterBenchmark(name.c_str(), per_step, size.problem, series.method,
                                   size.elements)
          ->MeasureProcessCPUTime()
          ->Unit(benchmark::kMillisecond);
      results[name] = {series.label, series.method, size.problem, 0, {}};
      names_by_series[series.label].push_back(name);
    }
  }
  CollectingReporter reporter(&results);
  benchmark::RunSpecifiedBenchmarks(&reporter);

  std::vector<geomint::Row> rows;
  for (const Series& series : all_series()) {
    std::vector<const Result*> points;
    for (const std::string& name : names_by_series[series.label]) {
      const Result& result = results[name];
      if (result.counters.count("dof") == 0) continue;  // filtered out or skipped
      points.push_back(&result);
      geomint::Row row{{"series", series.label},
                       {"method", series.method},
                       {"problem", result.problem},
                       {"seconds_per_step", fmt::format("{:.6g}", result.seconds_per_step)}};
      for (const auto& [counter, value] : result.counters) {
        row[counter] = fmt::format("{:.6g}", value);
      }
      rows.push_back(row);
    }
    if (points.size() >= 2) {
      std::printf("exponent %-15s %-36s cost ~ dof^%.2f (%zu sizes, dof %.0f..%.0f)\n",
                  series.label.c_str(), series.method.c_str(), fitted_exponent(points),
                  points.size(), points.front()->counters.at("dof"),
                  points.back()->counters.at("dof"));
    }
  }
  if (!csv_path.empty()) {
    const std::vector<std::string> columns = geomint::column_union(
        rows, {"series", "method", "problem", "dof", "elements", "seconds_per_step", "h",
               "newton_per_step", "failed_steps", "gradient_elements_per_s", "peak_rss_mib"});
    geomint::write_file_atomic(csv_path,
                               geomint::to_csv(rows, columns, geomint::provenance(command_line)));
  }
  benchmark::Shutdown();
  return 0;
}
