// Linear-stability search and the predicted limits (see stability.hpp; docs/METHOD.md §7).
#include "harness/stability.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "harness/run_spec.hpp"
#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"

namespace geomint {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTwoPi = 6.283185307179586;

struct Search {
  const Problem& problem;
  const MethodFactory& method;
  const StabilityOptions& options;
  double horizon;
  long runs = 0;

  // One run of the criterion at step h.
  bool stable(double h, std::string* reason) {
    ++runs;
    auto integrator = method.make();
    State state = problem.initial_state();
    const double energy0 = problem.energy(state.q, state.p);
    const double bound = options.growth * std::max(std::abs(energy0), 1e-300);
    const long steps =
        std::max(options.min_steps, static_cast<long>(std::ceil(horizon / h - 1e-9)));
    integrator->reset(problem, state, h);
    for (long k = 0; k < steps; ++k) {
      const StepStatus status = integrator->step(problem, state, h);
      if (!status.ok) {
        if (reason) *reason = status.reason;
        return false;
      }
      if (!state.q.allFinite() || !state.p.allFinite()) {
        if (reason) *reason = "nan";
        return false;
      }
      const double energy = problem.energy(state.q, state.p);
      if (!(std::abs(energy) <= bound)) {
        if (reason) *reason = std::isfinite(energy) ? "growth" : "nan";
        return false;
      }
    }
    return true;
  }
};

// ω of the problem's fastest mode at its initial state, or NaN when it does not say.
double problem_omega(const Problem& problem) {
  if (!problem.has(kOmegaMax)) return kNaN;
  return problem.omega_max(problem.initial_state().q);
}

// Horizon of each run and the search range in h, from the options and ω.
void resolve(const Problem& problem, const StabilityOptions& options, double* horizon, double* h_lo,
             double* h_hi) {
  const double omega = problem_omega(problem);
  const bool in_h = options.h_min > 0;
  if (!in_h && !(omega > 0)) {
    throw InputError(fmt::format(
        "problem '{}' has no omega_max: give the search range as h_min/h_max instead of "
        "homega_min/homega_max",
        problem.spec()));
  }
  if (options.t_end <= 0 && !(omega > 0)) {
    throw InputError(
        fmt::format("problem '{}' has no omega_max: give the horizon as t_end instead of periods",
                    problem.spec()));
  }
  *horizon = options.t_end > 0 ? options.t_end : options.periods * kTwoPi / omega;
  *h_lo = in_h ? options.h_min : options.homega_min / omega;
  *h_hi = in_h ? options.h_max : options.homega_max / omega;
}

}  // namespace

double predicted_homega_limit(const MethodFactory& method) {
  return method.prototype().predicted_linear_stability().homega_limit;
}

void validate_stability_options(const StabilityOptions& options, const std::string& where) {
  auto positive = [&](double value, const char* key) {
    if (!(value > 0) || !std::isfinite(value)) {
      throw InputError(
          fmt::format("{}: '{}' must be a finite number > 0 (got {})", where, key, value));
    }
  };
  if (options.h_min > 0 || options.h_max > 0) {
    positive(options.h_min, "h_min");
    positive(options.h_max, "h_max");
    if (!(options.h_max > options.h_min))
      throw InputError(fmt::format("{}: 'h_max' must be larger than 'h_min'", where));
  } else {
    positive(options.homega_min, "homega_min");
    positive(options.homega_max, "homega_max");
    if (!(options.homega_max > options.homega_min))
      throw InputError(fmt::format("{}: 'homega_max' must be larger than 'homega_min'", where));
  }
  if (options.t_end > 0) {
    positive(options.t_end, "t_end");
  } else {
    positive(options.periods, "periods");
  }
  positive(options.growth, "growth");
  if (!(options.growth > 1))
    throw InputError(fmt::format("{}: 'growth' must be > 1 (got {})", where, options.growth));
  if (options.min_steps < 1 || options.min_steps > kMaxStabilityStepsPerRun)
    throw InputError(
        fmt::format("{}: 'min_steps' must be in 1..{}", where, kMaxStabilityStepsPerRun));
  if (options.scan_points_per_decade < 1 || options.scan_points_per_decade > 100)
    throw InputError(fmt::format("{}: 'scan_points_per_decade' must be in 1..100", where));
  if (!(options.rel_tol > 0 && options.rel_tol < 1))
    throw InputError(fmt::format("{}: 'rel_tol' must be in (0, 1)", where));
}

void check_stability_budget(const Problem& problem, const std::string& problem_spec,
                            const StabilityOptions& options, const std::string& where) {
  double horizon = 0, h_lo = 0, h_hi = 0;
  try {
    resolve(problem, options, &horizon, &h_lo, &h_hi);
  } catch (const InputError& error) {
    throw InputError(fmt::format("{}: {}", where, error.what()));
  }
  const bool in_h = options.h_min > 0;
  const double steps = std::max(static_cast<double>(options.min_steps), horizon / h_lo);
  if (!(steps <= static_cast<double>(kMaxStabilityStepsPerRun))) {
    throw InputError(fmt::format(
        "{}: problem '{}': {} = {:g} with a horizon of {:g} gives {:g} steps per run, more than "
        "the allowed {}: raise {} or shorten {}",
        where, problem_spec, in_h ? "h_min" : "homega_min",
        in_h ? options.h_min : options.homega_min, horizon, steps, kMaxStabilityStepsPerRun,
        in_h ? "h_min" : "homega_min", options.t_end > 0 ? "t_end" : "periods"));
  }
  const double points = std::log10(h_hi / h_lo) * options.scan_points_per_decade + 1;
  if (!(points <= kMaxStabilityScanPoints)) {
    throw InputError(fmt::format(
        "{}: problem '{}': the scan from {} to {} at {} points per decade has {:g} points, more "
        "than the allowed {}",
        where, problem_spec, in_h ? "h_min" : "homega_min", in_h ? "h_max" : "homega_max",
        options.scan_points_per_decade, std::ceil(points), kMaxStabilityScanPoints));
  }
}

