// The run loop (see run.hpp): metric pass with observers at step points, then a timing pass.
#include "harness/run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "harness/chaos_metrics.hpp"
#include "harness/map_defect.hpp"
#include "harness/modified_energy.hpp"
#include "harness/observers.hpp"
#include "harness/paths.hpp"
#include "harness/reference.hpp"
#include "harness/run_spec.hpp"
#include "harness/structure_metrics.hpp"
#include "integrators/general_step.hpp"
#include "problems/articulated.hpp"
#include "problems/lagrangian.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

bool finite(const State& state) { return state.q.allFinite() && state.p.allFinite(); }

// Time series writer: t, energy, invariants, problem extras, then q and p. Rows are streamed to
// a temporary file as they are produced (a long series is never held in memory) and the file is
// renamed onto the series path by commit(); an abandoned writer removes its temporary file.
class SeriesWriter {
 public:
  SeriesWriter(const Problem& problem, const RunConfig& config, const std::string& method_spec)
      : config_(config), file_(config.series_path), out_(file_.stream()) {
    with_state_ = problem.dof() <= 64 || config.series_state;
    first_order_ = problem.has(kFirstOrderOnly);
    std::vector<std::string> columns = {"t"};
    if (!first_order_) columns.push_back("energy");
    if (problem.has(kLinearMomentum)) {
      const Vec momentum =
          problem.linear_momentum(problem.initial_state().q, problem.initial_state().p);
      for (int i = 0; i < momentum.size(); ++i) columns.push_back(fmt::format("momentum_{}", i));
    }
    if (problem.has(kAngularMomentum)) {
      const State s = problem.initial_state();
      const Vec angular = problem.angular_momentum(s.q, s.p);
      for (int i = 0; i < angular.size(); ++i) {
        columns.push_back(fmt::format("angular_momentum_{}", i));
      }
    }
    for (const auto& name : problem.series_names()) columns.push_back(name);
    // Constrained problems: the residuals and the exact motion's multipliers through the state.
    if (const HolonomicConstraints* constraints = problem.as_constrained()) {
      columns.push_back("constraint_err");
      columns.push_back("constraint_vel_err");
      for (const auto& name : constraints->multiplier_names()) columns.push_back(name);
    }
    if (with_state_) {
      // A first-order-only problem's state is y alone (State::q).
      for (int i = 0; i < problem.dof(); ++i) {
        columns.push_back(fmt::format("{}_{}", first_order_ ? "y" : "q", i));
      }
      if (!first_order_) {
        for (int i = 0; i < problem.dof(); ++i) columns.push_back(fmt::format("p_{}", i));
      }
    }
    for (const auto& [key, value] : provenance(config.command_line)) {
      out_ << provenance_line(key, value);
    }
    out_ << fmt::format("# problem: {}\n# method: {}\n# dt: {}\n", problem.spec(), method_spec,
                        format_number(config.dt));
    out_ << fmt::format("{}\n", fmt::join(columns, ","));
  }

  void observe(const Problem& problem, const State& state, bool last) {
    if (config_.series_section >= 0) {
      observe_section(problem, state);
      return;
    }
    if (count_++ % config_.series_every != 0 && !last) return;
    write_row(problem, state);
  }

  void commit() { file_.commit(); }

