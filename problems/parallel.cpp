// The thread count setting and the persistent chunk pool (problems/parallel.hpp, issue 30 item 2).
#include "problems/parallel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "problems/spec.hpp"

namespace geomint {
namespace {

// Read once: std::thread::hardware_concurrency() reads /sys/devices/system/cpu/online (three
// system calls) on every call, and chunk_count() runs for every element loop and CG product; read
// per call it made up two thirds of the CPU time of the inexact_solves scene.
int hardware_threads() {
  static const int threads =
      std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, kMaxThreads);
  return threads;  // hardware_concurrency() is 0 when unknown: 1
}

// GEOMINT_THREADS, or 0 when unset; InputError when malformed.
int environment_threads() {
  const char* text = std::getenv("GEOMINT_THREADS");
  if (text == nullptr) return 0;
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || errno != 0 || value < 1 || value > kMaxThreads) {
    throw InputError(fmt::format(
        "environment variable GEOMINT_THREADS='{}' is not allowed: use an integer in [1, {}] "
        "(threads for the element loops), or unset it for the hardware's {}",
        text, kMaxThreads, hardware_threads()));
  }
  return static_cast<int>(value);
}

// 0 until chosen. Atomic because the threads of a sweep read it; relaxed order suffices for a
// single value that is chosen before any loop runs.
std::atomic<int> chosen_threads{0};
std::atomic<bool> chosen_by_environment{false};
// Whether GEOMINT_THREADS has been read, so thread_count() reads it once, not per loop.
std::atomic<bool> environment_read{false};

}  // namespace

void apply_thread_count_from_environment() {
  const int from_environment = environment_threads();
  environment_read.store(true, std::memory_order_relaxed);
  if (from_environment == 0) return;
  chosen_threads.store(from_environment, std::memory_order_relaxed);
  chosen_by_environment.store(true, std::memory_order_relaxed);
}

int thread_count() {
  // A program that did not call apply_thread_count_from_environment (a benchmark, a test) still
  // honours the variable.
  if (!environment_read.load(std::memory_order_relaxed)) apply_thread_count_from_environment();
  const int chosen = chosen_threads.load(std::memory_order_relaxed);
  return chosen > 0 ? chosen : hardware_threads();
}

void set_thread_count(int n) {
  if (n < 1 || n > kMaxThreads) {
    throw InputError(
        fmt::format("thread count {} is not allowed: use an integer in [1, {}]", n, kMaxThreads));
  }
  chosen_threads.store(n, std::memory_order_relaxed);
  chosen_by_environment.store(false, std::memory_order_relaxed);
  environment_read.store(true, std::memory_order_relaxed);  // the program's choice stands
}

std::string thread_count_description() {
  const int count = thread_count();
  const bool configured = chosen_threads.load(std::memory_order_relaxed) > 0;
  return fmt::format("{} ({})", count,
                     chosen_by_environment.load(std::memory_order_relaxed) ? "GEOMINT_THREADS"
                     : configured                                          ? "set by the program"
                                                                           : "hardware");
}

int chunk_count(std::size_t items, std::size_t min_items_per_chunk) {
  const std::size_t most =
      std::max<std::size_t>(1, items / std::max<std::size_t>(1, min_items_per_chunk));
  if (most == 1) return 1;  // too little work to split, whatever the setting
  return static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(thread_count()), most));
}

