// The chunk pool (problems/parallel.cpp: polling, sleeping, tickets) and the blocked CG loop's
// block sums (integrators/conjugate_gradient.hpp) under ThreadSanitizer: back-to-back loops,
// loops after the pool has gone to sleep, a worker chunk that outlasts the caller's poll, loops
// with more chunks than cores, loops from four threads at once and a loop inside a chunk. Built
// with -fsanitize=thread from those sources alone (tests/CMakeLists.txt); exits 1 on a wrong
// coverage or sum, and TSan exits 66 on a data race.
#include <Eigen/Core>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

#include "integrators/conjugate_gradient.hpp"
#include "problems/parallel.hpp"

namespace {

using geomint::for_each_chunk;

int failures = 0;

void covered_once(int chunks, std::size_t items, bool slow_worker) {
  std::vector<std::atomic<int>> hits(items);
  for_each_chunk(chunks, items, [&](int chunk, std::size_t begin, std::size_t end) {
    if (slow_worker && chunk == 1) std::this_thread::sleep_for(5 * geomint::kPoolPollBeforeSleep);
    for (std::size_t i = begin; i < end; ++i) ++hits[i];
  });
  for (const std::atomic<int>& hit : hits) {
    if (hit != 1) {
      std::fprintf(stderr, "pool_tsan: a loop of %d chunks missed or repeated an item\n", chunks);
      ++failures;
      return;
    }
  }
}

}  // namespace

int main() {
  geomint::set_thread_count(4);
  for (int loop = 0; loop < 2000; ++loop) covered_once(2, 64, false);
  for (int loop = 0; loop < 200; ++loop) covered_once(3 + loop % 2, 100, false);
  for (int loop = 0; loop < 10; ++loop) {
    std::this_thread::sleep_for(10 * geomint::kPoolPollBeforeSleep);
    covered_once(2, 64, loop % 2 == 1);
  }
  std::vector<std::thread> callers;
  for (int caller = 0; caller < 4; ++caller) {
    callers.emplace_back([caller] {
      for (int loop = 0; loop < 100; ++loop) covered_once(2 + (caller + loop) % 3, 500, false);
    });
  }
  for (std::thread& caller : callers) caller.join();
  for_each_chunk(2, 2, [](int, std::size_t, std::size_t) { covered_once(3, 300, false); });

  // The block sums of the blocked CG loop: Σ i over a vector that is also updated, at 1–4 threads.
  const Eigen::Index size = 5 * geomint::kCgBlock + 17;
  for (int threads = 1; threads <= 4; ++threads) {
    geomint::set_thread_count(threads);
    Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(size, 0.0, static_cast<double>(size - 1));
    double totals[2];
    geomint::sum_over_blocks(
        size,
        [&](Eigen::Index first, Eigen::Index count, double* sums) {
          sums[0] = v.segment(first, count).sum();
          v.segment(first, count) *= 2.0;
          sums[1] = v.segment(first, count).sum();
        },
        totals);
    const double expected = 0.5 * static_cast<double>(size) * static_cast<double>(size - 1);
    if (totals[0] != expected || totals[1] != 2 * expected) {
      std::fprintf(stderr, "pool_tsan: block sums %g, %g at %d threads, expected %g, %g\n",
                   totals[0], totals[1], threads, expected, 2 * expected);
      ++failures;
    }
  }
  if (failures == 0) std::printf("pool_tsan: ok\n");
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
