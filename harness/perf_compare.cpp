// Speed regressions as a statistical test: Google Benchmark JSON reader and the one-sided
// Mann–Whitney U test (harness/perf_compare.hpp; docs/PERF.md).
#include "harness/perf_compare.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "problems/spec.hpp"

namespace geomint {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

double unit_in_ns(const std::string& file, const std::string& name, const std::string& unit) {
  if (unit == "ns") return 1;
  if (unit == "us") return 1e3;
  if (unit == "ms") return 1e6;
  if (unit == "s") return 1e9;
  throw InputError(fmt::format("{}: benchmark '{}' has time_unit '{}' (valid: ns, us, ms, s)", file,
                               name, unit));
}

std::string context_value(const json& value) {
  return value.is_string() ? value.get<std::string>() : value.dump();
}

// One file into `samples`; `owner` remembers which file each benchmark came from.
void load_file(const fs::path& path, BenchmarkSamples& samples,
               std::map<std::string, std::string>& owner) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("perf-compare: cannot read '{}'", file));
  // Read in blocks up to the cap, so an endless input (/dev/zero, a pipe from `yes`) stops at it
  // instead of at the end of memory.
  std::string text;
  std::vector<char> block(1 << 16);
  while (in.read(block.data(), static_cast<std::streamsize>(block.size())) || in.gcount() > 0) {
    text.append(block.data(), static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxBenchmarkFileBytes) {
      throw InputError(fmt::format(
          "{}: more than {} MiB, the limit of one benchmark file (an endless input, or not "
          "Google Benchmark JSON?)",
          file, kMaxBenchmarkFileBytes >> 20));
    }
  }
  json document;
  try {
    document = json::parse(text);
  } catch (const json::parse_error& error) {
    throw InputError(fmt::format(
        "{}: not a complete JSON document (truncated or not Google Benchmark output?): {}", file,
        error.what()));
  }
  if (!document.is_object() || !document.contains("context") || !document["context"].is_object() ||
      !document.contains("benchmarks") || !document["benchmarks"].is_array()) {
    throw InputError(fmt::format(
        "{}: not Google Benchmark JSON: an object with \"context\" and a \"benchmarks\" array "
        "is expected (write it with --benchmark_out=F --benchmark_out_format=json)",
        file));
  }
  for (const auto& [key, value] : document["context"].items()) {
    if (value.is_primitive() && !samples.context.count(key)) {
      samples.context[key] = context_value(value);
    }
  }
  std::size_t iteration_rows = 0;
  std::size_t index = 0;
  for (const json& row : document["benchmarks"]) {
    ++index;
    if (!row.is_object() || !row.contains("name") || !row["name"].is_string()) {
      throw InputError(fmt::format("{}: benchmarks[{}] has no \"name\"", file, index - 1));
    }
    const std::string name = row.contains("run_name") && row["run_name"].is_string()
                                 ? row["run_name"].get<std::string>()
                                 : row["name"].get<std::string>();
    if (row.contains("error_occurred") && row["error_occurred"].is_boolean() &&
        row["error_occurred"].get<bool>()) {
      throw InputError(fmt::format(
          "{}: benchmark '{}' reported an error ('{}'): a failed benchmark has no timing", file,
          name, row.contains("error_message") ? context_value(row["error_message"]) : ""));
    }
    const std::string run_type = row.contains("run_type") && row["run_type"].is_string()
                                     ? row["run_type"].get<std::string>()
                                     : "iteration";
    if (run_type == "aggregate") continue;
    if (run_type != "iteration") {
      throw InputError(
          fmt::format("{}: benchmark '{}' has run_type '{}' (valid: iteration, "
                      "aggregate)",
                      file, name, run_type));
    }
    if (!row.contains("real_time") || !row["real_time"].is_number() || !row.contains("time_unit") ||
        !row["time_unit"].is_string()) {
      throw InputError(
          fmt::format("{}: benchmark '{}' lacks a numeric real_time or its time_unit", file, name));
    }
    const double real_time = row["real_time"].get<double>();
    if (!std::isfinite(real_time) || real_time <= 0) {
      throw InputError(
          fmt::format("{}: benchmark '{}' has real_time {} (a positive number is "
                      "expected)",
                      file, name, real_time));
    }
    // Bounded so that medians, their ratio and the statistics stay finite (1e300 s overflowed
    // to inf ns, and the ratio to nan).
    const std::string unit = row["time_unit"].get<std::string>();
    const double time_ns = real_time * unit_in_ns(file, name, unit);
    if (!(time_ns >= kMinBenchmarkTimeNs && time_ns <= kMaxBenchmarkTimeNs)) {
      throw InputError(fmt::format(
          "{}: benchmark '{}' has real_time {:g} {} = {:g} ns, outside the range "
          "[{:g}, {:g}] ns (1e-9 ns to about 31 years) that perf-compare accepts",
          file, name, real_time, unit, time_ns, kMinBenchmarkTimeNs, kMaxBenchmarkTimeNs));
    }
    const auto [it, inserted] = owner.emplace(name, file);
    if (!inserted && it->second != file) {
      throw InputError(fmt::format("perf-compare: benchmark '{}' is in both '{}' and '{}'", name,
                                   it->second, file));
    }
    samples.real_time_ns[name].push_back(time_ns);
    ++iteration_rows;
  }
  if (iteration_rows == 0) {
    throw InputError(
        fmt::format("{}: no benchmark measurements (an empty \"benchmarks\" array, "
                    "or aggregates only: run without "
                    "--benchmark_report_aggregates_only)",
                    file));
  }
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// P(U ≥ u) under H0 from the Gaussian binomial coefficient [n+m choose n]_q, whose coefficient
// of q^k counts the arrangements with U = k: built as Π_i (1 − q^{m+i}) / (1 − q^i).
double exact_upper_tail(std::size_t n, std::size_t m, double u) {
  const std::size_t degree = n * m;
  std::vector<double> counts(degree + 1, 0.0);
  counts[0] = 1;
  for (std::size_t i = 1; i <= n; ++i) {
    const std::size_t shift = m + i;
    for (std::size_t k = degree; k >= shift && k <= degree; --k) counts[k] -= counts[k - shift];
    for (std::size_t k = i; k <= degree; ++k) counts[k] += counts[k - i];
  }
  double total = 0, tail = 0;
  for (std::size_t k = 0; k <= degree; ++k) {
    total += counts[k];
    if (static_cast<double>(k) >= u - 1e-9) tail += counts[k];
  }
  return std::min(1.0, tail / total);
}

}  // namespace

