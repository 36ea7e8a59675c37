// Per-step cost of del and hp solved matrix-free (integrators/operator_del_solve.hpp) and of RK4,
// all on the O(n) articulated recursions, on the rope at n = 64, 256, 1024 at its default step and
// at h = 0.01 (docs/PERF.md "Articulated chains: DEL and HP in O(n)"); counters: tree passes and
// iterations per step.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "integrators/integrator.hpp"
#include "problems/articulated.hpp"
#include "problems/problem.hpp"

namespace {

// One step per benchmark iteration from the rope's initial state (restarted every 2000 steps, or
// 1000 at `fixed_h`, so that long runs time the same motion), at the problem's default step
// (0.25/n time units: the fastest mode resolved) or at `fixed_h`.
void run(benchmark::State& bench, const std::string& problem_name, const std::string& method,
         double fixed_h = 0) {
  const long n = bench.range(0);
  const auto problem = geomint::make_problem(problem_name + ":n=" + std::to_string(n));
  const auto& tree =
      dynamic_cast<const geomint::articulated::PlanarTreeLagrangian&>(*problem->as_lagrangian());
  const auto integrator = geomint::make_integrator(method);
  const double h = fixed_h > 0 ? fixed_h : problem->default_dt();
  geomint::State state = problem->initial_state();
  integrator->reset(*problem, state, h);
  // At h = 0.01 the 256-link rope's DEL step itself (dense Newton too) has no solution near v₀
  // from t ≈ 14.8 on (docs/METHODS.md "Articulated bodies"): restart before.
  const long restart = fixed_h > 0 ? 1000 : 2000;
  const long passes_before = tree.dynamics().passes();
  long steps = 0;
  for (auto _ : bench) {
    if (steps % restart == restart - 1) state = problem->initial_state();
    const geomint::StepStatus status = integrator->step(*problem, state, h);
    if (!status.ok) {
      bench.SkipWithError(status.message.c_str());
      break;
    }
    ++steps;
    benchmark::DoNotOptimize(state.q.data());
  }
  const double per_step = steps > 0 ? 1.0 / static_cast<double>(steps) : 0.0;
  bench.counters["passes_per_step"] =
      static_cast<double>(tree.dynamics().passes() - passes_before) * per_step;
  bench.counters["iterations_per_step"] =
      static_cast<double>(integrator->counters().newton_iters) * per_step;
  bench.counters["links"] = static_cast<double>(n);
}

void BM_RopeDel(benchmark::State& s) { run(s, "rope", "del"); }
void BM_RopeHp(benchmark::State& s) { run(s, "rope", "hp"); }
void BM_RopeDelNewtonKrylov(benchmark::State& s) { run(s, "rope", "del:solve=newton_krylov"); }
void BM_RopeRk4(benchmark::State& s) { run(s, "rope", "rk4"); }
// h = 0.01, 25 times the default step at 256 links (hω ≈ 10): the stiff case of the solve.
void BM_RopeDelCoarse(benchmark::State& s) { run(s, "rope", "del", 0.01); }
void BM_RopeDelNewtonKrylovCoarse(benchmark::State& s) {
  run(s, "rope", "del:solve=newton_krylov", 0.01);
}

constexpr auto kUnit = benchmark::kMicrosecond;
BENCHMARK(BM_RopeDel)->Arg(64)->Arg(256)->Arg(1024)->Unit(kUnit);
BENCHMARK(BM_RopeHp)->Arg(64)->Arg(256)->Arg(1024)->Unit(kUnit);
BENCHMARK(BM_RopeDelNewtonKrylov)->Arg(64)->Arg(256)->Arg(1024)->Unit(kUnit);
BENCHMARK(BM_RopeRk4)->Arg(64)->Arg(256)->Arg(1024)->Unit(kUnit);
BENCHMARK(BM_RopeDelCoarse)->Arg(256)->Unit(kUnit);
BENCHMARK(BM_RopeDelNewtonKrylovCoarse)->Arg(256)->Unit(kUnit);

}  // namespace

BENCHMARK_MAIN();
