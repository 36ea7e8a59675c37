// Throughput of the elastic bar's FEM kernels (docs/METHOD.md §6): gradient (Σ vol P D_m⁻ᵀ) and
// sparse Hessian assembly (Σ vol Bᵀ (dP/dF) B) at ~10³, 10⁴, 10⁵ linear tetrahedra, in elements/s,
// with the precomputed mesh data and the Hessian's non-zeros as memory counters; and one step of
// the HP midpoint minimiser (Kharevych et al. 2006) at 10⁴ and 10⁵ tetrahedra far beyond the
// explicit limit h = 2/ω_max, with Newton iterations per step as a counter.
#include <benchmark/benchmark.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/elastic_bar.hpp"
#include "problems/parallel.hpp"
#include "problems/problem.hpp"

namespace {

using geomint::Problem;
using geomint::SparseMatrix;
using geomint::State;
using geomint::Vec;

// Cells nx × n × n, 6 tetrahedra each: 960, 9 984 and 99 840 tetrahedra.
struct Size {
  int nx, n;
};
constexpr Size kSizes[] = {{10, 4}, {26, 8}, {65, 16}};

std::unique_ptr<Problem> make_bar(const benchmark::State& state, const std::string& material) {
  const Size size = kSizes[state.range(0)];
  return geomint::make_problem("elastic_bar:material=" + material +
                               ",nx=" + std::to_string(size.nx) + ",ny=" + std::to_string(size.n) +
                               ",nz=" + std::to_string(size.n));
}

long tetrahedra(const benchmark::State& state) {
  const Size size = kSizes[state.range(0)];
  return 6L * size.nx * size.n * size.n;
}

// A deformed configuration (1% of the cell size at random, plus the sag of a gentle bend), so
// that no branch of the kernels sees the special case F = I.
Vec deformed(const Problem& problem) {
  std::mt19937 generator(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Vec q = problem.initial_state().q;
  for (int i = 0; i < q.size(); ++i) q[i] += 1e-3 * uniform(generator);
  return q;
}

void add_counters(benchmark::State& state, const Problem& problem, const SparseMatrix* H) {
  const long elements = tetrahedra(state);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * elements);
  state.counters["tets"] = static_cast<double>(elements);
  state.counters["dof"] = problem.dof();
  state.counters["mesh_bytes"] = static_cast<double>(geomint::elastic_bar_footprint_bytes(problem));
  if (H != nullptr) {
    state.counters["hessian_nnz"] = static_cast<double>(H->nonZeros());
    state.counters["hessian_bytes"] = static_cast<double>(
        H->nonZeros() * (sizeof(double) + sizeof(int)) + (H->outerSize() + 1) * sizeof(int));
  }
}

void BM_Gradient(benchmark::State& state, const std::string& material) {
  const auto problem = make_bar(state, material);
  const Vec q = deformed(*problem);
  Vec g;
  for (auto _ : state) {
    problem->gradient(q, g);
    benchmark::DoNotOptimize(g.data());
    benchmark::ClobberMemory();
  }
  add_counters(state, *problem, nullptr);
}

void BM_Hessian(benchmark::State& state, const std::string& material) {
  const auto problem = make_bar(state, material);
  const Vec q = deformed(*problem);
  SparseMatrix H;
  for (auto _ : state) {
    problem->hessian(q, H);
    benchmark::DoNotOptimize(H.valuePtr());
    benchmark::ClobberMemory();
  }
  add_counters(state, *problem, &H);
}

// One step of hp:alpha=0.5,solver=minimize on the clamped neo-Hookean bar sagging under gravity,
// from rest, at h = kStepOverLimit · 2/ω_max. Each iteration restarts from the same state so
// that every timed step solves the same problem; the reset is outside the timing.
constexpr double kStepOverLimit = 20;

void BM_HpMidpointStep(benchmark::State& state) {
  const auto problem = make_bar(state, "neohookean");
  const State start = problem->initial_state();
  const double h = kStepOverLimit * 2 / problem->omega_max(start.q);
  auto integrator = geomint::make_integrator("hp:alpha=0.5,solver=minimize");
  long steps = 0, newton_iterations = 0, failures = 0;
  for (auto _ : state) {
    state.PauseTiming();
    State current = start;
    integrator->reset(*problem, current, h);
    const long iterations_before = integrator->counters().newton_iters;
    state.ResumeTiming();
    const geomint::StepStatus status = integrator->step(*problem, current, h);
    benchmark::DoNotOptimize(current.q.data());
    state.PauseTiming();
    ++steps;
    newton_iterations += integrator->counters().newton_iters - iterations_before;
    if (!status.ok) ++failures;
    state.ResumeTiming();
  }
  state.counters["tets"] = static_cast<double>(tetrahedra(state));
  state.counters["dof"] = problem->dof();
  state.counters["h"] = h;
  state.counters["h_omega_max"] = h * problem->omega_max(start.q);
  state.counters["newton_per_step"] = static_cast<double>(newton_iterations) / steps;
  state.counters["failed_steps"] = static_cast<double>(failures);
}

// Threads (issue 30 item 2, docs/PERF.md "Threads"): the energy, gradient and Hessian of the
// neo-Hookean bar and the product H x, at size index range(0) and range(1) threads (the thread
// setting is restored afterwards). "eigen_spmv" is Eigen's serial H * x, the reference of
// geomint::symmetric_product on the scalar matrix ("spmv") and on its 3×3-block copy, the one CG
// uses ("block_spmv"), which give the same bits.
// The fastest repetition: the least disturbed by other processes on a shared machine.
double fastest(const std::vector<double>& times) {
  return *std::min_element(times.begin(), times.end());
}

enum class Kernel { kEnergy, kGradient, kHessian, kSpmv, kBlockSpmv, kEigenSpmv };

void BM_Threads(benchmark::State& state, Kernel kernel) {
  const int saved_threads = geomint::thread_count();
  geomint::set_thread_count(static_cast<int>(state.range(1)));
  const auto problem = make_bar(state, "neohookean");
  const Vec q = deformed(*problem);
  SparseMatrix H;
  problem->hessian(q, H);
  geomint::SymmetricBlockMatrix blocks;  // the 3×3-block copy CG multiplies with
  geomint::to_symmetric_blocks(H, blocks);
  Vec out;
  double energy = 0;
  for (auto _ : state) {
    switch (kernel) {
      case Kernel::kEnergy:
        energy = problem->potential(q);
        benchmark::DoNotOptimize(energy);
        break;
      case Kernel::kGradient:
        problem->gradient(q, out);
        break;
      case Kernel::kHessian:
        problem->hessian(q, H);
        break;
      case Kernel::kSpmv:
        geomint::symmetric_product(H, q, out);
        break;
      case Kernel::kBlockSpmv:
        geomint::symmetric_product(blocks, q, out);
        break;
      case Kernel::kEigenSpmv:
        out.noalias() = H * q;
        break;
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::DoNotOptimize(H.valuePtr());
    benchmark::ClobberMemory();
  }
  state.counters["threads"] = static_cast<double>(state.range(1));
  state.counters["tets"] = static_cast<double>(tetrahedra(state));
  state.counters["hessian_nnz"] = static_cast<double>(H.nonZeros());
  geomint::set_thread_count(saved_threads);
}

BENCHMARK_CAPTURE(BM_Threads, energy, Kernel::kEnergy)
    ->ArgsProduct({{1, 2}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ComputeStatistics("min", fastest);
BENCHMARK_CAPTURE(BM_Threads, gradient, Kernel::kGradient)
    ->ArgsProduct({{1, 2}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ComputeStatistics("min", fastest);
BENCHMARK_CAPTURE(BM_Threads, hessian, Kernel::kHessian)
    ->ArgsProduct({{1, 2}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ComputeStatistics("min", fastest);
BENCHMARK_CAPTURE(BM_Threads, spmv, Kernel::kSpmv)
    ->ArgsProduct({{1, 2}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ComputeStatistics("min", fastest);
BENCHMARK_CAPTURE(BM_Threads, block_spmv, Kernel::kBlockSpmv)
    ->ArgsProduct({{1, 2}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ComputeStatistics("min", fastest);
BENCHMARK_CAPTURE(BM_Threads, eigen_spmv, Kernel::kEigenSpmv)
    ->ArgsProduct({{1, 2}, {1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ComputeStatistics("min", fastest);

// One iteration each: at 10⁵ tetrahedra a step is minutes, almost all of it in the simplicial
// sparse LDLᵀ factorisations of the Newton steps (3 per step measured on 2026-12-01).
// The pool's cost per threaded loop (docs/PERF.md "Pool wake-up"): an empty loop of two chunks,
// back to back, so the worker is still polling when the next one starts (kPoolPollBeforeSleep),
// and after a pause of 1 ms (range(0) = 1), when it has gone to sleep and must be woken.
void BM_PoolLoop(benchmark::State& state) {
  const bool after_pause = state.range(0) == 1;
  const int saved_threads = geomint::thread_count();
  geomint::set_thread_count(2);
  for (auto _ : state) {
    if (after_pause) {
      state.PauseTiming();
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      state.ResumeTiming();
    }
    geomint::for_each_chunk(2, 2, [](int, std::size_t, std::size_t) {});
  }
  geomint::set_thread_count(saved_threads);
}
BENCHMARK(BM_PoolLoop)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();

BENCHMARK(BM_HpMidpointStep)->DenseRange(1, 2)->Unit(benchmark::kMillisecond)->Iterations(1);

BENCHMARK_CAPTURE(BM_Gradient, neohookean, std::string("neohookean"))
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Gradient, stvk, std::string("stvk"))
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Hessian, neohookean, std::string("neohookean"))
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Hessian, stvk, std::string("stvk"))
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