 private:
  // The Poincaré section q_i = 0, q̇_i > 0: a crossing between the previous step point and this
  // one is located on the cubic Hermite interpolant of q_i (bisection, to round-off) and the
  // whole state written there, interpolated the same way.
  void observe_section(const Problem& problem, const State& state) {
    const auto i = static_cast<Eigen::Index>(config_.series_section);
    Vec q_rate, p_rate;
    rates(problem, state, q_rate, p_rate);
    if (has_previous_ && previous_.q[i] < 0 && state.q[i] >= 0) {
      const double h = state.t - previous_.t;
      auto hermite = [&](double a0, double a1, double d0, double d1, double s) {
        const double s2 = s * s, s3 = s2 * s;
        return (2 * s3 - 3 * s2 + 1) * a0 + (s3 - 2 * s2 + s) * h * d0 + (-2 * s3 + 3 * s2) * a1 +
               (s3 - s2) * h * d1;
      };
      auto q_i = [&](double s) {
        return hermite(previous_.q[i], state.q[i], previous_q_rate_[i], q_rate[i], s);
      };
      double lo = 0, hi = 1;
      for (int k = 0; k < 60 && hi - lo > 1e-16; ++k) {
        const double mid = 0.5 * (lo + hi);
        (q_i(mid) < 0 ? lo : hi) = mid;
      }
      const double s = 0.5 * (lo + hi);
      State crossing{previous_.t + s * h, Vec(state.q.size()), Vec(state.p.size())};
      for (Eigen::Index k = 0; k < state.q.size(); ++k) {
        crossing.q[k] = hermite(previous_.q[k], state.q[k], previous_q_rate_[k], q_rate[k], s);
        crossing.p[k] = hermite(previous_.p[k], state.p[k], previous_p_rate_[k], p_rate[k], s);
      }
      write_row(problem, crossing);
    }
    previous_ = state;
    previous_q_rate_ = q_rate;
    previous_p_rate_ = p_rate;
    has_previous_ = true;
  }
  static void rates(const Problem& problem, const State& state, Vec& q_rate, Vec& p_rate) {
    q_rate = MassOperator(problem).solve(state.q, state.p);
    problem.gradient(state.q, p_rate);
    p_rate = -p_rate;
  }

  void write_row(const Problem& problem, const State& state) {
    line_ = format_number(state.t);
    if (!first_order_) line_ += "," + format_number(problem.energy(state.q, state.p));
    auto append = [this](const Vec& values) {
      for (double v : values) line_ += "," + format_number(v);
    };
    if (problem.has(kLinearMomentum)) append(problem.linear_momentum(state.q, state.p));
    if (problem.has(kAngularMomentum)) append(problem.angular_momentum(state.q, state.p));
    problem.series_values(state.q, state.p, extras_);
    for (double v : extras_) line_ += "," + format_number(v);
    if (problem.has(kConstraints)) {
      line_ += "," + format_number(problem.constraint_residual(state.t, state.q));
      line_ += "," + format_number(problem.constraint_velocity_residual(state.t, state.q, state.p));
      append(problem.multipliers(state.t, state.q, state.p));
    }
    if (with_state_) {
      append(state.q);
      append(state.p);
    }
    line_ += '\n';
    out_ << line_;
  }

  const RunConfig& config_;
  AtomicFileWriter file_;
  std::ostream& out_;
  bool with_state_ = true;
  bool first_order_ = false;
  long count_ = 0;
  std::string line_;
  std::vector<double> extras_;
  State previous_;
  Vec previous_q_rate_, previous_p_rate_;
  bool has_previous_ = false;
};

// [[nodiscard]] as StepStatus: the metric pass and the timing pass both read the status.
struct [[nodiscard]] LoopOutcome {
  StepStatus status;
  long steps = 0;
  double t_reached = 0;  // time of the last step point that passed the checks
  double seconds = 0;    // wall time of the loop (a timeout row's wall_s)
};

using Clock = std::chrono::steady_clock;

std::atomic<bool> interrupt_flag{false};
static_assert(std::atomic<bool>::is_always_lock_free, "request_interrupt runs in a signal handler");

StepStatus interrupted_at(double t) {
  return StepStatus::failure(kInterruptedStatus, fmt::format("interrupted at t={:.6g}", t));
}

