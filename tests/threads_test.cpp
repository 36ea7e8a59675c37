// Threaded element loops (issue 30 item 2, problems/parallel.hpp, docs/PERF.md "Threads"): the
// elastic bar's energy, gradient, Hessian and damping, and the products H x (scalar and 3×3-block),
// give the same bits at 1, 2, 3 and 4 threads, and implicit steps repeated at 2 threads and at 1
// give the same bytes (also with modified Newton); the chunking covers every item once and passes
// exceptions on, also for concurrent and nested loops; the pool's workers persist; the setting
// refuses what it cannot use.
#include <gtest/gtest.h>
#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/parallel.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace threads_test {
namespace {

// 24·8·8 cells = 9216 tets: 4 chunks at 4 threads (2048 elements per chunk at least), so every
// thread count below is really used. Non-unit sizes and moduli; damping for force/C.
const char* const kBar =
    "elastic_bar:nx=24,ny=8,nz=8,length=2.5,width=0.4,height=0.3,young=3e6,density=700,"
    "damping=0.02";

bool same_bits(const Vec& a, const Vec& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}
bool same_bits(const SparseMatrix& a, const SparseMatrix& b) {
  const auto bytes = [](const SparseMatrix& m) {
    return sizeof(double) * static_cast<std::size_t>(m.nonZeros());
  };
  return a.nonZeros() == b.nonZeros() && std::memcmp(a.valuePtr(), b.valuePtr(), bytes(a)) == 0 &&
         std::memcmp(a.innerIndexPtr(), b.innerIndexPtr(), bytes(a) / 2) == 0;
}

struct Evaluations {
  double energy = 0;
  Vec gradient, force;
  SparseMatrix hessian, damping_jacobian;
};

Evaluations evaluate(const Problem& bar, const Vec& q, const Vec& v) {
  Evaluations out;
  out.energy = bar.potential(q);
  bar.gradient(q, out.gradient);
  bar.hessian(q, out.hessian);
  force_of(bar).force(q, v, 0.0, out.force);
  force_of(bar).force_jacobian_v(q, v, 0.0, out.damping_jacobian);
  return out;
}

TEST(ElasticBarThreads, EvaluationsAreBitIdenticalAtAnyThreadCount) {
  test::ThreadCountGuard guard;
  const auto bar = make_problem(kBar);
  ASSERT_EQ(bar->dof(), 3 * 24 * 9 * 9);  // the face x = 0 is clamped
  // A deformed state of 1e-2 relative size, and a velocity: every element matrix differs.
  const State start = bar->initial_state();
  const Vec q = start.q + 1e-2 * test::random_vector(bar->dof(), 7);
  const Vec v = 0.3 * test::random_vector(bar->dof(), 8);
  set_thread_count(1);
  ASSERT_EQ(chunk_count(9216, 2048), 1);
  const Evaluations serial = evaluate(*bar, q, v);
  ASSERT_TRUE(serial.gradient.allFinite());
  for (int threads : {2, 2, 3, 4}) {
    set_thread_count(threads);
    ASSERT_EQ(chunk_count(9216, 2048), threads);
    const Evaluations threaded = evaluate(*bar, q, v);
    EXPECT_EQ(std::memcmp(&threaded.energy, &serial.energy, sizeof(double)), 0)
        << threads << " threads: energy " << threaded.energy - serial.energy << " off";
    EXPECT_TRUE(same_bits(threaded.gradient, serial.gradient))
        << threads << " threads: gradient off by "
        << (threaded.gradient - serial.gradient).lpNorm<Eigen::Infinity>();
    EXPECT_TRUE(same_bits(threaded.force, serial.force)) << threads << " threads: damping force";
    EXPECT_TRUE(same_bits(threaded.hessian, serial.hessian))
        << threads << " threads: Hessian off by "
        << SparseMatrix(threaded.hessian - serial.hessian).coeffs().cwiseAbs().maxCoeff();
    EXPECT_TRUE(same_bits(threaded.damping_jacobian, serial.damping_jacobian))
        << threads << " threads: damping Jacobian";
    // The threaded H x against Eigen's serial product (~2.3·10⁵ non-zeros: 3 chunks at 3 and
    // 4 threads).
    // NaN first: a row the product skipped stays visible.
    Vec product = Vec::Constant(bar->dof(), std::numeric_limits<double>::quiet_NaN());
    symmetric_product(serial.hessian, v, product);
    const Vec reference = serial.hessian * v;
    EXPECT_TRUE(same_bits(product, reference))
        << threads << " threads: H x off by " << (product - reference).lpNorm<Eigen::Infinity>();
    // The 3×3-block copy CG multiplies with (three coordinates per node): the same bits, also for
    // a matrix of size 1e-150 or 1e+150.
    for (double scale : {1.0, 1e-150, 1e150}) {
      const SparseMatrix scaled = scale * serial.hessian;
      SymmetricBlockMatrix blocks;
      ASSERT_TRUE(to_symmetric_blocks(scaled, blocks)) << threads;
      Vec block_product = Vec::Constant(bar->dof(), std::numeric_limits<double>::quiet_NaN());
      symmetric_product(blocks, v, block_product);
      const Vec scaled_reference = scaled * v;
      EXPECT_TRUE(same_bits(block_product, scaled_reference))
          << threads << " threads, scale " << scale << ": block H x off by "
          << (block_product - scaled_reference).lpNorm<Eigen::Infinity>();
    }
  }
}

// Patterns that are not made of whole aligned 3×3 blocks stay with the scalar product.
TEST(ParallelChunks, BlockCopyRefusesPatternsNotMadeOf3x3Blocks) {
  const auto matrix = [](int n, const std::vector<std::pair<int, int>>& entries) {
    std::vector<Eigen::Triplet<double>> triplets;
    for (const auto& [row, column] : entries) triplets.emplace_back(row, column, 1.0);
    SparseMatrix A(n, n);
    A.setFromTriplets(triplets.begin(), triplets.end());
    return A;
  };
  std::vector<std::pair<int, int>> full;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) full.emplace_back(i, j);
  }
  SymmetricBlockMatrix blocks;
  EXPECT_TRUE(to_symmetric_blocks(matrix(6, full), blocks));
  EXPECT_EQ(blocks.values.size(), 36u);
  std::vector<std::pair<int, int>> missing = full;
  missing.erase(missing.begin() + 7);  // (1, 1): one entry of the first block left out
  EXPECT_FALSE(to_symmetric_blocks(matrix(6, missing), blocks));
  EXPECT_TRUE(blocks.values.empty());
  std::vector<std::pair<int, int>> diagonal;  // 1×1 "blocks" on the diagonal only
  for (int i = 0; i < 6; ++i) diagonal.emplace_back(i, i);
  EXPECT_FALSE(to_symmetric_blocks(matrix(6, diagonal), blocks));
  // Shifted by one row: every column holds three entries, but not an aligned block.
  std::vector<std::pair<int, int>> shifted;
  for (int j = 0; j < 6; ++j) {
    for (int i = 1; i < 4; ++i) shifted.emplace_back(i, j);
  }
  EXPECT_FALSE(to_symmetric_blocks(matrix(6, shifted), blocks));
  EXPECT_FALSE(to_symmetric_blocks(matrix(5, {{0, 0}}), blocks));  // not a multiple of 3
}

