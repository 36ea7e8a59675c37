// `geomint perf-compare BASE NEW`: two sets of Google Benchmark measurements (JSON files or
// folders written by `make perf`) compared benchmark by benchmark; exit 1 on a slowdown
// (harness/perf_compare.hpp, docs/PERF.md).
#include "harness/perf_compare.hpp"

#include <fmt/format.h>

#include <memory>

#include "harness/cli/verbs.hpp"

namespace geomint::cli {
namespace {

struct PerfCompareCliOptions {
  std::string base_path, new_path;
  PerfCompareOptions compare;
};

// A CSV field per RFC 4180: quoted when it holds a comma, a quote or a line break (templated
// benchmarks such as `BM_X<a, b>` do), with quotes doubled inside.
std::string csv_field(const std::string& value) {
  if (value.find_first_of(",\"\r\n") == std::string::npos) return value;
  std::string out = "\"";
  for (char c : value) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

// A context value on one comment line: line breaks and other control characters as spaces.
std::string one_line(std::string value) {
  for (char& c : value) {
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  }
  return value;
}

std::string provenance_line(const char* side, const BenchmarkSamples& samples) {
  const auto value = [&](const char* key) {
    const auto it = samples.context.find(key);
    return it == samples.context.end() ? std::string("?") : one_line(it->second);
  };
  return fmt::format("# {}: commit {}, compiler {}, cpu {}, threads {}, host {}, {}", side,
                     value("commit"), value("compiler"), value("cpu_model"), value("threads"),
                     value("host_name"), value("date"));
}

int run_perf_compare(const PerfCompareCliOptions& cli, const Context& context) {
  const BenchmarkSamples base = load_benchmark_samples(cli.base_path);
  const BenchmarkSamples candidate = load_benchmark_samples(cli.new_path);
  const std::vector<PerfComparison> rows = compare_benchmarks(base, candidate, cli.compare);
  fmt::print("{}\n{}\n", provenance_line("base", base), provenance_line("new", candidate));
  fmt::print(
      "# one-sided Mann-Whitney U per benchmark: slower when p < {} and the median grew by "
      "more than {:.0f}%\n",
      cli.compare.alpha, 100 * cli.compare.min_slowdown);
  fmt::print(
      "benchmark,base_n,new_n,base_median_ns,new_median_ns,ratio,p_slower,p_faster,"
      "verdict\n");
  int slower = 0, faster = 0;
  for (const PerfComparison& row : rows) {
    const bool both = row.base_n > 0 && row.new_n > 0;
    fmt::print("{},{},{},{:.6g},{:.6g},{},{},{},{}\n", csv_field(row.name), row.base_n, row.new_n,
               row.base_median_ns, row.new_median_ns, both ? fmt::format("{:.4f}", row.ratio) : "",
               both ? fmt::format("{:.3g}", row.p_slower) : "",
               both ? fmt::format("{:.3g}", row.p_faster) : "", row.verdict);
    slower += row.verdict == "slower";
    faster += row.verdict == "faster";
  }
  inform(context, fmt::format("{}: perf-compare: {} benchmark(s), {} slower, {} faster",
                              context.program, rows.size(), slower, faster));
  return slower > 0 ? kExitFailed : kExitOk;
}

}  // namespace

Verb add_perf_compare(CLI::App& app) {
  auto options = std::make_shared<PerfCompareCliOptions>();
  auto* command = app.add_subcommand(
      "perf-compare",
      "Compare two Google Benchmark JSON files (or folders of them, as `make perf` writes) with a "
      "one-sided Mann-Whitney U test per benchmark; exit 1 when one is significantly slower");
  command->add_option("base", options->base_path, "the reference measurements (JSON or folder)")
      ->required();
  command->add_option("new", options->new_path, "the measurements under test (JSON or folder)")
      ->required();
  command
      ->add_option("--alpha", options->compare.alpha,
                   "significance level of each one-sided test, in (0, 1)")
      ->capture_default_str();
  command
      ->add_option("--min-slowdown", options->compare.min_slowdown,
                   "relative growth of the median that counts as a slowdown (0.05 = 5%), >= 0")
      ->capture_default_str();
  return {"perf-compare", command,
          [options](const Context& context) { return run_perf_compare(*options, context); }};
}

}  // namespace geomint::cli