// Advances from the initial state to t_end; `visit(state, last)` sees every step point.
// Fixed steps use t_k = t_0 + k·dt (no accumulated round-off in t); the last step is shortened
// only when dt does not divide t_end. With `checked`, a step point must be finite and pass
// `admit(state)` (the observers' divergence rule, add_energy_observers) before it is visited;
// `checked` = false (timing pass) skips both, and `visit` for fixed-step methods: the metric
// pass has already established that the run succeeds.
// config.wall_budget_s > 0: a step point reached after the budget ends the run as `timeout`
// (checked runs at every step point; unchecked adaptive runs too, since an adaptive step costs
// far more than reading the clock). The unchecked fixed-step loop has no visitor, so that
// explicit methods keep their state in registers; it replays a grid the checked pass (slower,
// with observers) finished inside the budget, and time_run reports a repeat that overruns.
template <typename Admit, typename Visit>
LoopOutcome integrate(const Problem& problem, Integrator& integrator, State& state,
                      const RunConfig& config, bool adaptive, bool checked, Admit&& admit,
                      Visit&& visit) {
  LoopOutcome outcome;
  const double t0 = state.t;
  outcome.t_reached = t0;
  const auto start = Clock::now();
  const auto seconds_since_start = [&] {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  // Sets outcome.status and returns false when the run has spent its wall-clock budget.
  auto within_budget = [&](const State& s) {
    if (config.wall_budget_s <= 0) return true;
    const double spent = seconds_since_start();
    if (spent <= config.wall_budget_s) return true;
    outcome.status = StepStatus::failure(
        kTimeoutStatus,
        fmt::format("wall-clock budget spent: {:.3g} s > wall_budget_s = {:g} s at t={:.6g} "
                    "(raise it with --wall-budget S, scene key wall_budget_s)",
                    spent, config.wall_budget_s, s.t));
    return false;
  };
  // Sets outcome.status and returns false when the state fails the checks; a passing step
  // builds no failure message.
  auto check = [&](const State& s) {
    if (!checked) return true;
    if (!within_budget(s)) return false;
    if (interrupt_requested()) {
      outcome.status = interrupted_at(s.t);
      return false;
    }
    if (!finite(s)) {
      outcome.status = StepStatus::failure("nan", fmt::format("non-finite state at t={}", s.t));
      return false;
    }
    StepStatus admitted = admit(s);
    if (admitted.ok) return true;
    outcome.status = std::move(admitted);
    return false;
  };
  if (adaptive) {
    const double t_end = t0 + config.t_end;
    while (state.t < t_end) {
      StepStatus status = integrator.adaptive_step(problem, state, t_end);
      if (!status.ok) {
        outcome.status = std::move(status);
        return outcome;
      }
      if (!check(state) || (!checked && !within_budget(state))) {
        outcome.seconds = seconds_since_start();
        return outcome;
      }
      if (!checked && interrupt_requested()) {
        outcome.status = interrupted_at(state.t);
        outcome.seconds = seconds_since_start();
        return outcome;
      }
      ++outcome.steps;
      outcome.t_reached = state.t;
      visit(state, state.t >= t_end);
    }
    outcome.seconds = seconds_since_start();
    return outcome;
  }
  const StepGrid grid{t0, config.dt, config.t_end,
                      std::max(1L, static_cast<long>(std::ceil(config.t_end / config.dt - 1e-9)))};
  if (grid.n > config.max_steps) {
    outcome.status = StepStatus::failure(
        "max_steps",
        fmt::format("t_end/dt = {} steps exceed the step budget of a fixed-step run ({} steps); "
                    "raise it with --max-steps N (scene key max_steps, at most {:g})",
                    grid.n, config.max_steps, kMaxFixedSteps));
    return outcome;
  }
  // The timing pass passes no visitor: explicit methods then run their whole grid in one
  // statically typed loop (Integrator::advance).
  auto check_and_visit = [&](const State& s, long k) {
    if (!check(s)) return false;
    outcome.t_reached = s.t;
    visit(s, k == grid.n);
    return true;
  };
  AdvanceOutcome advanced = integrator.advance(
      problem, state, grid, checked ? StepVisitor(check_and_visit) : StepVisitor());
  outcome.steps = advanced.steps;
  if (!advanced.status.ok) {
    if (advanced.status.message.find("t=") == std::string::npos) {
      advanced.status.message +=
          fmt::format(" (step ending at t={:.6g})", grid.time(advanced.steps + 1));
    }
    outcome.status = std::move(advanced.status);
  }
  outcome.seconds = seconds_since_start();
  return outcome;
}

}  // namespace

