// The speed-regression test of `geomint perf-compare` (harness/perf_compare.hpp): the exact
// Mann–Whitney law against brute-force enumeration, its normal approximation, the verdicts and
// the JSON reader's refusals.
#include "harness/perf_compare.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <string>

#include "problems/spec.hpp"

namespace geomint {
namespace perf_compare_test {
namespace {

namespace fs = std::filesystem;

// P(U >= u) by listing every way to pick which n of the n + m ranks are the "faster" sample.
double brute_force_upper_tail(int n, int m, double u) {
  std::vector<int> pick(n + m, 0);
  std::fill(pick.begin(), pick.begin() + n, 1);  // 1 = faster sample
  std::sort(pick.begin(), pick.end());
  long total = 0, tail = 0;
  do {
    double count = 0;  // pairs (faster i, slower j) with rank_j > rank_i
    for (int i = 0; i < n + m; ++i) {
      if (pick[i] != 1) continue;
      for (int j = i + 1; j < n + m; ++j) count += pick[j] == 0;
    }
    ++total;
    tail += count >= u;
  } while (std::next_permutation(pick.begin(), pick.end()));
  return static_cast<double>(tail) / static_cast<double>(total);
}

TEST(MannWhitney, ExactTailMatchesEnumerationForEverySmallSampleAndStatistic) {
  for (int n = 1; n <= 6; ++n) {
    for (int m = 1; m <= 6; ++m) {
      for (int u = 0; u <= n * m; ++u) {
        // Samples realising exactly u: slower values interleave the faster ones.
        std::vector<double> faster(n), slower(m);
        std::iota(faster.begin(), faster.end(), 0.0);
        for (int j = 0; j < m; ++j) slower[j] = -0.5;
        // Raise slower values one rank at a time until the count reaches u.
        int remaining = u;
        for (int j = 0; j < m && remaining > 0; ++j) {
          const int step = std::min(remaining, n);
          slower[j] = step - 0.5;
          remaining -= step;
        }
        const MannWhitney result = mann_whitney_greater(faster, slower);
        ASSERT_DOUBLE_EQ(result.u, u) << n << "x" << m;
        EXPECT_TRUE(result.exact);
        EXPECT_NEAR(result.p_value, brute_force_upper_tail(n, m, u), 1e-12)
            << "n=" << n << " m=" << m << " u=" << u;
      }
    }
  }
}

TEST(MannWhitney, SmallestPIsOneOverTheBinomial) {
  EXPECT_DOUBLE_EQ(mann_whitney_min_p(5, 5), 1.0 / 252);
  EXPECT_DOUBLE_EQ(mann_whitney_min_p(3, 7), 1.0 / 120);
  const std::vector<double> faster = {1, 2, 3, 4, 5}, slower = {6, 7, 8, 9, 10};
  EXPECT_DOUBLE_EQ(mann_whitney_greater(faster, slower).p_value, 1.0 / 252);
  EXPECT_DOUBLE_EQ(mann_whitney_greater(slower, faster).p_value, 1.0);
}

TEST(MannWhitney, NormalApproximationWithTiesIsCloseToTheExactLaw) {
  // 40 + 40 samples, one tie pair: the approximation with continuity correction is within 1e-3 of
  // the exact law of the untied neighbour (identical ranks but for the tie).
  std::vector<double> faster, slower, slower_untied;
  for (int i = 0; i < 40; ++i) {
    faster.push_back(2.0 * i);
    slower.push_back(2.0 * i + 7.0);
    slower_untied.push_back(2.0 * i + 7.0);
  }
  slower[0] = faster[3];  // a tie
  slower_untied[0] = faster[3] + 0.5;
  const MannWhitney approximate = mann_whitney_greater(faster, slower);
  const MannWhitney exact = mann_whitney_greater(faster, slower_untied);
  EXPECT_FALSE(approximate.exact);
  EXPECT_TRUE(exact.exact);
  EXPECT_GT(approximate.p_value, 0.0);
  EXPECT_NEAR(approximate.p_value, exact.p_value, 1e-3);
  // Everything tied: no evidence.
  EXPECT_DOUBLE_EQ(mann_whitney_greater({1, 1, 1}, {1, 1, 1}).p_value, 1.0);
}

// U by its definition, #{(i, j): slower_j > faster_i} + ½ #{slower_j = faster_i}, over every
// pair: the O(n·m) count mann_whitney_greater used before it ranked the pooled sample.
double pairwise_u(const std::vector<double>& faster, const std::vector<double>& slower) {
  double u = 0;
  for (double a : faster) {
    for (double b : slower) u += b > a ? 1.0 : b == a ? 0.5 : 0.0;
  }
  return u;
}

// The ranked U equals the pair count, bit for bit, on random samples drawn from a few values (so
// ties within and across the samples are frequent), of unequal sizes, including all-tied ones;
// and with the same U the p-value is the same function of it.
TEST(MannWhitney, RankedStatisticEqualsThePairCountWithTies) {
  std::mt19937 random(20261206);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 1 + static_cast<int>(random() % 40), m = 1 + static_cast<int>(random() % 40);
    const int levels = 1 + static_cast<int>(random() % 12);
    std::vector<double> faster(n), slower(m);
    for (double& x : faster) x = 0.25 * static_cast<double>(random() % levels);
    for (double& x : slower) x = 0.25 * static_cast<double>(random() % levels) + 0.25 * (trial % 3);
    SCOPED_TRACE(testing::Message()
                 << "trial " << trial << ": " << n << "x" << m << ", " << levels << " levels");
    EXPECT_EQ(mann_whitney_greater(faster, slower).u, pairwise_u(faster, slower));
    EXPECT_EQ(mann_whitney_greater(slower, faster).u, pairwise_u(slower, faster));
  }
}

// 60 000 repetitions per side (ties included): the pair count took 30 s, the ranks take well
// under a second. Logged, not asserted (the machine's load is not the test's business).
TEST(MannWhitney, SixtyThousandPerSideLogsItsTime) {
  std::mt19937 random(7);
  std::vector<double> faster(60000), slower(60000);
  for (double& x : faster) x = 1000 + static_cast<double>(random() % 5000);
  for (double& x : slower) x = 1500 + static_cast<double>(random() % 5000);
  const auto start = std::chrono::steady_clock::now();
  const MannWhitney result = mann_whitney_greater(faster, slower);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RecordProperty("mann_whitney_60000_seconds", std::to_string(seconds));
  std::printf("mann_whitney_greater, 60000 x 60000: %.3f s (U = %.1f, p = %.3g)\n", seconds,
              result.u, result.p_value);
  EXPECT_FALSE(result.exact);
  EXPECT_GT(result.u, 0.5 * 60000.0 * 60000.0);  // the slower side is shifted up
}

BenchmarkSamples samples_of(const std::vector<double>& times_ns) {
  BenchmarkSamples samples;
  samples.real_time_ns["BM_Step"] = times_ns;
  return samples;
}

// Ten noisy repetitions around `centre` (a fixed pattern of ±3% times `spread`, so the test is
// deterministic).
std::vector<double> noisy(double centre, double spread = 1) {
  const double pattern[] = {0.01, -0.02, 0.03, 0.0, -0.01, 0.02, -0.03, 0.015, -0.015, 0.005};
  std::vector<double> times;
  for (double offset : pattern) times.push_back(centre * (1 + spread * offset));
  return times;
}

TEST(PerfCompare, SlowdownSpeedupAndNoise) {
  const PerfCompareOptions options;  // alpha 0.01, 5 %
  const auto verdict = [&](double base, double now) {
    return compare_benchmarks(samples_of(noisy(base)), samples_of(noisy(now)), options)
        .at(0)
        .verdict;
  };
  EXPECT_EQ(verdict(100, 130), "slower");  // a seeded 30 % slowdown
  EXPECT_EQ(verdict(130, 100), "faster");
  EXPECT_EQ(verdict(100, 100), "same");
  // Within the noise: a 2 % shift under ±3 % noise is not significant at p < 0.01.
  EXPECT_EQ(verdict(100, 102), "same");
  // Significant (±0.3 % noise, fully separated) but below the relative threshold: not a slowdown
  // at 5 %, a slowdown at 1 %.
  const auto quiet = [](double centre) { return samples_of(noisy(centre, 0.1)); };
  EXPECT_EQ(compare_benchmarks(quiet(100), quiet(102), options).at(0).verdict, "same");
  PerfCompareOptions strict = options;
  strict.min_slowdown = 0.01;
  EXPECT_EQ(compare_benchmarks(quiet(100), quiet(102), strict).at(0).verdict, "slower");
}

TEST(PerfCompare, BenchmarksOnOneSideAreListedAndTooFewRepetitionsRefused) {
  BenchmarkSamples base = samples_of(noisy(100));
  base.real_time_ns["BM_Gone"] = noisy(5);
  BenchmarkSamples candidate = samples_of(noisy(100));
  candidate.real_time_ns["BM_New"] = noisy(7);
  const auto rows = compare_benchmarks(base, candidate, PerfCompareOptions{});
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].name, "BM_Gone");
  EXPECT_EQ(rows[0].verdict, "only in base");
  EXPECT_EQ(rows[1].verdict, "only in new");
  EXPECT_EQ(rows[2].verdict, "same");
  try {
    compare_benchmarks(samples_of({1, 2, 3, 4}), samples_of({1, 2, 3, 4}), PerfCompareOptions{});
    FAIL() << "four repetitions cannot reach p < 0.01";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("at least 5"), std::string::npos) << error.what();
  }
}

