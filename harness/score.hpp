// `geomint score`: the metrics of a trajectory another program wrote (CSV or .npy), computed by the
// same observers as `geomint run` (docs/USAGE.md "Scoring a trajectory from another program"), so
// that an integrator geomint cannot link gets the same checks.
#pragma once

#include <string>
#include <vector>

#include "harness/order.hpp"
#include "harness/record.hpp"
#include "problems/problem.hpp"

namespace geomint {

// The first row must be the problem's initial state: every component of (t, q, p) within
// start_tol · max(1, |initial value|) of it (`--start-tol`). 1e-9 admits a state written with
// %.10g or converted from velocities through the mass, and refuses a trajectory of another
// problem or another initial condition.
constexpr double kDefaultStartTolerance = 1e-9;

struct Trajectory {
  std::string path;
  std::vector<State> states;  // canonical (q, p); at least two, t strictly increasing
};

// Reads and validates one trajectory for `problem` (docs/USAGE.md for the formats): CSV with a
// header t,q0..,p0.. (or v0.., or geomint's own series with q_0.., p_0..), or .npy (2-D '<f8',
// C order, columns t, q, then p, or v when `npy_velocities`). Velocities become momenta through
// the problem's mass, or p = ∂L/∂v for a general Lagrangian. InputError naming the file and the
// first bad line or row and column.
Trajectory read_trajectory(const std::string& path, const Problem& problem, double start_tol,
                           bool npy_velocities = false);

// The optional metrics (`--metric`) a trajectory alone can give: those that read no method.
const std::vector<std::string>& score_optional_metrics();
// One message per unknown or method-bound name in `names`.
std::vector<std::string> score_metric_errors(const std::vector<std::string>& names);

struct ScoreConfig {
  // As RunConfig::reference_dir: problems without an exact solution are compared against
  // <reference_dir>/<problem>.csv when it has a row at the trajectory's last time.
  std::string reference_dir = "results/references";
  std::vector<std::string> extra_metrics;  // from score_optional_metrics()
};

// The run record of the trajectory: metrics by the observers of `geomint run` (energy error and
// drift, momenta, Casimir, constraint residuals, error against the exact solution or reference,
// phase and period), method = the file's path, dt = the first step, t_end = t_last − t_0.
RunRecord score_trajectory(const Problem& problem, const Trajectory& trajectory,
                           const ScoreConfig& config);

// The convergence order over trajectories at successively smaller steps (`--order`), fitted like
// order_study: error_final where every record has it (exact solution or reference), otherwise
// the final-state difference to the finest trajectory. InputError when fewer than
// kMinOrderLevels trajectories are given, their first steps do not decrease or their last times
// differ.
OrderFit score_order(const Problem& problem, const std::vector<Trajectory>& trajectories,
                     const std::vector<RunRecord>& records);

}  // namespace geomint
