// Steady-state implicit step of the elastic bar per linear solver and per method (issue 30; the
// table behind `linear_solver=auto` and paper claim 5 at scale, docs/PERF.md "Implicit step"):
// after one warm-up step (first factorisation or AMG set-up, symbolic analysis), the wall and CPU
// time of each further step of the same trajectory, at ~10³, 10⁴, 10⁵ and 10⁶ tetrahedra, with
// the process's peak resident set (getrusage ru_maxrss) when the benchmark ends.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <string>

#include "integrators/integrator.hpp"
#include "integrators/newton_profile.hpp"
#include "problems/parallel.hpp"
#include "problems/problem.hpp"

namespace {

// Cells nx × n × n, 6 tetrahedra each: 960, 9 984, 99 840 and 1 029 000 tetrahedra.
struct Size {
  int nx, n;
};
constexpr Size kSizes[] = {{10, 4}, {26, 8}, {65, 16}, {140, 35}};

// h = 0.011 at 10⁵ tetrahedra (the step of issue 30's measurement), scaled with the cell size so
// that every size takes the same number of steps per wave crossing a cell.
double step_size(int size) { return 0.011 * 16.0 / kSizes[size].n; }

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

void BM_Step(benchmark::State& state, const std::string& method) {
  const int size = static_cast<int>(state.range(0));
  const Size cells = kSizes[size];
  const auto problem =
      geomint::make_problem("elastic_bar:nx=" + std::to_string(cells.nx) +
                            ",ny=" + std::to_string(cells.n) + ",nz=" + std::to_string(cells.n));
  const auto integrator = geomint::make_integrator(method);
  geomint::State s = problem->initial_state();
  const double h = step_size(size);
  integrator->reset(*problem, s, h);
  geomint::StepStatus status = integrator->step(*problem, s, h);  // warm-up
  const geomint::Counters before = integrator->counters();
  const geomint::NewtonProfile profile_before = geomint::newton_profile();
  for (auto _ : state) {
    status = integrator->step(*problem, s, h);
    if (!status.ok) {
      state.SkipWithError(status.message.c_str());
      break;
    }
  }
  const geomint::Counters& after = integrator->counters();
  const auto per_step = [&](long geomint::Counters::*field) {
    return benchmark::Counter(static_cast<double>(after.*field - before.*field),
                              benchmark::Counter::kAvgIterations);
  };
  state.counters["tets"] = 6.0 * cells.nx * cells.n * cells.n;
  state.counters["dof"] = problem->dof();
  state.counters["newton_iters"] = per_step(&geomint::Counters::newton_iters);
  state.counters["factorizations"] = per_step(&geomint::Counters::factorizations);
  state.counters["hessian_evals"] = per_step(&geomint::Counters::hessian_evals);
  state.counters["peak_rss_mb"] = peak_rss_mb();
  // Where a step's time goes (integrators/newton.hpp NewtonProfile): CG iterations per step
  // (deterministic) and wall seconds per step of each phase of the Newton solves, which under
  // load are as unreliable as the step's wall time but show the shares.
  const geomint::NewtonProfile profile = geomint::newton_profile();
  const auto per_step_count = [&](long geomint::NewtonProfile::*field) {
    return benchmark::Counter(static_cast<double>(profile.*field - profile_before.*field),
                              benchmark::Counter::kAvgIterations);
  };
  const auto per_step_seconds = [&](double geomint::NewtonProfile::*field) {
    return benchmark::Counter(profile.*field - profile_before.*field,
                              benchmark::Counter::kAvgIterations);
  };
  state.counters["cg_iters"] = per_step_count(&geomint::NewtonProfile::cg_iterations);
  state.counters["residual_evals"] = per_step_count(&geomint::NewtonProfile::residuals);
  state.counters["energy_evals"] = per_step_count(&geomint::NewtonProfile::objectives);
  state.counters["s_newton"] = per_step_seconds(&geomint::NewtonProfile::total_s);
  state.counters["s_jacobian"] = per_step_seconds(&geomint::NewtonProfile::jacobian_s);
  state.counters["s_residual"] = per_step_seconds(&geomint::NewtonProfile::residual_s);
  state.counters["s_energy"] = per_step_seconds(&geomint::NewtonProfile::objective_s);
  state.counters["s_setup"] = per_step_seconds(&geomint::NewtonProfile::setup_s);
  state.counters["s_linear"] = per_step_seconds(&geomint::NewtonProfile::linear_s);
  state.counters["threads"] = geomint::thread_count();
}

// One benchmark per (method, sizes first..last); three timed steps, one at 10⁶ tetrahedra.
void sizes(benchmark::internal::Benchmark* b, int first, int last) {
  b->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();
  for (int size = first; size <= last; ++size) b->Arg(size);
}

#define GEOMINT_STEP(label, method, first, last)                                \
  BENCHMARK_CAPTURE(BM_Step, label, std::string(method))                        \
      ->Apply([](benchmark::internal::Benchmark* b) { sizes(b, first, last); }) \
      ->Iterations(3)

// Linear solvers on the HP midpoint step (hp:alpha=0.5, the minimiser): `auto`'s table.
// SimplicialLDLT takes minutes per step from 10⁵ tetrahedra, CHOLMOD's fill exceeds memory at 10⁶.
GEOMINT_STEP(hp_ldlt, "hp:alpha=0.5,linear_solver=ldlt", 0, 1);
GEOMINT_STEP(hp_cholmod, "hp:alpha=0.5,linear_solver=cholmod", 0, 2);
GEOMINT_STEP(hp_cg, "hp:alpha=0.5,linear_solver=cg", 0, 3);
GEOMINT_STEP(hp_cg_amg, "hp:alpha=0.5,linear_solver=cg_amg", 0, 3);
GEOMINT_STEP(hp_cg_modified, "hp:alpha=0.5,linear_solver=cg,modified_newton=true", 0, 3);
// Hessian reuse with the stronger preconditioners: fewer CG iterations, each dearer (docs/PERF.md
// "Blocked CG").
GEOMINT_STEP(hp_cg_ichol_modified, "hp:alpha=0.5,linear_solver=cg_ichol,modified_newton=true", 1,
             2);
GEOMINT_STEP(hp_cg_amg_modified, "hp:alpha=0.5,linear_solver=cg_amg,modified_newton=true", 1, 2);
GEOMINT_STEP(hp_auto, "hp:alpha=0.5", 0, 2);
// The DEL midpoint rule (root-finding Newton with the merit line search), for the DEL step's own
// same-run comparisons (docs/PERF.md "One step per method").
GEOMINT_STEP(del_auto, "del", 0, 2);
// Paper claim 5 at scale: minimiser, Newton on the momentum residual and implicit Euler with the
// same linear solver and the same stopping rule (tol 1e-12 relative, every method's default).
GEOMINT_STEP(hp_newton_cg_amg, "hp:alpha=0.5,solver=newton,linear_solver=cg_amg", 1, 3);
GEOMINT_STEP(implicit_euler_cg_amg, "implicit_euler:linear_solver=cg_amg", 1, 3);
GEOMINT_STEP(hp_newton_cg, "hp:alpha=0.5,solver=newton,linear_solver=cg", 1, 3);
GEOMINT_STEP(implicit_euler_cg, "implicit_euler:linear_solver=cg", 1, 3);

}  // namespace

BENCHMARK_MAIN();
