// Reference generator (see reference_generator.hpp): Gauss–Legendre s = 3 (GNI Table II.1.2; the
// tableau of integrators/high_order_coefficients.hpp, checked there in long double) in long double.
#include "harness/reference_generator.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "harness/paths.hpp"
#include "harness/run_spec.hpp"
#include "harness/table.hpp"
#include "integrators/high_order_coefficients.hpp"
#include "problems/lagrangian.hpp"
#include "problems/mass_operator.hpp"
#include "problems/structures/time_dependent.hpp"

namespace geomint {
namespace {

using Real = long double;
using VecL = Eigen::Matrix<Real, Eigen::Dynamic, 1>;

constexpr int kStages = 3;
static_assert(coefficients::kGauss3.stages == kStages);
constexpr int kMaxStageIterations = 100;

// The first-order field f(t, y) with y = (q, p) in long double. q' = M⁻¹p is formed in long
// double; p' = −∇V(q) + F comes from the problem in double (problems offer only double), so each
// force evaluation carries a relative rounding error of ~1e-16. The time stepping, the stage
// iteration and the accumulation of the state are long double.
class Field {
 public:
  explicit Field(const Problem& problem)
      : problem_(problem),
        dof_(problem.dof()),
        // A time-dependent H(q, p, t) has q' = ∂T/∂p(p, t), not M⁻¹p: its own, like the general
        // kind's.
        non_separable_(problem.kind() == ProblemKind::kLagrangian ||
                       problem.as<TimeDependentHamiltonian>() != nullptr) {
    // Only the separable kind has a constant diagonal mass (the operator throws on the others).
    if (!non_separable_)
      inverse_mass_ = MassOperator(problem).constant_inverse_diagonal().cast<Real>();
  }
  void operator()(Real t, const VecL& y, VecL& ydot) {
    y_double_ = y.cast<double>();
    problem_.first_order_rhs(static_cast<double>(t), y_double_, ydot_double_);
    ydot.resize(2 * dof_);
    // The general kind has a position-dependent mass: q' = v(q, p) = M(q)⁻¹(p − a(q)) comes
    // from the problem's Hamilton equations, in double like the forces (it has no constant M⁻¹).
    if (non_separable_) {
      ydot.head(dof_) = ydot_double_.head(dof_).cast<Real>();
    } else {
      ydot.head(dof_) = inverse_mass_.cwiseProduct(y.tail(dof_));
    }
    ydot.tail(dof_) = ydot_double_.tail(dof_).cast<Real>();
    ++evaluations;
  }
  long evaluations = 0;

 private:
  const Problem& problem_;
  int dof_;
  bool non_separable_;
  VecL inverse_mass_;
  Vec y_double_, ydot_double_;
};

// Fixed-step Gauss s = 3 with fixed-point stage iteration (the reference problems are not stiff
// at the reference step) and a Kahan-compensated state update.
class GaussIntegrator {
 public:
  explicit GaussIntegrator(const Problem& problem) : field_(problem), n_(2 * problem.dof()) {
    for (auto& z : z_) z = VecL::Zero(n_);
    for (auto& f : f_) f = VecL::Zero(n_);
    compensation_ = VecL::Zero(n_);
  }