class BenchmarkJson : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("geomint_perf_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  fs::path dir_;
};

const char* const kDocument = R"({
  "context": {"commit": "0123abc", "compiler": "GNU 12.2.0", "num_cpus": 2, "threads": "1"},
  "benchmarks": [
    {"name": "BM_Step", "run_name": "BM_Step", "run_type": "iteration", "repetitions": 2,
     "repetition_index": 0, "iterations": 10, "real_time": 1.5, "cpu_time": 1.5, "time_unit": "us"},
    {"name": "BM_Step", "run_name": "BM_Step", "run_type": "iteration", "repetitions": 2,
     "repetition_index": 1, "iterations": 10, "real_time": 2.5, "cpu_time": 2.5, "time_unit": "ms"},
    {"name": "BM_Step_median", "run_name": "BM_Step", "run_type": "aggregate",
     "aggregate_name": "median", "iterations": 2, "real_time": 2.0, "cpu_time": 2.0, "time_unit": "us"}
  ]
})";

TEST_F(BenchmarkJson, ReadsRepetitionsInNanosecondsAndSkipsAggregates) {
  const BenchmarkSamples samples = load_benchmark_samples(write("a.json", kDocument));
  ASSERT_EQ(samples.real_time_ns.size(), 1u);
  const std::vector<double> expected = {1.5e3, 2.5e6};
  EXPECT_EQ(samples.real_time_ns.at("BM_Step"), expected);
  EXPECT_EQ(samples.context.at("commit"), "0123abc");
  EXPECT_EQ(samples.context.at("num_cpus"), "2");
}