// One step of the HP integrator (Newton with CG on the threaded Hessian and gradient) from a
// twisted bar: twice at 2 threads and once at 1, the same bytes.
TEST(ElasticBarThreads, ImplicitStepsAreBitIdenticalAtOneAndTwoThreads) {
  test::ThreadCountGuard guard;
  // 12·8·8 cells = 4608 tets: 2 chunks at 2 threads.
  const auto bar = make_problem(
      "elastic_bar:nx=12,ny=8,nz=8,length=1.5,width=0.4,height=0.3,young=3e6,density=700,"
      "damping=0.02,init=twist,twist=0.2");
  // Also the minimiser with modified Newton (the Newton matrix kept across iterations and steps),
  // over three steps so that later steps start on a held matrix.
  for (const auto& [spec, steps] : std::vector<std::pair<std::string, int>>{
           {"hp:alpha=0.5,solver=newton,linear_solver=cg", 1},
           {"hp:alpha=0.5,linear_solver=cg,modified_newton=true", 3}}) {
    const auto run = [&bar, &spec = spec, steps = steps](int threads) {
      set_thread_count(threads);
      const auto method = make_integrator(spec);
      State state = bar->initial_state();
      const double h = 2e-4;
      method->reset(*bar, state, h);
      for (int k = 0; k < steps; ++k) {
        EXPECT_TRUE(method->step(*bar, state, h).ok) << spec << " step " << k << " at " << threads;
      }
      return state;
    };
    const State first = run(2), second = run(2), serial = run(1);
    EXPECT_GT((first.q - bar->initial_state().q).norm(), 0) << spec;
    EXPECT_TRUE(same_bits(first.q, second.q) && same_bits(first.p, second.p)) << spec;
    EXPECT_TRUE(same_bits(first.q, serial.q) && same_bits(first.p, serial.p))
        << spec << ": 1 vs 2 threads: q off by " << (first.q - serial.q).lpNorm<Eigen::Infinity>();
  }
}

