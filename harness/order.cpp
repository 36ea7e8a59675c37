// Order fit with plateau rejection and the dt-ladder study (see order.hpp).
#include "harness/order.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "harness/metrics.hpp"
#include "harness/observers.hpp"
#include "harness/reference.hpp"

namespace geomint {
namespace {

double local_slope(const std::vector<double>& dts, const std::vector<double>& errors, int a,
                   int b) {
  return std::log(errors[a] / errors[b]) / std::log(dts[a] / dts[b]);
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// |λ̄ − λ(t_N − h/2)|∞ for the method's discrete multiplier λ̄ = (start + end)/h, the mean
// constraint force of its last step, which is second order about the step's midpoint and only
// first order at either end (measured, docs/METHOD.md §3); methods without impulses fall back to
// the state's multiplier λ(q_N, p_N) against λ(t_N).
double multiplier_error(const Problem& problem, const RunResult& run, OrderStudy& study) {
  const State& end = run.final_state;
  const HolonomicConstraints& constraints = constraints_of(problem);
  if (run.final_impulses) {
    const ConstraintImpulses& impulses = *run.final_impulses;
    const Vec exact = *constraints.exact_multipliers(end.t - impulses.h / 2);
    return (impulses.mean_multiplier() - exact).lpNorm<Eigen::Infinity>();
  }
  study.multiplier_from_state = true;
  const Vec exact = *constraints.exact_multipliers(end.t);
  return (problem.multipliers(end.t, end.q, end.p) - exact).lpNorm<Eigen::Infinity>();
}

}  // namespace

OrderFit fit_order(const std::vector<double>& dts, const std::vector<double>& errors,
                   double plateau_floor, double error_ceiling) {
  OrderFit fit;
  fit.order = std::numeric_limits<double>::quiet_NaN();
  std::vector<int> points;
  int failed = 0, plateau = 0, too_large = 0;
  for (int i = 0; i < static_cast<int>(dts.size()); ++i) {
    if (!std::isfinite(errors[i]) || errors[i] <= 0) {
      ++failed;
    } else if (errors[i] > error_ceiling) {
      ++too_large;
    } else if (errors[i] < plateau_floor) {
      ++plateau;
    } else {
      points.push_back(i);
    }
  }
  // Round-off plateau at small dt: the error stops decreasing (local slope below a third of the
  // typical one), so drop trailing points until it decreases again.
  auto slopes_of = [&](const std::vector<int>& idx) {
    std::vector<double> slopes;
    for (size_t j = 1; j < idx.size(); ++j) {
      slopes.push_back(local_slope(dts, errors, idx[j - 1], idx[j]));
    }
    return slopes;
  };
  while (points.size() > 3) {
    const auto slopes = slopes_of(points);
    if (slopes.back() < median(slopes) / 3) {
      points.pop_back();
      ++plateau;
    } else {
      break;
    }
  }
  // Pre-asymptotic points at large dt: drop leading points whose local slope differs from the
  // median of the remaining ones by more than 0.25.
  int preasymptotic = 0;
  while (points.size() > 3) {
    const auto slopes = slopes_of(points);
    const std::vector<double> rest(slopes.begin() + 1, slopes.end());
    if (std::abs(slopes.front() - median(rest)) > 0.25) {
      points.erase(points.begin());
      ++preasymptotic;
    } else {
      break;
    }
  }
  std::vector<std::string> notes;
  if (failed) notes.push_back(fmt::format("{} failed", failed));
  if (too_large) {
    notes.push_back(fmt::format("{} with error above {:.3g}, not small against the solution",
                                too_large, error_ceiling));
  }
  if (plateau) notes.push_back(fmt::format("{} on round-off plateau", plateau));
  if (preasymptotic) notes.push_back(fmt::format("{} pre-asymptotic", preasymptotic));
  if (points.size() < 3) {
    notes.push_back(fmt::format("only {} usable points (need 3)", points.size()));
  } else {
    std::vector<double> log_dt, log_error;
    for (int i : points) {
      log_dt.push_back(std::log(dts[i]));
      log_error.push_back(std::log(errors[i]));
    }
    fit.order = least_squares_slope(log_dt, log_error);
    fit.used = points;
  }
  fit.note = fmt::format("{}", fmt::join(notes, "; "));
  return fit;
}

std::vector<std::string> order_study_errors(const Problem& problem, const MethodFactory& method,
                                            double dt0, long levels, double t_end) {
  std::vector<std::string> errors;
  const bool levels_ok = levels >= kMinOrderLevels && levels <= kMaxOrderLevels;
  if (!levels_ok) {
    errors.push_back(fmt::format("--levels must be in {}..{} (got {})", kMinOrderLevels,
                                 kMaxOrderLevels, levels));
  }
  const bool dt0_ok = dt0 > 0 && std::isfinite(dt0);
  if (!dt0_ok) errors.push_back(fmt::format("--dt must be a finite number > 0 (got {})", dt0));
  // The finest level's grid, once its step is known; its own --dt message would repeat the one
  // above.
  RunConfig finest;
  finest.dt = dt0_ok && levels_ok ? dt0 * std::ldexp(1.0, -static_cast<int>(levels - 1)) : 1.0;
  finest.t_end = t_end;
  for (std::string& error : run_config_errors(finest, method.adaptive())) {
    errors.push_back(std::move(error));
  }
  if (const Applicability fit = applicable(method.prototype(), problem); !fit.ok) {
    errors.push_back(fit.reason);
  }
  return errors;
}

OrderStudy order_study(const std::shared_ptr<const Problem>& problem, const MethodFactory& method,
                       double dt0, int levels, double t_end, double diverge_factor) {
  throw_input_errors(order_study_errors(*problem, method, dt0, levels, t_end));
  OrderStudy study;
  std::vector<double> dts, errors;
  bool exact = true;
  for (int k = 0; k < levels; ++k) {
    RunConfig config;
    config.dt = dt0 * std::ldexp(1.0, -k);
    config.t_end = t_end;
    config.timing_repeats = 0;
    config.diverge_factor = diverge_factor;
    RunResult result = run_one(RunSpec{problem, method, config});
    exact = result.record.metrics.count(metric::error_final.key()) > 0;
    dts.push_back(config.dt);
    result.record.order_level = k;
    study.runs.push_back(std::move(result));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> errors_q, errors_p, errors_multiplier;
  const HolonomicConstraints* constraints = problem->as_constrained();
  study.multiplier_applies = constraints != nullptr &&
                             constraints->exact_multipliers(problem->initial_state().t).has_value();
  // What error_final was measured against: the exact solution, or the reference file the run
  // found (car_axis: the Test Set's values); without either, the finest level
  // (Richardson-style self-convergence).
  std::shared_ptr<const ReferenceSolution> reference_file;
  if (exact && !problem->has(kExact)) {
    reference_file = load_reference(reference_path(RunConfig{}.reference_dir, *problem), *problem);
  }
  const auto reference_at = [&](double t) -> State {
    if (!exact) return study.runs.back().final_state;
    if (!reference_file) return problem->exact(t);
    const int row = reference_file->row_at(t);  // error_final exists, so the row does
    if (row < 0) return {t, Vec::Constant(problem->dof(), nan), Vec::Constant(problem->dof(), nan)};
    return {t, reference_file->q[row], reference_file->p[row]};
  };
  // The solution's own scale, against which an error must be small to be asymptotic: the
  // larger of ‖(q, p)‖ at the start and at t_end (a decaying solution keeps its initial scale).
  const State initial = problem->initial_state();
  double state_scale = std::sqrt(initial.q.squaredNorm() + initial.p.squaredNorm());
  double multiplier_scale = 0;
  for (const auto& run : study.runs) {
    double error = nan, error_q = nan, error_p = nan, error_multiplier = nan;
    if (run.ok) {
      const State reference = reference_at(run.final_state.t);
      if (reference.q.allFinite() && reference.p.allFinite()) {
        state_scale =
            std::max(state_scale, std::sqrt(reference.q.squaredNorm() + reference.p.squaredNorm()));
      }
      if (study.multiplier_applies) {
        multiplier_scale =
            std::max(multiplier_scale,
                     constraints->exact_multipliers(run.final_state.t)->lpNorm<Eigen::Infinity>());
      }
      const double q_squared = (run.final_state.q - reference.q).squaredNorm();
      const double p_squared = (run.final_state.p - reference.p).squaredNorm();
      error_q = std::sqrt(q_squared);
      error_p = std::sqrt(p_squared);
      error = exact ? run.record.metrics.at(metric::error_final.key())
                    : std::sqrt(q_squared + p_squared);
      if (study.multiplier_applies) error_multiplier = multiplier_error(*problem, run, study);
    }
    errors.push_back(error);
    errors_q.push_back(error_q);
    errors_p.push_back(error_p);
    errors_multiplier.push_back(error_multiplier);
  }
  if (!exact) {
    // The finest level is the reference, so it has no error of its own.
    errors.back() = errors_q.back() = errors_p.back() = nan;
  }
  constexpr double kPlateau = 1e-13;
  const double ceiling = kAsymptoticErrorFraction * state_scale;
  study.fit_q = fit_order(dts, errors_q, kPlateau, ceiling);
  study.fit_p = fit_order(dts, errors_p, kPlateau, ceiling);
  if (study.multiplier_applies) {
    study.fit_multiplier =
        fit_order(dts, errors_multiplier, kPlateau, kAsymptoticErrorFraction * multiplier_scale);
  }
  study.fit = fit_order(dts, errors, kPlateau, ceiling);
  OrderRecord& record = study.record;
  record.problem = study.runs.front().record.problem;
  record.method = study.runs.front().record.method;
  record.ran = true;
  record.t_end = t_end;
  if (std::isfinite(study.fit.order)) record.order = study.fit.order;
  if (std::isfinite(study.fit_q.order)) record.order_q = study.fit_q.order;
  if (std::isfinite(study.fit_p.order)) record.order_p = study.fit_p.order;
  record.multiplier_applies = study.multiplier_applies;
  if (std::isfinite(study.fit_multiplier.order)) {
    record.order_multiplier = study.fit_multiplier.order;
  }
  record.declared_order = method.info().order;
  for (int i : study.fit.used) record.points_used.push_back(dts[i]);
  record.status = std::isfinite(study.fit.order) ? "ok" : "no_fit";
  std::string note = study.fit.note;
  if (!exact) note += std::string(note.empty() ? "" : "; ") + "error vs finest level";
  const auto add_note = [&note](const std::string& text) {
    note += (note.empty() ? "" : "; ") + text;
  };
  if (study.multiplier_applies && study.multiplier_from_state) {
    add_note("multiplier from (q, p): the method exposes none");
  }
  if (study.multiplier_applies && !std::isfinite(study.fit_multiplier.order)) {
    add_note("no multiplier fit: " + study.fit_multiplier.note);
  }
  if (!note.empty()) record.message = note;
  return study;
}

ResultTable ladder_table(const OrderStudy& study,
                         const std::vector<std::pair<std::string, std::string>>& lines) {
  std::vector<RunRecord> records;
  for (const auto& level : study.runs) records.push_back(level.record);
  return record_table("ladder", records, lines);
}

}  // namespace geomint