std::vector<std::string> run_config_errors(const RunConfig& config, bool adaptive) {
  std::vector<std::string> errors;
  const bool dt_ok = adaptive || (config.dt > 0 && std::isfinite(config.dt));
  if (!dt_ok) errors.push_back(fmt::format("--dt must be a finite number > 0 (got {})", config.dt));
  const bool t_end_ok = config.t_end > 0 && std::isfinite(config.t_end);
  if (!t_end_ok) {
    errors.push_back(fmt::format("--t-end must be a finite number > 0 (got {})", config.t_end));
  }
  // The step count means something only when both of its terms are valid.
  if (!adaptive && dt_ok && t_end_ok && config.t_end / config.dt > kMaxFixedSteps) {
    errors.push_back(fmt::format("--t-end/--dt = {:g} steps is more than the allowed {:g}",
                                 config.t_end / config.dt, kMaxFixedSteps));
  }
  if (config.max_steps < 1 || static_cast<double>(config.max_steps) > kMaxFixedSteps) {
    errors.push_back(
        fmt::format("--max-steps must be in 1..{:g} (got {})", kMaxFixedSteps, config.max_steps));
  }
  if (config.series_every < 1) {
    errors.push_back(fmt::format("--every must be >= 1 (got {})", config.series_every));
  }
  if (config.timing_repeats < 0 || config.timing_repeats > kMaxTimingRepeats) {
    errors.push_back(fmt::format("--timing-repeats must be in 0..{} (got {})", kMaxTimingRepeats,
                                 config.timing_repeats));
  }
  if (!(config.diverge_factor >= 0)) {
    errors.push_back(
        fmt::format("--diverge-factor must be >= 0 (0 or inf: no divergence rule; got {})",
                    config.diverge_factor));
  }
  if (!(config.wall_budget_s >= 0 && config.wall_budget_s <= kMaxWallBudgetSeconds)) {
    errors.push_back(
        fmt::format("--wall-budget must be in [0, {:g}] seconds (0: no budget; got {})",
                    kMaxWallBudgetSeconds, config.wall_budget_s));
  }
  return errors;
}

void validate_run_config(const RunConfig& config, bool adaptive) {
  throw_input_errors(run_config_errors(config, adaptive));
}

std::string series_section_error(const Problem& problem, long section) {
  if (section < 0) return {};
  // The crossing is interpolated with q̇ = M⁻¹p and ṗ = −∇V: canonical separable problems only.
  if (section >= problem.dof() || problem.has(kFirstOrderOnly) || problem.has(kForce) ||
      problem.has(kConstraints) || problem.kind() == ProblemKind::kLagrangian) {
    return fmt::format(
        "series_section = {}: a Poincare section needs a coordinate index in 0..{} of an "
        "unforced, unconstrained, separable problem (H = p^T M^-1 p/2 + V(q)); '{}' is not",
        section, problem.dof() - 1, problem.spec());
  }
  return {};
}

void check_series_section(const Problem& problem, long section) {
  if (std::string why = series_section_error(problem, section); !why.empty()) {
    throw InputError(why);
  }
}
void check_run_outputs(const RunConfig& config) {
  if (!config.series_path.empty()) check_output_file(config.series_path, "--series");
}

std::string TimingOutcome::failure_message() const {
  return fmt::format("timing pass failed: {}: {}", status.reason, status.message);
}

TimingStats timing_stats(std::vector<double> seconds) {
  if (seconds.empty()) throw std::invalid_argument("timing_stats: no timed run");
  std::sort(seconds.begin(), seconds.end());
  const auto quantile = [&](double p) {
    const double position = p * static_cast<double>(seconds.size() - 1);
    const auto j = static_cast<size_t>(std::floor(position));
    const double f = position - static_cast<double>(j);
    return j + 1 < seconds.size() ? seconds[j] + f * (seconds[j + 1] - seconds[j]) : seconds[j];
  };
  TimingStats stats;
  stats.min = seconds.front();
  stats.max = seconds.back();
  stats.median = quantile(0.5);
  stats.iqr = quantile(0.75) - quantile(0.25);
  stats.count = static_cast<int>(seconds.size());
  return stats;
}

void request_interrupt() { interrupt_flag.store(true, std::memory_order_relaxed); }
void clear_interrupt() { interrupt_flag.store(false, std::memory_order_relaxed); }
bool interrupt_requested() { return interrupt_flag.load(std::memory_order_relaxed); }

TimingOutcome time_run(const std::string& problem_spec, const std::string& method_spec,
                       const RunConfig& config, int repeats) {
  return time_run(RunSpec::parse(problem_spec, method_spec, config), repeats);
}