namespace {

std::atomic<long> started_threads{0};

// kPoolPollBeforeSleep (problems/parallel.hpp): a CG iteration runs one threaded product every
// ~0.4 ms with serial vector updates between them, and waking a sleeping thread costs ~25 µs here
// (a futex round trip in a VM; docs/PERF.md "Pool wake-up"), so a worker that polls a little
// longer than those gaps starts the next loop at once. Bounded, and yielding the core while it
// polls, so an idle pool sleeps and a pool sharing its cores with other work costs it little.
// Polls `ready` until it is true or kPoolPollBeforeSleep has passed; whether it became true.
template <typename Ready>
bool poll(const Ready& ready) {
  const auto start = std::chrono::steady_clock::now();
  for (int round = 1;; ++round) {
    if (ready()) return true;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
    if (round % 64 == 0) {
      if (std::chrono::steady_clock::now() - start > kPoolPollBeforeSleep) return ready();
      std::this_thread::yield();
    }
  }
}

// Workers 1, 2, … of run_chunks, each running the chunk of its own index of the current loop. One
// loop at a time (`in_use`); the caller runs chunk 0 and waits until every other chunk is done.
// A loop is published as a ticket (its sequence number and chunk count in one atomic word, so a
// worker never pairs one loop's number with another's count) and a finished chunk by decrementing
// `pending_`. Both sides poll for these a short while before they sleep (kPoolPollBeforeSleep)
// when the loop has no more threads than the hardware (with more, a polling thread would hold a
// core that a working one needs), and every change a sleeper waits for is made or followed under
// `mutex_` before the notify, so no wake-up is lost.
class ChunkPool {
 public:
  ~ChunkPool() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_.store(true, std::memory_order_release);
    }
    wake_.notify_all();
    for (std::thread& worker : workers_) worker.join();
  }

  // False (nothing run) when another loop holds the pool.
  bool try_run(int chunks, const std::function<void(int)>& run) {
    const std::unique_lock<std::mutex> use(in_use_, std::try_to_lock);
    if (!use.owns_lock()) return false;
    while (static_cast<int>(workers_.size()) < chunks - 1) {
      const int index = static_cast<int>(workers_.size()) + 1;
      workers_.emplace_back([this, index] { work(index); });
      started_threads.fetch_add(1, std::memory_order_relaxed);
    }
    // Safe to write: every worker of the last loop has finished with job_ (pending_ reached 0).
    job_ = &run;
    pending_.store(chunks - 1, std::memory_order_relaxed);
    {
      // The release publishes job_ and pending_ to the workers that see the new ticket.
      const std::lock_guard<std::mutex> lock(mutex_);
      ++loops_;
      ticket_.store(loops_ << kChunkBits | static_cast<std::uint64_t>(chunks),
                    std::memory_order_release);
    }
    wake_.notify_all();
    run(0);
    const auto all_done = [this] { return pending_.load(std::memory_order_acquire) == 0; };
    if (!(chunks <= hardware_threads() && poll(all_done))) {
      std::unique_lock<std::mutex> lock(mutex_);
      done_.wait(lock, all_done);
    }
    return true;
  }

 private:
  static constexpr int kChunkBits = 16;
  static_assert(kMaxThreads < (1 << kChunkBits), "a ticket's chunk count takes kChunkBits");

  void work(int index) {
    std::uint64_t seen = 0;
    bool may_poll = false;  // whether the last loop left a core per thread
    while (true) {
      const auto news = [&] {
        return stop_.load(std::memory_order_acquire) ||
               ticket_.load(std::memory_order_acquire) != seen;
      };
      if (!(may_poll && poll(news))) {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, news);
      }
      if (stop_.load(std::memory_order_acquire)) return;
      seen = ticket_.load(std::memory_order_acquire);
      const int chunks = static_cast<int>(seen & ((std::uint64_t{1} << kChunkBits) - 1));
      // A worker outside the loop, or one of more threads than cores, sleeps at once next time.
      may_poll = index < chunks && chunks <= hardware_threads();
      if (index >= chunks) continue;  // this loop has fewer chunks than workers
      (*job_)(index);
      if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
        // The caller may have found pending_ > 0 and be about to sleep: notify under the mutex,
        // which it holds from that test until it sleeps.
        const std::lock_guard<std::mutex> lock(mutex_);
        done_.notify_one();
      }
    }
  }

  std::mutex in_use_;
  std::mutex mutex_;  // held to publish a ticket and to notify; sleepers wait on it
  std::condition_variable wake_, done_;
  std::vector<std::thread> workers_;  // changed only by the loop holding in_use_
  // Written by the caller before it publishes a ticket; read by the workers of that loop only.
  const std::function<void(int)>* job_ = nullptr;
  std::uint64_t loops_ = 0;               // guarded by mutex_
  std::atomic<std::uint64_t> ticket_{0};  // loops_ << kChunkBits | chunks of the current loop
  std::atomic<int> pending_{0};           // chunks ≥ 1 of the current loop not yet finished
  std::atomic<bool> stop_{false};
};