  // Advances (t, y) by h; throws InputError if the stage iteration does not converge.
  void step(Real t, VecL& y, Real h) {
    // The iteration starts from the previous step's stage increments Z_i = Y_i − y (zero at the
    // first step): a smooth solution changes little from one step to the next.
    Real previous_change = std::numeric_limits<Real>::infinity();
    bool converged = false;
    for (int iteration = 0; iteration < kMaxStageIterations && !converged; ++iteration) {
      for (int i = 0; i < kStages; ++i) {
        stage_ = y + z_[i];
        field_(t + table_.c[i] * h, stage_, f_[i]);
      }
      Real change = 0, scale = 0;
      for (int i = 0; i < kStages; ++i) {
        next_z_ = VecL::Zero(n_);
        for (int j = 0; j < kStages; ++j) next_z_ += (h * table_.a[i][j]) * f_[j];
        change = std::max(change, (next_z_ - z_[i]).template lpNorm<Eigen::Infinity>());
        scale = std::max(scale, next_z_.template lpNorm<Eigen::Infinity>());
        z_[i] = next_z_;
      }
      // Converged when the increments stop changing, or stagnate at the round-off floor of the
      // double force evaluations (~1e-16 of the increment).
      converged = change <= 1e-18L * scale ||
                  (iteration >= 2 && change >= previous_change && change <= 1e-12L * scale);
      previous_change = change;
    }
    if (!converged) {
      throw InputError(
          fmt::format("reference: Gauss stage iteration did not converge at t={} with dt={}; "
                      "pass a smaller --dt",
                      static_cast<double>(t), static_cast<double>(h)));
    }
    // The slopes f_ are those of the last iterate but one; they differ from the slopes at z_ by
    // L·change, at the round-off floor once converged.
    increment_ = VecL::Zero(n_);
    for (int i = 0; i < kStages; ++i) increment_ += (h * table_.b[i]) * f_[i];
    // Kahan summation: y += increment, carrying the low-order bits lost in the addition.
    for (int k = 0; k < n_; ++k) {
      const Real corrected = increment_[k] - compensation_[k];
      const Real sum = y[k] + corrected;
      compensation_[k] = (sum - y[k]) - corrected;
      y[k] = sum;
    }
  }
  long evaluations() const { return field_.evaluations; }

