// BoomerAMG settings for the CG inside Newton (integrators/boomer_amg.hpp): set-up time, CG
// iterations and solve time on the HP midpoint matrix M + (h/2)²∇²V of the elastic bar at ~10⁴
// and 10⁵ tetrahedra, next to the diagonal preconditioner of linear_solver=cg. Wall time.
#include <benchmark/benchmark.h>

#include <Eigen/IterativeLinearSolvers>
#include <string>

#include "integrators/boomer_amg.hpp"
#include "problems/problem.hpp"

namespace {

using geomint::SparseMatrix;
using geomint::Vec;

struct Size {
  int nx, n;
};
constexpr Size kSizes[] = {{10, 4}, {26, 8}, {65, 16}};

SparseMatrix midpoint_matrix(int size) {
  const Size s = kSizes[size];
  const auto problem = geomint::make_problem("elastic_bar:nx=" + std::to_string(s.nx) + ",ny=" +
                                             std::to_string(s.n) + ",nz=" + std::to_string(s.n));
  SparseMatrix H;
  problem->hessian(problem->initial_state().q, H);
  const double h = 0.011 * 16.0 / s.n;
  SparseMatrix A = (0.25 * h * h) * H + SparseMatrix(problem->mass().asDiagonal());
  A.makeCompressed();
  return A;
}

// Eigen's preconditioner interface around one V-cycle.
class AmgPreconditioner {
 public:
  AmgPreconditioner() = default;
  template <class M>
  explicit AmgPreconditioner(const M&) {}
  template <class M>
  AmgPreconditioner& analyzePattern(const M&) {
    return *this;
  }
  template <class M>
  AmgPreconditioner& factorize(const M&) {
    return *this;
  }
  template <class M>
  AmgPreconditioner& compute(const M&) {
    return *this;
  }
  Vec solve(const Vec& r) const { return amg_->solve(r); }
  Eigen::ComputationInfo info() const { return Eigen::Success; }
  geomint::BoomerAmg* amg_ = nullptr;
};

geomint::BoomerAmgOptions options_of(const benchmark::State& state) {
  geomint::BoomerAmgOptions options;
  options.functions = static_cast<int>(state.range(1));
  options.aggressive_levels = static_cast<int>(state.range(2));
  options.strong_threshold = static_cast<double>(state.range(3)) / 100.0;
  return options;
}

void BM_AmgSetup(benchmark::State& state) {
  const SparseMatrix A = midpoint_matrix(static_cast<int>(state.range(0)));
  geomint::BoomerAmg amg(options_of(state));
  for (auto _ : state) benchmark::DoNotOptimize(amg.setup(A));
}

// CG to a relative residual 1e-8 (what a Newton iteration asks: 1e-3 of ‖R‖ or below).
void BM_AmgCg(benchmark::State& state) {
  const SparseMatrix A = midpoint_matrix(static_cast<int>(state.range(0)));
  geomint::BoomerAmg amg(options_of(state));
  amg.setup(A);
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper, AmgPreconditioner> cg;
  cg.compute(A);
  cg.preconditioner().amg_ = &amg;
  cg.setTolerance(1e-8);
  const Vec b = Vec::Ones(A.rows());
  Vec x;
  for (auto _ : state) {
    x = cg.solve(b);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["cg_iterations"] = static_cast<double>(cg.iterations());
}

void BM_DiagonalCg(benchmark::State& state) {
  const SparseMatrix A = midpoint_matrix(static_cast<int>(state.range(0)));
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper> cg;
  cg.compute(A);
  cg.setTolerance(1e-8);
  const Vec b = Vec::Ones(A.rows());
  Vec x;
  for (auto _ : state) {
    x = cg.solve(b);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["cg_iterations"] = static_cast<double>(cg.iterations());
}

// size, functions, aggressive levels, strong threshold ×100
void settings(benchmark::internal::Benchmark* b) {
  for (int size : {1, 2}) {
    for (int functions : {1, 3}) {
      for (int aggressive : {0, 1}) {
        for (int threshold : {25, 50}) b->Args({size, functions, aggressive, threshold});
      }
    }
  }
}

BENCHMARK(BM_AmgSetup)->Apply(settings)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AmgCg)->Apply(settings)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DiagonalCg)->DenseRange(1, 2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