TEST(ParallelChunks, CoverEveryItemOnceInContiguousRanges) {
  for (int chunks : {1, 2, 3, 7}) {
    for (std::size_t items : {0, 1, 5, 1000}) {
      std::vector<std::atomic<int>> hits(items);
      std::vector<std::size_t> begins(static_cast<std::size_t>(chunks), items + 1);
      for_each_chunk(chunks, items, [&](int chunk, std::size_t begin, std::size_t end) {
        begins[static_cast<std::size_t>(chunk)] = begin;
        EXPECT_EQ(end, chunk_begin(items, chunk + 1, chunks));
        for (std::size_t i = begin; i < end; ++i) ++hits[i];
      });
      for (std::size_t i = 0; i < items; ++i) EXPECT_EQ(hits[i].load(), 1) << i;
      for (int c = 0; c < chunks; ++c) {
        EXPECT_EQ(begins[static_cast<std::size_t>(c)], chunk_begin(items, c, chunks));
      }
    }
  }
}

TEST(ParallelChunks, AnExceptionOfAnyChunkReachesTheCaller) {
  for (int failing : {0, 2}) {
    EXPECT_THROW(for_each_chunk(3, 30,
                                [failing](int chunk, std::size_t, std::size_t) {
                                  if (chunk == failing) throw std::runtime_error("chunk failed");
                                }),
                 std::runtime_error)
        << failing;
  }
}

// The one-pass energy and gradient (Problem::potential_with_gradient, the HP line search's) have
// the bits of potential() and gradient() at 1–4 threads, for both materials, and for a state with
// an inverted element: V = +∞ and the same NaN forces.
TEST(ElasticBarThreads, PotentialWithGradientHasTheBitsOfTheTwoAtAnyThreadCount) {
  test::ThreadCountGuard guard;
  for (const char* material : {"", ",material=stvk"}) {
    const auto bar = make_problem(std::string(kBar) + material);
    const Vec q = bar->initial_state().q + 1e-2 * test::random_vector(bar->dof(), 9);
    Vec inverted = q;
    inverted.segment<3>(3 * 500) += Eigen::Vector3d(2.0, -3.0, 1.5);  // through its neighbours
    for (const Vec* state : {static_cast<const Vec*>(&q), static_cast<const Vec*>(&inverted)}) {
      for (int threads : {1, 2, 3, 4}) {
        set_thread_count(threads);
        Vec g, g_alone;
        double V = 0;
        ASSERT_TRUE(bar->potential_with_gradient(*state, g, V));
        bar->gradient(*state, g_alone);
        const double V_alone = bar->potential(*state);
        EXPECT_EQ(std::memcmp(&V, &V_alone, sizeof(double)), 0) << material << threads;
        EXPECT_TRUE(same_bits(g, g_alone)) << material << " " << threads << " threads";
        if (state == &inverted && std::string(material).empty()) {
          EXPECT_EQ(V, std::numeric_limits<double>::infinity());
          EXPECT_FALSE(g.allFinite());
        }
      }
    }
  }
}

// The pool's workers persist: after a first loop has started them, a thousand more loops start no
// thread, and chunk 1 runs on the same thread every time.
TEST(ParallelChunks, LoopsReuseThePoolsWorkers) {
  for_each_chunk(3, 3, [](int, std::size_t, std::size_t) {});
  const long started = threads_started();
  const std::thread::id caller = std::this_thread::get_id();
  std::thread::id first_runner;
  std::atomic<long> sum{0};
  for (int loop = 0; loop < 1000; ++loop) {
    for_each_chunk(3, 300, [&](int chunk, std::size_t begin, std::size_t end) {
      if (chunk == 1) {
        if (loop == 0) first_runner = std::this_thread::get_id();
        EXPECT_EQ(std::this_thread::get_id(), first_runner) << loop;
        EXPECT_NE(std::this_thread::get_id(), caller) << loop;
      }
      for (std::size_t i = begin; i < end; ++i) sum += static_cast<long>(i);
    });
  }
  EXPECT_EQ(threads_started(), started);
  EXPECT_EQ(sum.load(), 1000L * (299 * 300 / 2));
}