 private:
  Field field_;
  const coefficients::PartitionedTableau& table_ = coefficients::kGauss3;  // â = a for Gauss
  int n_;
  VecL z_[kStages], f_[kStages], next_z_, stage_, increment_, compensation_;
};

// One run from the initial state; returns y at each output time (steps_per_output steps apart).
std::vector<VecL> run_gauss(const Problem& problem, Real output_every, long outputs,
                            long steps_per_output, long& steps) {
  const State initial = problem.initial_state();
  const int dof = problem.dof();
  VecL y(2 * dof);
  y.head(dof) = initial.q.cast<Real>();
  y.tail(dof) = initial.p.cast<Real>();
  const Real t0 = initial.t;
  const Real h = output_every / static_cast<Real>(steps_per_output);
  GaussIntegrator gauss(problem);
  std::vector<VecL> out;
  steps = 0;
  for (long k = 1; k <= outputs; ++k) {
    for (long s = 0; s < steps_per_output; ++s) {
      const Real t = t0 + static_cast<Real>((k - 1) * steps_per_output + s) * h;
      gauss.step(t, y, h);
      ++steps;
    }
    if (!y.allFinite()) {
      throw InputError(fmt::format("reference: non-finite state at t={}; pass a smaller --dt",
                                   static_cast<double>(t0 + k * output_every)));
    }
    out.push_back(y);
  }
  return out;
}

std::string number17(double value) { return fmt::format("{:.17g}", value); }

}  // namespace

ReferenceSummary generate_reference(const ReferenceOptions& options) {
  const auto problem = parse_problem(options.problem_spec);
  if (problem->has(kFirstOrderOnly)) {
    // The generator integrates (q, p) with ∇V; a first-order problem carries its reference instead.
    throw InputError(fmt::format(
        "reference: problem '{}' is a first-order ODE y' = f(t, y) without a potential; the "
        "generator integrates Lagrangian systems only{}",
        problem->name(),
        problem->has(kEndReference) ? " (this one carries its own reference at its end time)"
                                    : ""));
  }
  if (problem->has(kConstraints)) {
    // Its Gauss step integrates q' = v, p' = −∇V: the constraint forces would be missing.
    throw InputError(fmt::format(
        "reference: problem '{}' has holonomic constraints, which the generator (unconstrained "
        "Gauss collocation) does not enforce; generate the reference of an unconstrained "
        "formulation instead (e.g. coordinates=joint or coordinates=angles)",
        problem->name()));
  }
  if (!(options.t_end > 0 && std::isfinite(options.t_end))) {
    throw InputError(fmt::format("--t-end must be a finite number > 0 (got {})", options.t_end));
  }
  const double dt_wanted = options.dt > 0 ? options.dt : problem->default_dt() / 8;
  if (!(dt_wanted > 0 && std::isfinite(dt_wanted)) || options.dt < 0) {
    throw InputError(fmt::format("--dt must be a finite number > 0 (got {})", options.dt));
  }
  const double every = options.output_every > 0 ? options.output_every : options.t_end / 100;
  const double ratio = options.t_end / every;
  const long outputs = std::lround(ratio);
  if (!(options.output_every >= 0) || !(ratio <= kMaxReferenceRows) || outputs < 1 ||
      std::abs(ratio - static_cast<double>(outputs)) > 1e-9 * ratio) {
    throw InputError(
        fmt::format("--every must divide --t-end into a whole number of outputs, at most {:g} "
                    "(got --every {} for --t-end {})",
                    kMaxReferenceRows, every, options.t_end));
  }
  // An even number of steps per output, so the check run at 2·dt lands on the same times.
  long steps_per_output = static_cast<long>(std::ceil(every / dt_wanted - 1e-9));
  steps_per_output += steps_per_output % 2;
  if (static_cast<double>(steps_per_output) * static_cast<double>(outputs) > 1e10) {
    throw InputError(fmt::format("--t-end/--dt = {:g} steps is more than the allowed 1e10",
                                 static_cast<double>(steps_per_output) * outputs));
  }

  ReferenceSummary summary;
  summary.path =
      options.out_path.empty() ? reference_path(kReferenceDir, *problem) : options.out_path;
  check_output_file(summary.path, options.out_path.empty() ? "reference file" : "--out");
  const auto start = std::chrono::steady_clock::now();
  long check_steps = 0;
  const std::vector<VecL> fine =
      run_gauss(*problem, every, outputs, steps_per_output, summary.steps);
  const std::vector<VecL> check =
      run_gauss(*problem, every, outputs, steps_per_output / 2, check_steps);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.dt = every / static_cast<double>(steps_per_output);
  for (long k = 0; k < outputs; ++k) {
    const double difference = static_cast<double>((fine[k] - check[k]).norm());
    summary.estimated_error_max = std::max(summary.estimated_error_max, difference);
    if (k == outputs - 1) summary.estimated_error_final = difference;
  }

  const int dof = problem->dof();
  std::vector<std::string> columns = {"t"};
  for (int i = 0; i < dof; ++i) columns.push_back(fmt::format("q_{}", i));
  for (int i = 0; i < dof; ++i) columns.push_back(fmt::format("p_{}", i));
  std::vector<Row> rows;
  const State initial = problem->initial_state();
  auto add_row = [&](double t, const VecL& y) {
    Row row;
    row["t"] = number17(t);
    for (int i = 0; i < 2 * dof; ++i) row[columns[1 + i]] = number17(static_cast<double>(y[i]));
    rows.push_back(std::move(row));
  };
  VecL y0(2 * dof);
  y0.head(dof) = initial.q.cast<Real>();
  y0.tail(dof) = initial.p.cast<Real>();
  add_row(initial.t, y0);
  for (long k = 0; k < outputs; ++k) {
    const double t = k == outputs - 1 ? initial.t + options.t_end
                                      : initial.t + static_cast<double>(k + 1) * every;
    add_row(t, fine[k]);
  }

  auto lines = provenance(options.command_line);
  lines.emplace_back("reference_problem", problem->spec());
  lines.emplace_back("reference_method",
                     "Gauss-Legendre collocation s=3 (order 6), long double state, "
                     "Kahan-compensated update, fixed-point stage iteration; forces in double");
  lines.emplace_back("reference_dt", number17(summary.dt));
  lines.emplace_back("reference_check_dt", number17(2 * summary.dt));
  lines.emplace_back("reference_steps", std::to_string(summary.steps));
  lines.emplace_back("estimated_error_final", fmt::format("{:.3g}", summary.estimated_error_final));
  lines.emplace_back("estimated_error_max", fmt::format("{:.3g}", summary.estimated_error_max));
  lines.emplace_back("estimated_error_definition",
                     "2-norm of (q, p) between the run at dt and the check run at 2*dt (an upper "
                     "estimate: the order-6 error at dt is ~1/64 of it), max over the rows");
  write_file_atomic(summary.path, to_csv(rows, columns, lines));
  return summary;
}

}  // namespace geomint