TEST_F(BenchmarkJson, RefusesTruncatedMalformedAndDuplicatedInput) {
  const std::string text = kDocument;
  const auto refused = [&](const std::string& path, const std::string& word) {
    try {
      load_benchmark_samples(path);
      ADD_FAILURE() << path << " was accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(word), std::string::npos) << error.what();
    }
  };
  // Every proper prefix of the document is refused, never read in part.
  for (std::size_t cut = 1; cut < text.size(); cut += 7) {
    refused(write("cut.json", text.substr(0, cut)), "cut.json");
  }
  std::string bad_unit = text;
  bad_unit.replace(bad_unit.find("\"ms\""), 4, "\"min\"");
  refused(write("unit.json", bad_unit), "time_unit");
  std::string negative = text;
  negative.insert(negative.find("1.5, \"cpu"), "-");
  refused(write("negative.json", negative), "real_time");
  refused(write("empty.json", R"({"context": {}, "benchmarks": []})"), "no benchmark");
  // Times whose nanoseconds overflow (1e300 s = inf ns: the median was inf, the ratio nan) or
  // leave [1e-9 ns, 1e18 ns] are input errors naming the benchmark.
  for (const char* time : {"1e300, \"cpu_time\": 1, \"time_unit\": \"s\"",
                           "1e10, \"cpu_time\": 1, \"time_unit\": \"s\"",
                           "1e-320, \"cpu_time\": 1, \"time_unit\": \"ns\""}) {
    std::string huge = text;
    huge.replace(huge.find("1.5, \"cpu_time\": 1.5, \"time_unit\": \"us\""),
                 std::string("1.5, \"cpu_time\": 1.5, \"time_unit\": \"us\"").size(), time);
    refused(write("huge.json", huge), "benchmark 'BM_Step' has real_time");
    refused(write("huge.json", huge), "outside the range");
  }
  // An endless input stops at the size limit instead of at the end of memory.
  refused("/dev/zero", "64 MiB");
  // The same benchmark in two files of one folder.
  fs::create_directories(dir_ / "folder");
  write("folder/one.json", kDocument);
  write("folder/two.json", kDocument);
  refused((dir_ / "folder").string(), "in both");
}

}  // namespace
}  // namespace perf_compare_test
}  // namespace geomint