StabilityResult stability_search(const Problem& problem_ref, const MethodFactory& method,
                                 const StabilityOptions& options) {
  const Problem* problem = &problem_ref;
  validate_stability_options(options, "stability");
  check_stability_budget(*problem, problem->spec(), options, "stability");
  const Integrator* integrator = &method.prototype();
  const MethodInfo& info = method.info();
  if (info.flags & kAdaptive) {
    throw InputError(fmt::format(
        "method '{}' is adaptive: a stability search needs a fixed-step method", info.name));
  }
  if (const Applicability fit = applicable(*integrator, *problem); !fit.ok) {
    throw InputError(fit.reason);
  }
  double horizon = 0, h_lo = 0, h_hi = 0;
  resolve(*problem, options, &horizon, &h_lo, &h_hi);
  const double omega = problem_omega(*problem);
  // Reported in h·ω when ω is known, in h otherwise.
  const double unit = omega > 0 ? omega : 1.0;
  // What runs (hp without solver= runs Newton on a non-separable problem): the row names it.
  const std::string ran_spec = spec_on(*integrator, *problem);
  Search search{*problem, method, options, horizon};

  // Geometric scan from the bottom of the range; the last point is h_hi itself.
  std::vector<double> grid;
  const double ratio = std::pow(10.0, 1.0 / options.scan_points_per_decade);
  for (double h = h_lo; h < h_hi * (1 - 1e-12); h *= ratio) grid.push_back(h);
  grid.push_back(h_hi);
  std::vector<bool> stable(grid.size());
  std::vector<std::string> reasons(grid.size());
  for (size_t i = 0; i < grid.size(); ++i) stable[i] = search.stable(grid[i], &reasons[i]);
  size_t first_unstable = grid.size();
  for (size_t i = 0; i < grid.size() && first_unstable == grid.size(); ++i) {
    if (!stable[i]) first_unstable = i;
  }

  StabilityResult result;
  std::string note;
  double limit = 0;
  if (first_unstable == grid.size()) {
    result.status = "stable_to_max";
    limit = h_hi;
  } else if (first_unstable == 0) {
    result.status = "unstable_at_min";
    note = "unstable at the bottom of the range (" + reasons[0] + ")";
  } else {
    result.status = "bracketed";
    double a = grid[first_unstable - 1], b = grid[first_unstable];
    std::string reason = reasons[first_unstable];
    while ((b - a) > options.rel_tol * a) {
      const double mid = std::sqrt(a * b);
      std::string why;
      if (search.stable(mid, &why)) {
        a = mid;
      } else {
        b = mid;
        reason = why;
      }
    }
    limit = a;
    note = "unstable above by " + reason;
  }
  for (size_t i = first_unstable + 1; i < grid.size(); ++i) {
    if (stable[i]) {
      note += fmt::format("{}stable again at h*omega = {:.4g}", note.empty() ? "" : "; ",
                          grid[i] * unit);
      break;
    }
  }
  result.homega_limit = limit * unit;
  result.predicted =
      problem->name() == "harmonic" ? integrator->predicted_linear_stability().homega_limit : kNaN;

  Row& row = result.row;
  row["problem"] = problem->spec();
  row["method"] = ran_spec;
  const Spec spec = Spec::parse(ran_spec);
  if (spec.values.count("alpha")) row["alpha"] = spec.values.at("alpha");
  row["omega"] = omega > 0 ? format_number(omega) : "";
  row["homega_lo"] = format_number(h_lo * unit);
  row["homega_hi"] = format_number(h_hi * unit);
  row["homega_max_measured"] = format_number(result.homega_limit);
  if (!std::isnan(result.predicted)) {
    row["predicted"] = format_number(result.predicted);
    if (std::isfinite(result.predicted) && result.predicted > 0 && result.status == "bracketed") {
      row["rel_diff"] = format_number(result.homega_limit / result.predicted - 1);
    }
  }
  row["status"] = result.status;
  if (!note.empty()) row["message"] = note;
  row["runs"] = std::to_string(search.runs);
  row["horizon"] = format_number(horizon);
  row["growth"] = format_number(options.growth);
  return result;
}

const std::vector<std::string>& stability_columns() {
  static const std::vector<std::string> columns = {
      "label",     "problem",   "method",    "alpha",
      "omega",     "homega_lo", "homega_hi", "homega_max_measured",
      "predicted", "rel_diff",  "status",    "message",
      "runs",      "horizon",   "growth"};
  return columns;
}

ColumnType stability_column_type(const std::string& name) {
  if (name == "runs") return ColumnType::kInteger;
  for (const char* real : {"alpha", "omega", "homega_lo", "homega_hi", "homega_max_measured",
                           "predicted", "rel_diff", "horizon", "growth"}) {
    if (name == real) return ColumnType::kReal;
  }
  return ColumnType::kText;
}

}  // namespace geomint