BenchmarkSamples load_benchmark_samples(const std::string& path) {
  BenchmarkSamples samples;
  std::map<std::string, std::string> owner;
  std::error_code error;
  if (fs::is_directory(path, error)) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(path)) {
      if (entry.path().extension() == ".json") files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    if (files.empty()) {
      throw InputError(
          fmt::format("perf-compare: folder '{}' has no *.json file (write them "
                      "with `make perf`)",
                      path));
    }
    for (const auto& file : files) load_file(file, samples, owner);
  } else {
    load_file(path, samples, owner);
  }
  return samples;
}

double mann_whitney_min_p(std::size_t n, std::size_t m) {
  // 1 / C(n + m, n), by a product that stays in range.
  double p = 1;
  for (std::size_t i = 1; i <= n; ++i) p *= static_cast<double>(i) / static_cast<double>(m + i);
  return p;
}

MannWhitney mann_whitney_greater(const std::vector<double>& faster,
                                 const std::vector<double>& slower) {
  MannWhitney result;
  const std::size_t n = faster.size(), m = slower.size();
  if (n == 0 || m == 0) return result;
  // U from the ranks of the pooled sorted sample: a run of t equal values shared by f faster and
  // s slower ones contributes, for each slower value, the faster values below the run plus ½f
  // for the ties, exactly the pair count #{slower > faster} + ½#{slower = faster}. O((n+m) log).
  std::vector<std::pair<double, bool>> pooled;  // (value, is_slower)
  pooled.reserve(n + m);
  for (double a : faster) pooled.emplace_back(a, false);
  for (double b : slower) pooled.emplace_back(b, true);
  std::sort(pooled.begin(), pooled.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  bool ties = false;  // a faster and a slower value equal
  double faster_below = 0;
  for (std::size_t i = 0; i < pooled.size();) {
    std::size_t j = i;
    double run_faster = 0, run_slower = 0;
    for (; j < pooled.size() && pooled[j].first == pooled[i].first; ++j) {
      (pooled[j].second ? run_slower : run_faster) += 1;
    }
    result.u += run_slower * (faster_below + 0.5 * run_faster);
    ties = ties || (run_faster > 0 && run_slower > 0);
    faster_below += run_faster;
    i = j;
  }
  if (!ties && n * m <= 10000) {
    // U counts pairs with slower > faster; by symmetry its null law is that of the q-binomial.
    result.p_value = exact_upper_tail(n, m, result.u);
    result.exact = true;
    return result;
  }
  double tie_sum = 0;
  for (std::size_t i = 0; i < pooled.size();) {
    std::size_t j = i;
    while (j < pooled.size() && pooled[j].first == pooled[i].first) ++j;
    const double t = static_cast<double>(j - i);
    tie_sum += t * t * t - t;
    i = j;
  }
  const double nn = static_cast<double>(n), mm = static_cast<double>(m), total = nn + mm;
  const double mean = nn * mm / 2;
  const double variance = nn * mm / 12 * ((total + 1) - tie_sum / (total * (total - 1)));
  if (variance <= 0) return result;  // every value tied: no evidence either way
  const double z = (result.u - mean - 0.5) / std::sqrt(variance);
  result.p_value = 0.5 * std::erfc(z / std::sqrt(2.0));
  return result;
}

std::vector<PerfComparison> compare_benchmarks(const BenchmarkSamples& base,
                                               const BenchmarkSamples& candidate,
                                               const PerfCompareOptions& options) {
  if (!(options.alpha > 0 && options.alpha < 1)) {
    throw InputError(fmt::format("perf-compare: --alpha {} is outside (0, 1)", options.alpha));
  }
  if (!(options.min_slowdown >= 0) || !std::isfinite(options.min_slowdown)) {
    throw InputError(fmt::format("perf-compare: --min-slowdown {} must be a finite number >= 0",
                                 options.min_slowdown));
  }
  std::vector<PerfComparison> rows;
  std::map<std::string, int> names;
  for (const auto& entry : base.real_time_ns) names[entry.first] |= 1;
  for (const auto& entry : candidate.real_time_ns) names[entry.first] |= 2;
  for (const auto& [name, where] : names) {
    PerfComparison row;
    row.name = name;
    if (where != 3) {
      row.verdict = where == 1 ? "only in base" : "only in new";
      const auto& samples =
          where == 1 ? base.real_time_ns.at(name) : candidate.real_time_ns.at(name);
      (where == 1 ? row.base_n : row.new_n) = samples.size();
      (where == 1 ? row.base_median_ns : row.new_median_ns) = median(samples);
      rows.push_back(row);
      continue;
    }
    const auto& before = base.real_time_ns.at(name);
    const auto& after = candidate.real_time_ns.at(name);
    row.base_n = before.size();
    row.new_n = after.size();
    if (mann_whitney_min_p(row.base_n, row.new_n) >= options.alpha) {
      std::size_t needed = 1;
      while (mann_whitney_min_p(needed, needed) >= options.alpha) ++needed;
      throw InputError(fmt::format(
          "perf-compare: benchmark '{}' has {} repetition(s) in base and {} in new; p < {} needs "
          "at least {} on each side (make perf PERF_REPS={}, or --benchmark_repetitions)",
          name, row.base_n, row.new_n, options.alpha, needed, std::max<std::size_t>(needed, 10)));
    }
    row.base_median_ns = median(before);
    row.new_median_ns = median(after);
    row.ratio = row.new_median_ns / row.base_median_ns;
    if (!std::isfinite(row.ratio)) {  // unreachable with the bounded times; kept as the guard
      throw InputError(fmt::format(
          "perf-compare: benchmark '{}': the ratio of the medians {:g} / {:g} ns is not finite",
          name, row.new_median_ns, row.base_median_ns));
    }
    row.p_slower = mann_whitney_greater(before, after).p_value;
    row.p_faster = mann_whitney_greater(after, before).p_value;
    if (row.p_slower < options.alpha && row.ratio > 1 + options.min_slowdown) {
      row.verdict = "slower";
    } else if (row.p_faster < options.alpha && row.ratio < 1 / (1 + options.min_slowdown)) {
      row.verdict = "faster";
    } else {
      row.verdict = "same";
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace geomint
