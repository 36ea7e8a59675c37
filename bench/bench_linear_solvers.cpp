// Linear solvers of the Newton step (integrators/newton.hpp LinearSolverKind; docs/METHODS.md
// "Scale"): numeric factorisation and solve time per solver on the elastic bar's implicit-Euler
// matrix M + h²∇²V at ~10³, 10⁴, 10⁵ tetrahedra (symbolic analysis once, outside the timing, as in
// a run), and one implicit step (implicit Euler, HP midpoint) per solver through the method
// registry. CPU time (the machine is shared): run with --benchmark_filter=... to pick a size or
// solver.
#include <benchmark/benchmark.h>

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
// clang-format off
#include <iostream>  // before MetisSupport, which uses std::cerr without including it
#include <Eigen/MetisSupport>
// clang-format on
#include <Eigen/SparseCholesky>
#include <memory>
#include <string>

#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace {

using geomint::Problem;
using geomint::SparseMatrix;
using geomint::Vec;

// Cells nx × n × n, 6 tetrahedra each: 960, 9 984 and 99 840 tetrahedra.
struct Size {
  int nx, n;
};
constexpr Size kSizes[] = {{10, 4}, {26, 8}, {65, 16}};

std::string bar_spec(const benchmark::State& state) {
  const Size size = kSizes[state.range(0)];
  return "elastic_bar:nx=" + std::to_string(size.nx) + ",ny=" + std::to_string(size.n) +
         ",nz=" + std::to_string(size.n);
}

// h = 0.011 at 10⁵ tetrahedra, scaled with the cell size below.
double step_size(const benchmark::State& state) { return 0.011 * 16.0 / kSizes[state.range(0)].n; }

SparseMatrix newton_matrix(const benchmark::State& state) {
  const auto problem = geomint::make_problem(bar_spec(state));
  const Vec q = problem->initial_state().q;
  SparseMatrix H;
  problem->hessian(q, H);
  const double h = step_size(state);
  SparseMatrix M(problem->mass().asDiagonal());
  SparseMatrix A = (h * h) * H + M;
  A.makeCompressed();
  return A;
}

void add_counters(benchmark::State& state, const SparseMatrix& A) {
  state.counters["dof"] = static_cast<double>(A.rows());
  state.counters["nnz"] = static_cast<double>(A.nonZeros());
}

template <class Solver>
void configure(Solver&) {}

void configure(Eigen::CholmodSupernodalLLT<SparseMatrix>& solver) {
  cholmod_common& common = solver.cholmod();
  common.nmethods = 1;
  common.method[0].ordering = CHOLMOD_METIS;
  common.postorder = 1;
}

template <class Solver>
void BM_Factorise(benchmark::State& state) {
  const SparseMatrix A = newton_matrix(state);
  Solver solver;
  configure(solver);
  solver.analyzePattern(A);
  for (auto _ : state) {
    solver.factorize(A);
    benchmark::DoNotOptimize(solver.info());
  }
  add_counters(state, A);
}

template <class Solver>
void BM_Solve(benchmark::State& state) {
  const SparseMatrix A = newton_matrix(state);
  Solver solver;
  configure(solver);
  solver.compute(A);
  const Vec b = Vec::Ones(A.rows());
  Vec x;
  for (auto _ : state) {
    x = solver.solve(b);
    benchmark::DoNotOptimize(x.data());
  }
  add_counters(state, A);
}

// Conjugate gradients to a relative residual 1e-10 (the Newton solver asks for less: 1e-3 of the
// current residual, down to a tenth of the Newton threshold).
template <class Preconditioner>
void BM_ConjugateGradient(benchmark::State& state) {
  const SparseMatrix A = newton_matrix(state);
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper, Preconditioner> cg;
  cg.setTolerance(1e-10);
  const Vec b = Vec::Ones(A.rows());
  Vec x;
  for (auto _ : state) {
    cg.compute(A);
    x = cg.solve(b);
    benchmark::DoNotOptimize(x.data());
  }
  add_counters(state, A);
  state.counters["cg_iterations"] = static_cast<double>(cg.iterations());
}

using AmdLdlt = Eigen::SimplicialLDLT<SparseMatrix>;
using MetisLdlt = Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::MetisOrdering<int>>;
using Cholmod = Eigen::CholmodSupernodalLLT<SparseMatrix>;

BENCHMARK(BM_Factorise<AmdLdlt>)
    ->Name("Factorise/ldlt")
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Factorise<MetisLdlt>)
    ->Name("Factorise/ldlt_metis")
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Factorise<Cholmod>)
    ->Name("Factorise/cholmod")
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Solve<AmdLdlt>)->Name("Solve/ldlt")->DenseRange(0, 1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Solve<Cholmod>)
    ->Name("Solve/cholmod")
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ConjugateGradient<Eigen::DiagonalPreconditioner<double>>)
    ->Name("ConjugateGradient/diagonal")
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ConjugateGradient<Eigen::IncompleteCholesky<double>>)
    ->Name("ConjugateGradient/ichol")
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond);

// One step of an implicit method per linear solver, through the registry (assembly, Newton,
// line search: what a run pays per step).
void BM_ImplicitStep(benchmark::State& state, const std::string& method) {
  const auto problem = geomint::make_problem(bar_spec(state));
  const auto integrator = geomint::make_integrator(method);
  const geomint::State start = problem->initial_state();
  const double h = step_size(state);
  long iterations = 0, factorizations = 0;
  for (auto _ : state) {
    geomint::State s = start;
    integrator->reset(*problem, s, h);
    const geomint::StepStatus status = integrator->step(*problem, s, h);
    if (!status.ok) state.SkipWithError(status.message.c_str());
    iterations += integrator->counters().newton_iters;
    factorizations += integrator->counters().factorizations;
  }
  state.counters["dof"] = problem->dof();
  state.counters["newton_iters"] =
      benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
  state.counters["factorizations"] =
      benchmark::Counter(static_cast<double>(factorizations), benchmark::Counter::kAvgIterations);
}

// Sizes 0..largest (SimplicialLDLT at 10⁵ tetrahedra takes minutes per step: not run).
#define GEOMINT_STEP_BENCH(label, method, largest)               \
  BENCHMARK_CAPTURE(BM_ImplicitStep, label, std::string(method)) \
      ->DenseRange(0, largest)                                   \
      ->Unit(benchmark::kMillisecond)                            \
      ->MeasureProcessCPUTime()                                  \
      ->Iterations(1)

GEOMINT_STEP_BENCH(hp_ldlt, "hp:linear_solver=ldlt", 1);
GEOMINT_STEP_BENCH(hp_cholmod, "hp:linear_solver=cholmod", 2);
GEOMINT_STEP_BENCH(hp_cholmod_modified, "hp:linear_solver=cholmod,modified_newton=true", 2);
GEOMINT_STEP_BENCH(hp_cg, "hp:linear_solver=cg", 2);
GEOMINT_STEP_BENCH(hp_cg_ichol, "hp:linear_solver=cg_ichol", 2);
GEOMINT_STEP_BENCH(hp_auto, "hp", 2);
GEOMINT_STEP_BENCH(implicit_euler_cholmod, "implicit_euler:linear_solver=cholmod", 2);
GEOMINT_STEP_BENCH(implicit_euler_cg, "implicit_euler:linear_solver=cg", 2);
GEOMINT_STEP_BENCH(implicit_euler_auto, "implicit_euler", 2);

}  // namespace

BENCHMARK_MAIN();
