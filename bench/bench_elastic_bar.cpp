// Throughput of the elastic bar's FEM kernels (PAPER.md §6): gradient (Σ vol P D_m⁻ᵀ) and sparse
// Hessian assembly (Σ vol Bᵀ (dP/dF) B) at ~10³, 10⁴, 10⁵ linear tetrahedra, in elements/s, with
// the precomputed mesh data and the Hessian's non-zeros as memory counters.
#include <benchmark/benchmark.h>

#include <Eigen/SparseCore>
#include <cstddef>
#include <memory>
#include <random>
#include <string>

#include "problems/problem.hpp"

namespace geomint {
// Defined in problems/elastic_bar.cpp (problems have no per-problem headers).
std::size_t elastic_bar_footprint_bytes(const Problem& problem);
}  // namespace geomint

namespace {

using geomint::Problem;
using geomint::SparseMatrix;
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