ChunkPool& chunk_pool() {
  static ChunkPool pool;
  return pool;
}

}  // namespace

void run_chunks(int chunks, const std::function<void(int)>& run) {
  if (chunks <= 1) {
    run(0);
    return;
  }
  if (chunk_pool().try_run(chunks, run)) return;
  std::vector<std::thread> workers;
  workers.reserve(static_cast<std::size_t>(chunks - 1));
  for (int chunk = 1; chunk < chunks; ++chunk) workers.emplace_back(run, chunk);
  started_threads.fetch_add(chunks - 1, std::memory_order_relaxed);
  run(0);
  for (std::thread& worker : workers) worker.join();
}

long threads_started() { return started_threads.load(std::memory_order_relaxed); }

namespace {

// Below this many non-zeros per chunk a thread costs more than it saves (docs/PERF.md).
constexpr std::size_t kMinNonZerosPerChunk = 1 << 16;

// First (block) column of each chunk when [0, columns) is cut into `chunks` pieces of about equal
// non-zero counts (outer: the prefix sums of the non-zeros per column).
std::vector<Eigen::Index> balanced_columns(const int* outer, Eigen::Index columns, int chunks) {
  const auto nonzeros = static_cast<std::size_t>(outer[columns] - outer[0]);
  std::vector<Eigen::Index> first(static_cast<std::size_t>(chunks) + 1, columns);
  first[0] = 0;
  for (int chunk = 1; chunk < chunks; ++chunk) {
    const int target = outer[0] + static_cast<int>(chunk_begin(nonzeros, chunk, chunks));
    first[static_cast<std::size_t>(chunk)] =
        std::lower_bound(outer, outer + columns, target) - outer;
  }
  return first;
}

// multiply(first, last) over [0, columns) in chunks of about equal non-zero counts, on the pool
// when there is enough work (the column ranges each chunk owns are disjoint: no two threads
// write one entry).
template <typename Multiply>
void multiply_in_balanced_chunks(const int* outer, Eigen::Index columns, std::size_t nonzeros,
                                 const Multiply& multiply) {
  const int chunks = chunk_count(nonzeros, kMinNonZerosPerChunk);
  if (chunks == 1) {
    multiply(Eigen::Index{0}, columns);
    return;
  }
  const std::vector<Eigen::Index> first = balanced_columns(outer, columns, chunks);
  for_each_chunk(chunks, static_cast<std::size_t>(chunks),
                 [&](int chunk, std::size_t, std::size_t) {
                   multiply(first[static_cast<std::size_t>(chunk)],
                            first[static_cast<std::size_t>(chunk) + 1]);
                 });
}

}  // namespace

void symmetric_product(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x,
                       Eigen::VectorXd& y) {
  if (!A.isCompressed()) {  // the loops below need a compressed column layout
    y = A * x;
    return;
  }
  const Eigen::Index n = A.outerSize();
  y.resize(n);
  const double* values = A.valuePtr();
  const int* rows = A.innerIndexPtr();
  const int* outer = A.outerIndexPtr();
  const auto multiply = [&](Eigen::Index first, Eigen::Index last) {
    for (Eigen::Index column = first; column < last; ++column) {
      double sum = 0;
      for (int k = outer[column]; k < outer[column + 1]; ++k) sum += values[k] * x[rows[k]];
      y[column] = sum;
    }
  };
  // Chunk c covers the columns whose first non-zero lies in the c-th equal share of them.
  multiply_in_balanced_chunks(outer, n, static_cast<std::size_t>(outer[n] - outer[0]), multiply);
}

