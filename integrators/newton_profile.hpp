// Where the time of the Newton solves goes (issue 30 item 1): process-wide totals kept by
// integrators/newton.cpp, for the benchmarks to report per step (bench/bench_elastic_step.cpp).
#pragma once

namespace geomint {

// Totals over every NewtonSolver::solve since the program started (all threads): the work the
// per-run Counters do not carry (CG iterations; Counters are the committed tables' columns) and
// the wall time of each phase. The phases nest in `total_s`: residual (R), objective (E, in the
// line search), jacobian (J), setup (factorisation or preconditioner set-up), linear
// (back-substitution or CG).
struct NewtonProfile {
  long solves = 0, iterations = 0, cg_iterations = 0, residuals = 0, objectives = 0, jacobians = 0,
       linear_solves = 0;
  double total_s = 0, residual_s = 0, objective_s = 0, jacobian_s = 0, setup_s = 0, linear_s = 0;
};

NewtonProfile newton_profile();

}  // namespace geomint
