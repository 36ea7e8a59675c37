// Threads for the element loops of problems (issue 30 item 2, docs/PERF.md "Threads"): the thread
// count setting (GEOMINT_THREADS) and a fixed partition of an index range into contiguous chunks,
// run on a persistent pool of worker threads, so a loop's split depends only on its length and
// the setting.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <chrono>
#include <cstddef>
#include <exception>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace geomint {

// Largest accepted thread count; more than the cores of any machine this suite targets.
constexpr int kMaxThreads = 256;

// Threads the element loops may use (≥ 1). Defaults to the hardware's concurrency (2 on the
// measured machine, where 2 is fastest: docs/PERF.md), or GEOMINT_THREADS when it is set.
int thread_count();
// Sets the count for the rest of the process; InputError unless 1 ≤ n ≤ kMaxThreads.
void set_thread_count(int n);
// Applies GEOMINT_THREADS if set: an InputError naming it and the allowed values when it is not
// an integer in [1, kMaxThreads]. geomint calls it before any command runs (exit 2 when bad);
// thread_count() calls it on first use in programs that did not.
void apply_thread_count_from_environment();
// How the count was chosen, for provenance: e.g. "2 (GEOMINT_THREADS)" or "2 (hardware)".
std::string thread_count_description();

// Chunks for `items` independent pieces of work: one per thread, but never fewer than
// `min_items_per_chunk` items per chunk, since starting a thread costs tens of microseconds.
int chunk_count(std::size_t items, std::size_t min_items_per_chunk);

// First index of chunk `chunk` of `chunks` over [0, items): chunk c is [begin(c), begin(c+1)).
inline std::size_t chunk_begin(std::size_t items, int chunk, int chunks) {
  return items * static_cast<std::size_t>(chunk) / static_cast<std::size_t>(chunks);
}

// Runs run(chunk) for every chunk in [0, chunks): chunk 0 on the calling thread, chunk c ≥ 1 on
// worker c of a persistent pool (started on first use, kept until the process ends), so a loop
// costs a wake-up per chunk instead of a thread start (~180 products per implicit step of the
// elastic bar: docs/PERF.md "Persistent thread pool"). After a loop, the workers and the caller
// waiting for them poll for up to kPoolPollBeforeSleep before they sleep, so loops that follow
// each other closely skip the wake-up (docs/PERF.md "Pool wake-up"). While another loop holds the
// pool (a sweep's concurrent runs, or a loop inside a chunk) the chunks run on threads of their
// own instead. Which thread runs a chunk never changes what it computes. `run` must not throw.
inline constexpr std::chrono::microseconds kPoolPollBeforeSleep{200};
void run_chunks(int chunks, const std::function<void(int)>& run);
// Threads started by run_chunks since the process began (pool workers and fallback threads), for
// tests and benchmarks: constant while the pool serves every loop.
long threads_started();

// Calls body(chunk, begin, end) for every chunk of [0, items), chunk 0 on the calling thread and
// the others on the pool's workers (run_chunks); returns after all have finished. An exception
// thrown by a chunk is rethrown here (the first chunk's first) once every chunk has ended.
template <class Body>
void for_each_chunk(int chunks, std::size_t items, const Body& body) {
  if (chunks <= 1) {
    body(0, std::size_t{0}, items);
    return;
  }
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(chunks));
  run_chunks(chunks, [&](int chunk) {
    try {
      body(chunk, chunk_begin(items, chunk, chunks), chunk_begin(items, chunk + 1, chunks));
    } catch (...) {
      errors[static_cast<std::size_t>(chunk)] = std::current_exception();
    }
  });
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

// y = A x for a symmetric A stored in full (both triangles, column-major, as the Hessians of
// problems are): y_i = (column i)·x, summed in row order, which is the order in which Eigen's
// A * x adds into y_i, so the result has the same bits as A * x at any thread count. Rows are
// split into chunks of equal non-zero counts. A must be square with x.size() columns.
void symmetric_product(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x,
                       Eigen::VectorXd& y);

// A symmetric matrix stored in full as 3×3 blocks (block-compressed columns: one row index per
// block instead of one per entry, 8.4 instead of 12 bytes per non-zero): the Newton matrices of
// problems with three coordinates per node (M + c∇²V of the elastic bar) in the form the CG product
// reads (docs/PERF.md "Block product").
struct SymmetricBlockMatrix {
  Eigen::Index block_columns = 0;
  std::vector<int> outer;      // blocks of block column I: [outer[I], outer[I + 1])
  std::vector<int> block_row;  // block row J of each block
  // Block k at block row J, block column I: values[9k + 3a + b] = A(3J + b, 3I + a).
  std::vector<double> values;
};

// Copies A (compressed, square) into `blocks` when its pattern is made of full 3×3 blocks
// (every column of a block column has the same rows, in whole aligned triples); false, and
// `blocks` emptied, otherwise. Threaded like symmetric_product.
bool to_symmetric_blocks(const Eigen::SparseMatrix<double>& A, SymmetricBlockMatrix& blocks);

// y = A x for A as copied by to_symmetric_blocks: y_i is summed over the rows of column i in
// ascending order, as symmetric_product does, so the result has the same bits as
// symmetric_product(A, x, y) at any thread count.
void symmetric_product(const SymmetricBlockMatrix& A, const Eigen::VectorXd& x, Eigen::VectorXd& y);

}  // namespace geomint
