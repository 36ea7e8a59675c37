// The timing pass's statistics (harness/run.hpp TimingStats: minimum, median, interquartile
// range by Hyndman–Fan type 7) on injected samples with exact answers, and its budget: a pass
// that cannot fit its repeats still yields a time, with the count and a note saying why; the
// interrupt flag that ends runs early.
#include <gtest/gtest.h>

#include <stdexcept>
#include <thread>
#include <vector>

#include "harness/record.hpp"
#include "harness/run.hpp"
#include "harness/run_spec.hpp"

namespace geomint {
namespace timing_test {
namespace {

// Samples at a non-unit scale (0.25 s steps): every expected value below is exact in binary.
TEST(TimingStats, OddCountMedianIsTheMiddleAndQuartilesFallOnSamples) {
  // Sorted: 0.25 0.5 0.75 1 1.25; Q1 at position 1 (0.5), Q3 at position 3 (1).
  const TimingStats stats = timing_stats({1.25, 0.25, 1.0, 0.5, 0.75});
  EXPECT_EQ(stats.min, 0.25);
  EXPECT_EQ(stats.median, 0.75);
  EXPECT_EQ(stats.iqr, 0.5);
  EXPECT_EQ(stats.count, 5);
}

TEST(TimingStats, EvenCountInterpolatesBetweenOrderStatistics) {
  // Sorted: 0.5 1 1.5 2; median = (1 + 1.5)/2; Q1 at position 0.75 = 0.5 + 0.75·0.5 = 0.875,
  // Q3 at position 2.25 = 1.5 + 0.25·0.5 = 1.625.
  const TimingStats stats = timing_stats({2.0, 0.5, 1.5, 1.0});
  EXPECT_EQ(stats.min, 0.5);
  EXPECT_EQ(stats.median, 1.25);
  EXPECT_EQ(stats.iqr, 0.75);
  EXPECT_EQ(stats.count, 4);
}

TEST(TimingStats, OneSlowOutlierMovesNeitherMedianNorSpread) {
  // A repeat disturbed by another process (100x) is what the median and the IQR are for.
  const TimingStats stats = timing_stats({3.0, 3.0, 300.0, 3.0, 3.0, 3.0});
  EXPECT_EQ(stats.min, 3.0);
  EXPECT_EQ(stats.median, 3.0);
  EXPECT_EQ(stats.iqr, 0.0);
}

TEST(TimingStats, OneSampleHasNoSpreadAndNoSampleIsRefused) {
  const TimingStats stats = timing_stats({7e-4});
  EXPECT_EQ(stats.min, 7e-4);
  EXPECT_EQ(stats.median, 7e-4);
  EXPECT_EQ(stats.iqr, 0.0);
  EXPECT_EQ(stats.count, 1);
  EXPECT_THROW((void)timing_stats({}), std::invalid_argument);
}

// A cheap run (200 Störmer–Verlet steps): repeats and budget, never its speed.
TEST(TimingPass, RecordsEveryRepeatOrSaysTheBudgetCutThem) {
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 2.0;
  const TimingOutcome full = time_run("harmonic:omega=3,mass=2", "stormer_verlet", config, 5);
  ASSERT_TRUE(full.status.ok) << full.failure_message();
  EXPECT_EQ(full.stats.count, 5);
  EXPECT_TRUE(full.budget_note.empty()) << full.budget_note;
  EXPECT_LE(full.stats.min, full.stats.median);
  EXPECT_GE(full.stats.iqr, 0.0);
  EXPECT_EQ(full.seconds, full.stats.median);

  // No room for any repeat after the warm-up: its time is the one sample, and the row says so.
  config.timing_budget_s = 1e-12;
  const TimingOutcome cut = time_run("harmonic:omega=3,mass=2", "stormer_verlet", config, 5);
  ASSERT_TRUE(cut.status.ok) << cut.failure_message();
  EXPECT_EQ(cut.stats.count, 1);
  EXPECT_GT(cut.stats.median, 0.0);
  EXPECT_NE(cut.budget_note.find("0 of 5 repeats"), std::string::npos) << cut.budget_note;
  RunRecord record;
  record_timing(cut, record);
  ASSERT_TRUE(record.wall_s_repeats.has_value());
  EXPECT_EQ(*record.wall_s_repeats, 1);
  ASSERT_TRUE(record.wall_s.has_value());
  EXPECT_EQ(*record.wall_s, cut.stats.median);
  EXPECT_EQ(record.message, cut.budget_note);
}

// The interrupt flag (the Python package's Ctrl-C): a metric pass ends at its first step point
// with status `interrupted`, fixed-step and adaptive alike, a timing pass before any run; once
// cleared, the same run goes through.
// The recursive passes per step of a joint chain's steps: RK4 on the articulated-body recursions
// takes 4 stages of a mass solve (2 passes) and dT/dtheta (2 passes) at every n, and the count
// is of this run alone while another thread steps the same problem. Problems without tree
// recursions have no such column.
TEST(TimingPass, CountsTheRecursivePassesPerStepOfTreeProblems) {
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 0.2;
  for (const char* spec : {"articulated_chain:n=8", "rod_chain:coordinates=joint,n=64"}) {
    const RunSpec run = RunSpec::parse(spec, "rk4", config);
    std::thread other([&] { (void)time_run(run, 3); });
    const TimingOutcome timing = time_run(run, 1);
    other.join();
    ASSERT_TRUE(timing.recursive_passes_per_step.has_value()) << spec;
    EXPECT_EQ(*timing.recursive_passes_per_step, 16.0) << spec;
    RunRecord record;
    record_timing(timing, record);
    EXPECT_EQ(to_row(record).at("recursive_passes_per_step"), "16") << spec;
  }
  EXPECT_FALSE(time_run("harmonic", "rk4", config, 1).recursive_passes_per_step.has_value());
}

TEST(Interrupt, EndsRunsAtTheNextStepPointUntilCleared) {
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 2.0;
  config.timing_repeats = 0;
  request_interrupt();
  for (const char* method : {"stormer_verlet", "cvode_bdf"}) {
    const RunResult run = run_one("harmonic", method, config);
    EXPECT_FALSE(run.ok) << method;
    EXPECT_EQ(run.record.status, kInterruptedStatus) << method;
    EXPECT_EQ(run.record.steps, 0L) << method;
  }
  const TimingOutcome timing = time_run("harmonic", "stormer_verlet", config, 3);
  EXPECT_EQ(timing.status.reason, kInterruptedStatus);
  clear_interrupt();
  EXPECT_FALSE(interrupt_requested());
  const RunResult run = run_one("harmonic", "stormer_verlet", config);
  EXPECT_TRUE(run.ok) << run.record.message.value_or("");
  EXPECT_EQ(run.record.steps, 200L);
}

}  // namespace
}  // namespace timing_test
}  // namespace geomint