TimingOutcome time_run(const RunSpec& spec, int repeats) {
  const Problem* problem = spec.problem.get();
  const RunConfig& config = spec.config;
  const bool adaptive = spec.method.adaptive();
  const int wanted = std::max(1, repeats);
  const auto pass_start = Clock::now();
  // One run from a fresh integrator; its wall time, or nullopt with the failed status. It also
  // counts the recursive passes of its steps (this thread's, so parallel runs do not add theirs)
  // and the steps themselves.
  StepStatus failed = StepStatus::success();
  long run_passes = 0, run_steps = 0;
  const auto one_run = [&]() -> std::optional<double> {
    if (interrupt_requested()) {
      failed = interrupted_at(problem->initial_state().t);
      return std::nullopt;
    }
    auto integrator = spec.method.make();
    State state = problem->initial_state();
    const auto start = Clock::now();
    integrator->reset(*problem, state, config.dt);
    const long passes_before = articulated::thread_passes();
    LoopOutcome outcome = integrate(
        *problem, *integrator, state, config, adaptive, false,
        [](const State&) { return StepStatus::success(); }, [](const State&, bool) {});
    run_passes = articulated::thread_passes() - passes_before;
    run_steps = outcome.steps;
    if (!outcome.status.ok) {
      failed = std::move(outcome.status);
      return std::nullopt;
    }
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  // A run over the per-run budget ends the pass: the row is a timeout at that run's time.
  const auto over_budget = [&](double seconds) {
    return config.wall_budget_s > 0 && seconds > config.wall_budget_s;
  };
  const auto timed_out = [&](std::vector<double> seconds) {
    TimingOutcome result;
    result.status = StepStatus::success();
    result.timed_out = true;
    result.stats = timing_stats(std::move(seconds));
    result.seconds = result.stats.max;
    result.budget_note = fmt::format(
        "timing pass: a run took {:.3g} s > wall_budget_s = {:g} s (raise it with --wall-budget "
        "S, scene key wall_budget_s)",
        result.stats.max, config.wall_budget_s);
    return result;
  };
  const auto elapsed = [&] {
    return std::chrono::duration<double>(Clock::now() - pass_start).count();
  };
  TimingOutcome outcome;
  const std::optional<double> warm_up = one_run();
  if (!warm_up) {
    // An adaptive run that hit the budget inside its loop.
    if (failed.reason == kTimeoutStatus) return timed_out({elapsed()});
    return {std::move(failed), {}, 0, {}};
  }
  if (over_budget(*warm_up)) return timed_out({*warm_up});
  // Problems on tree recursions (the joint chains) count their passes: a cost per step that no
  // machine changes. Any other problem runs none.
  const LagrangianSystem* lagrangian = problem->as_lagrangian();
  if (lagrangian != nullptr && run_steps > 0 &&
      dynamic_cast<const articulated::PlanarTreeLagrangian*>(lagrangian) != nullptr) {
    outcome.recursive_passes_per_step =
        static_cast<double>(run_passes) / static_cast<double>(run_steps);
  }
  std::vector<double> seconds;
  // A repeat starts only when one more run of the longest duration seen so far still ends
  // inside the budget. A warm-up that alone leaves no room is the pass's only sample.
  double longest = *warm_up;
  while (static_cast<int>(seconds.size()) < wanted) {
    if (elapsed() + longest > config.timing_budget_s) break;
    const auto run_start = Clock::now();
    const std::optional<double> run = one_run();
    if (!run && failed.reason == kTimeoutStatus) {
      seconds.push_back(std::chrono::duration<double>(Clock::now() - run_start).count());
      return timed_out(seconds);
    }
    if (!run) return {std::move(failed), {}, 0, {}};
    seconds.push_back(*run);
    if (over_budget(*run)) return timed_out(seconds);
    longest = std::max(longest, *run);
  }
  if (static_cast<int>(seconds.size()) < wanted) {
    const bool warm_up_only = seconds.empty();
    if (warm_up_only) seconds.push_back(*warm_up);
    outcome.budget_note =
        fmt::format("timing budget: {} of {} repeats fit in timing_budget_s = {:g} s{}",
                    warm_up_only ? 0 : seconds.size(), wanted, config.timing_budget_s,
                    warm_up_only ? " (the warm-up run is the only sample)" : "");
  }
  outcome.status = StepStatus::success();
  outcome.stats = timing_stats(seconds);
  outcome.seconds = outcome.stats.median;
  return outcome;
}

void record_timing(const TimingOutcome& timing, RunRecord& record) {
  if (!timing.status.ok) {
    record.message = timing.failure_message();
    return;
  }
  if (timing.timed_out) {
    record.status = kTimeoutStatus;
    record.wall_s = timing.seconds;
    record.wall_s_min = timing.stats.min;
    record.wall_s_repeats = timing.stats.count;
    record.message = timing.budget_note;
    return;
  }
  record.wall_s = timing.stats.median;
  record.wall_s_min = timing.stats.min;
  record.wall_s_iqr = timing.stats.iqr;
  record.wall_s_repeats = timing.stats.count;
  record.recursive_passes_per_step = timing.recursive_passes_per_step;
  if (!timing.budget_note.empty()) record.message = timing.budget_note;
}

RunResult run_one(const std::string& problem_spec, const std::string& method_spec,
                  const RunConfig& config) {
  return run_one(RunSpec::parse(problem_spec, method_spec, config));
}

RunResult run_one(const RunSpec& spec) {
  throw_input_errors(spec.validate());
  const Problem* problem = spec.problem.get();
  const RunConfig& config = spec.config;
  auto integrator = spec.method.make();
  const MethodInfo& info = spec.method.info();
  const bool adaptive = spec.method.adaptive();

  RunResult result;
  RunRecord& record = result.record;
  record.problem = problem->spec();
  // What runs: hp without solver= runs Newton on a non-separable problem, and its row says so,
  // so that re-running the row's spec reproduces it (integrators/general_step.hpp).
  const std::string ran_spec = spec_on(*integrator, *problem);
  record.method = ran_spec;
  record.family = method_family(info, integrator->provider());
  if (!adaptive) record.dt = config.dt;
  record.t_end = config.t_end;

  // A reference applies when its rows reach t_end (error_max/error_final, valid_time).
  std::shared_ptr<const ReferenceSolution> reference;
  if (!problem->has(kExact) && !config.reference_dir.empty()) {
    const std::string path = reference_path(config.reference_dir, *problem);
    if (std::filesystem::exists(path)) {
      auto loaded = load_reference(path, *problem);  // InputError when malformed
      if (loaded->row_at(problem->initial_state().t + config.t_end) >= 0) {
        reference = std::move(loaded);
        record.reference = std::filesystem::path(path).filename().string();
      }
    }
  }
  ObserverList observers = make_observers({.problem = *problem,
                                           .metrics = config.extra_metrics,
                                           .dt = config.dt,
                                           .diverge_factor = config.diverge_factor,
                                           .method = &spec.method,
                                           .reference = reference});
  std::unique_ptr<SeriesWriter> series;
  if (!config.series_path.empty()) {
    series = std::make_unique<SeriesWriter>(*problem, config, ran_spec);
  }
  State state = problem->initial_state();
  for (auto& observer : observers) observer->begin(*problem, state, config.t_end);
  if (series) series->observe(*problem, state, false);
  integrator->reset(*problem, state, config.dt);
  const auto admit = [&](const State& s) {
    for (auto& observer : observers) {
      StepStatus status = observer->admit(*problem, s);
      if (!status.ok) return status;
    }
    return StepStatus::success();
  };
  const LoopOutcome outcome = integrate(*problem, *integrator, state, config, adaptive, true, admit,
                                        [&](const State& s, bool last) {
                                          for (auto& observer : observers)
                                            observer->observe(*problem, s);
                                          if (series) series->observe(*problem, s, last);
                                        });
  for (const auto& observer : observers) observer->finish(record.metrics);
  result.ok = outcome.status.ok;
  result.final_state = state;
  result.final_impulses = integrator->last_constraint_impulses();
  record.status = outcome.status.ok ? "ok" : outcome.status.reason;
  if (!outcome.status.ok) {
    record.message = outcome.status.message;
    record.t_reached = outcome.t_reached;
  }
  // A timeout is a point of the work-precision diagram at the budget: the seconds spent.
  if (outcome.status.reason == kTimeoutStatus) record.wall_s = outcome.seconds;
  record.steps = outcome.steps;
  record.counters = integrator->counters();
  if (series) series->commit();

  if (result.ok && config.timing_repeats > 0) {
    record_timing(time_run(spec, config.timing_repeats), record);
    result.ok = record.status != kTimeoutStatus;
  }
  return result;
}

}  // namespace geomint