bool to_symmetric_blocks(const Eigen::SparseMatrix<double>& A, SymmetricBlockMatrix& blocks) {
  blocks = SymmetricBlockMatrix{};
  if (!A.isCompressed() || A.rows() != A.cols() || A.cols() % 3 != 0) return false;
  const Eigen::Index block_columns = A.cols() / 3;
  const int* outer = A.outerIndexPtr();
  const int* rows = A.innerIndexPtr();
  const double* values = A.valuePtr();
  // The three columns of a block column hold equally many entries, a multiple of 3.
  std::vector<int> block_outer(static_cast<std::size_t>(block_columns) + 1, 0);
  for (Eigen::Index I = 0; I < block_columns; ++I) {
    const int count = outer[3 * I + 1] - outer[3 * I];
    if (count % 3 != 0 || outer[3 * I + 2] - outer[3 * I + 1] != count ||
        outer[3 * I + 3] - outer[3 * I + 2] != count) {
      return false;
    }
    block_outer[static_cast<std::size_t>(I) + 1] =
        block_outer[static_cast<std::size_t>(I)] + count / 3;
  }
  const auto block_count = static_cast<std::size_t>(block_outer.back());
  std::vector<int> block_row(block_count);
  std::vector<double> block_values(9 * block_count);
  std::atomic<bool> aligned{true};
  const auto copy = [&](Eigen::Index first, Eigen::Index last) {
    for (Eigen::Index I = first; I < last; ++I) {
      const int blocks_here =
          block_outer[static_cast<std::size_t>(I) + 1] - block_outer[static_cast<std::size_t>(I)];
      for (int m = 0; m < blocks_here; ++m) {
        const auto k = static_cast<std::size_t>(block_outer[static_cast<std::size_t>(I)] + m);
        const int J = rows[outer[3 * I] + 3 * m] / 3;
        block_row[k] = J;
        for (int a = 0; a < 3; ++a) {
          const int start = outer[3 * I + a] + 3 * m;
          for (int b = 0; b < 3; ++b) {
            if (rows[start + b] != 3 * J + b) {
              aligned.store(false, std::memory_order_relaxed);
              return;
            }
            block_values[9 * k + 3 * static_cast<std::size_t>(a) + static_cast<std::size_t>(b)] =
                values[start + b];
          }
        }
      }
    }
  };
  const auto nonzeros = static_cast<std::size_t>(outer[A.cols()] - outer[0]);
  const int chunks = chunk_count(nonzeros, kMinNonZerosPerChunk);
  const std::vector<Eigen::Index> first =
      balanced_columns(block_outer.data(), block_columns, chunks);
  for_each_chunk(
      chunks, static_cast<std::size_t>(chunks), [&](int chunk, std::size_t, std::size_t) {
        copy(first[static_cast<std::size_t>(chunk)], first[static_cast<std::size_t>(chunk) + 1]);
      });
  if (!aligned.load(std::memory_order_relaxed)) return false;
  blocks.block_columns = block_columns;
  blocks.outer = std::move(block_outer);
  blocks.block_row = std::move(block_row);
  blocks.values = std::move(block_values);
  return true;
}

void symmetric_product(const SymmetricBlockMatrix& A, const Eigen::VectorXd& x,
                       Eigen::VectorXd& y) {
  const Eigen::Index block_columns = A.block_columns;
  y.resize(3 * block_columns);
  const int* outer = A.outer.data();
  const int* block_row = A.block_row.data();
  const double* values = A.values.data();
  const double* in = x.data();
  double* out = y.data();
  const auto multiply = [&](Eigen::Index first, Eigen::Index last) {
    for (Eigen::Index I = first; I < last; ++I) {
      // Three sums, each over its column's rows in ascending order (block rows ascending, then
      // the three rows of a block): the order of symmetric_product on the scalar matrix.
      double s0 = 0, s1 = 0, s2 = 0;
      for (int k = outer[I]; k < outer[I + 1]; ++k) {
        const double* v = values + 9 * static_cast<std::ptrdiff_t>(k);
        const double* xb = in + 3 * static_cast<std::ptrdiff_t>(block_row[k]);
        s0 += v[0] * xb[0];
        s0 += v[1] * xb[1];
        s0 += v[2] * xb[2];
        s1 += v[3] * xb[0];
        s1 += v[4] * xb[1];
        s1 += v[5] * xb[2];
        s2 += v[6] * xb[0];
        s2 += v[7] * xb[1];
        s2 += v[8] * xb[2];
      }
      out[3 * I] = s0;
      out[3 * I + 1] = s1;
      out[3 * I + 2] = s2;
    }
  };
  multiply_in_balanced_chunks(outer, block_columns,
                              9 * static_cast<std::size_t>(outer[block_columns] - outer[0]),
                              multiply);
}

}  // namespace geomint
