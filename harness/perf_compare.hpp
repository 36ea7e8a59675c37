// Speed regressions as a statistical test (docs/PERF.md): the repeated
// measurements of two Google Benchmark JSON files (or folders of them, as `make perf` writes)
// compared per benchmark with a one-sided Mann–Whitney U test (Mann & Whitney 1947) and a
// relative threshold on the medians.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace geomint {

// Every repetition's real time of every benchmark (in nanoseconds), by name; aggregate rows
// (mean, median, stddev, cv) are recomputed here, not trusted. `context` keeps the provenance
// keys `make perf` writes (commit, compiler, cpu_model, threads, host_name, date).
struct BenchmarkSamples {
  std::map<std::string, std::vector<double>> real_time_ns;
  std::map<std::string, std::string> context;
};

// Limits of the input: one file's size (an endless input stops here), and one repetition's real
// time in ns (so medians, ratios and statistics stay finite).
inline constexpr std::size_t kMaxBenchmarkFileBytes = std::size_t{64} << 20;
inline constexpr double kMinBenchmarkTimeNs = 1e-9;
inline constexpr double kMaxBenchmarkTimeNs = 1e18;

// Reads one JSON file or every *.json file of a folder. InputError naming the file and what is
// wrong for anything short of a complete Google Benchmark JSON document: unparsable text (a
// truncated file), a missing "context" or "benchmarks", an iteration row without a name, a
// positive finite real_time or a known time_unit, a time outside [kMinBenchmarkTimeNs,
// kMaxBenchmarkTimeNs], a file over kMaxBenchmarkFileBytes, an error_occurred row, a benchmark name
// in two files of one folder, or no iteration row at all.
BenchmarkSamples load_benchmark_samples(const std::string& path);

// One-sided Mann–Whitney U test of H1: `slower` tends to be larger than `faster`. Returns the
// p-value: exact (the null distribution of U by recursion) when there are no ties and
// n·m ≤ 10⁴, otherwise the normal approximation with tie and continuity corrections.
struct MannWhitney {
  double u = 0;  // #{(i, j): slower_j > faster_i} + ½ #{ties}
  double p_value = 1;
  bool exact = false;
};
MannWhitney mann_whitney_greater(const std::vector<double>& faster,
                                 const std::vector<double>& slower);

// The smallest p-value the exact test can give with n and m samples, 1 / C(n + m, n): below the
// significance level or the comparison can never fail.
double mann_whitney_min_p(std::size_t n, std::size_t m);

struct PerfComparison {
  std::string name;
  std::size_t base_n = 0, new_n = 0;
  double base_median_ns = 0, new_median_ns = 0;
  double ratio = 1;  // new median / base median
  double p_slower = 1, p_faster = 1;
  std::string verdict;  // "slower", "faster", "same", "only in base", "only in new"
};

struct PerfCompareOptions {
  double alpha = 0.01;         // significance level of each one-sided test
  double min_slowdown = 0.05;  // relative change of the medians that counts, both ways
};

// Per benchmark (sorted by name): a slowdown is p_slower < alpha and ratio > 1 + min_slowdown;
// a speed-up the mirror image. InputError when a benchmark of both has too few repetitions for
// p < alpha to be reachable (naming it and the repetitions needed).
std::vector<PerfComparison> compare_benchmarks(const BenchmarkSamples& base,
                                               const BenchmarkSamples& candidate,
                                               const PerfCompareOptions& options);

}  // namespace geomint