// The pool's two ways to hand over a loop, polling and sleeping (kPoolPollBeforeSleep): loops
// back to back (workers still polling), loops after a pause far longer than the poll (workers
// asleep), and loops whose worker chunk outlasts the poll (the caller sleeps until it ends) each
// cover every item once on the same workers; and an idle pool sleeps rather than polls, so it
// takes no CPU time of its own while the process waits.
TEST(ParallelChunks, LoopsRunWhetherThePoolPollsOrSleeps) {
  for_each_chunk(2, 2, [](int, std::size_t, std::size_t) {});
  const long started = threads_started();
  constexpr std::size_t kItems = 64;
  const auto covered_once = [&](bool slow_worker) {
    std::vector<std::atomic<int>> hits(kItems);
    for_each_chunk(2, kItems, [&](int chunk, std::size_t begin, std::size_t end) {
      if (slow_worker && chunk == 1) std::this_thread::sleep_for(5 * kPoolPollBeforeSleep);
      for (std::size_t i = begin; i < end; ++i) ++hits[i];
    });
    return std::all_of(hits.begin(), hits.end(), [](const std::atomic<int>& h) { return h == 1; });
  };
  for (int loop = 0; loop < 200; ++loop)
    EXPECT_TRUE(covered_once(false)) << "back to back " << loop;
  for (int loop = 0; loop < 5; ++loop) {
    std::this_thread::sleep_for(10 * kPoolPollBeforeSleep);
    EXPECT_TRUE(covered_once(false)) << "after a pause " << loop;
    EXPECT_TRUE(covered_once(true)) << "slow worker " << loop;
  }
  EXPECT_EQ(threads_started(), started);
  // 200 ms idle: a worker that never stopped polling would take about as much CPU time. Its own
  // CPU clock, not the process's: a library's threads (OpenBLAS spins for ~0.1 s after it starts)
  // would be counted too.
  clockid_t worker_clock{};
  int clock_status = -1;
  for_each_chunk(2, 2, [&](int chunk, std::size_t, std::size_t) {
    if (chunk == 1) clock_status = pthread_getcpuclockid(pthread_self(), &worker_clock);
  });
  ASSERT_EQ(clock_status, 0);
  const auto worker_cpu_seconds = [&] {
    timespec now{};
    clock_gettime(worker_clock, &now);
    return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
  };
  const double cpu_before = worker_cpu_seconds();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_LT(worker_cpu_seconds() - cpu_before, 0.02);
}

// Loops from several threads at once (a sweep's concurrent runs) and a loop inside a chunk: the
// pool serves one loop at a time and the others run on threads of their own; every item is
// still covered exactly once by every loop.
TEST(ParallelChunks, ConcurrentAndNestedLoopsCoverEveryItemOnce) {
  constexpr std::size_t kItems = 1000;
  const auto covered_once = [](int chunks) {
    std::vector<std::atomic<int>> hits(kItems);
    for_each_chunk(chunks, kItems, [&](int, std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) ++hits[i];
    });
    return std::all_of(hits.begin(), hits.end(), [](const std::atomic<int>& h) { return h == 1; });
  };
  std::atomic<int> failures{0};
  std::vector<std::thread> callers;
  for (int caller = 0; caller < 4; ++caller) {
    callers.emplace_back([&, caller] {
      for (int loop = 0; loop < 50; ++loop) {
        if (!covered_once(2 + (caller + loop) % 3)) ++failures;
      }
    });
  }
  for (std::thread& caller : callers) caller.join();
  EXPECT_EQ(failures.load(), 0);
  std::atomic<int> nested_failures{0};
  for_each_chunk(2, 2, [&](int, std::size_t, std::size_t) {
    if (!covered_once(3)) ++nested_failures;
  });
  EXPECT_EQ(nested_failures.load(), 0);
}

TEST(ThreadSetting, RefusesCountsOutsideItsRangeAndLimitsChunks) {
  test::ThreadCountGuard guard;
  const auto set_text = [](const std::string& text) { set_thread_count(std::stoi(text)); };
  EXPECT_TRUE(test::input_error_names(set_text, "0",
                                      std::vector<std::string>{"thread count 0", "[1, 256]"}));
  EXPECT_TRUE(test::input_error_names(set_text, "257",
                                      std::vector<std::string>{"thread count 257", "[1, 256]"}));
  set_thread_count(3);
  EXPECT_EQ(thread_count(), 3);
  EXPECT_EQ(chunk_count(10, 2048), 1);        // too little work to share
  EXPECT_EQ(chunk_count(2 * 2048, 2048), 2);  // two chunks' worth
  EXPECT_EQ(chunk_count(100 * 2048, 2048), 3);
  EXPECT_EQ(thread_count_description(), "3 (set by the program)");
}

}  // namespace
}  // namespace threads_test
}  // namespace geomint
