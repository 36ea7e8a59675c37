// Metric observers (docs/DESIGN.md §3): energy error and drift, momentum maps, error against the
// exact solution.
#include "harness/observers.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "harness/metrics.hpp"
#include "harness/reference.hpp"
#include "integrators/newton.hpp"
#include "problems/structures/attitude.hpp"
#include "problems/structures/charged_particle.hpp"

namespace geomint {
namespace {

constexpr int kDriftWindows = 20;

double energy_reference(const Problem& problem, double energy0, double t) {
  if (!problem.has(kForce)) return energy0;
  const State exact = problem.exact(t);
  return problem.energy(exact.q, exact.p);
}

bool divergence_rule_on(double factor) { return factor > 0 && std::isfinite(factor); }

// energy_err_max, energy_err_final: |H(q_k, p_k) − H_ref(t_k)| / |H_0|; energy_drift: slope
// per unit time of the per-window maxima of that error over kDriftWindows equal time windows.
// With a divergence factor, also the divergence rule of a conservative run (admit), on the same
// energy evaluation as the metric: one problem.energy() per step point.
class EnergyObserver : public Observer {
 public:
  EnergyObserver(const Problem& problem, double diverge_factor)
      : diverge_factor_(diverge_factor),
        // First-order-only problems have no energy and forced ones no conserved one.
        rule_(divergence_rule_on(diverge_factor) && !problem.has(kForce) &&
              !problem.has(kFirstOrderOnly)) {}
  void begin(const Problem& problem, const State& state, double t_end) override {
    energy0_ = problem.energy(state.q, state.p);
    scale_ = std::abs(energy0_) > 0 ? std::abs(energy0_) : 1.0;
    divergence_scale_ = std::max(std::abs(energy0_), 1e-300);
    t0_ = state.t;
    window_length_ = (t_end - state.t) / kDriftWindows;
    window_max_.assign(kDriftWindows, -1.0);
  }
  StepStatus admit(const Problem& problem, const State& state) override {
    if (!rule_) return StepStatus::success();
    energy_ = problem.energy(state.q, state.p);
    energy_at_ = &state;
    // A finite state can still have no energy: a position-dependent mass that is singular
    // there (the spherical pendulum in angles on a pole) gives 0/0, which no comparison flags.
    if (!std::isfinite(energy_)) {
      return StepStatus::failure(
          "nan", fmt::format("non-finite energy at t={} (the mass is singular there)", state.t));
    }
    if (std::abs(energy_ - energy0_) > diverge_factor_ * divergence_scale_) {
      return StepStatus::failure(
          "diverged",
          fmt::format("relative energy error above {:g} at t={:.6g}", diverge_factor_, state.t));
    }
    return StepStatus::success();
  }
  void observe(const Problem& problem, const State& state) override {
    // The energy admit() evaluated at this very state, else a fresh evaluation.
    const double energy = energy_at_ == &state ? energy_ : problem.energy(state.q, state.p);
    energy_at_ = nullptr;
    const double error = std::abs(energy - energy_reference(problem, energy0_, state.t)) / scale_;
    err_max_ = std::max(err_max_, error);
    err_final_ = error;
    int window = static_cast<int>((state.t - t0_) / window_length_);
    window = std::clamp(window, 0, kDriftWindows - 1);
    window_max_[window] = std::max(window_max_[window], error);
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::energy_err_max.key()] = err_max_;
    metrics[metric::energy_err_final.key()] = err_final_;
    std::vector<double> times, maxima;
    for (int w = 0; w < kDriftWindows; ++w) {
      if (window_max_[w] < 0) continue;
      times.push_back(t0_ + (w + 0.5) * window_length_);
      maxima.push_back(window_max_[w]);
    }
    metrics[metric::energy_drift.key()] = least_squares_slope(times, maxima);
  }

 private:
  double diverge_factor_ = 0;
  bool rule_ = false;
  double energy0_ = 0, scale_ = 1, divergence_scale_ = 1, t0_ = 0, window_length_ = 1;
  double energy_ = 0;                 // the energy admit() evaluated, at *energy_at_
  const State* energy_at_ = nullptr;  // the state admit() evaluated, until observe() uses it
  double err_max_ = 0, err_final_ = 0;
  std::vector<double> window_max_;
};

// The divergence rule of a run without a conserved energy (forced, first-order): it stops when
// max(|q|∞, |p|∞) exceeds kDivergedStateNorm. No metric of its own.
class StateNormRule : public Observer {
 public:
  void begin(const Problem&, const State&, double) override {}
  StepStatus admit(const Problem&, const State& state) override {
    if (std::max(state.q.lpNorm<Eigen::Infinity>(), state.p.lpNorm<Eigen::Infinity>()) >
        kDivergedStateNorm) {
      return StepStatus::failure("diverged",
                                 fmt::format("state norm above 1e100 at t={:.6g}", state.t));
    }
    return StepStatus::success();
  }
  void observe(const Problem&, const State&) override {}
  void finish(std::map<std::string, double>&) const override {}
};

// Absolute error ‖J(q_k, p_k) − J(q_0, p_0)‖ of a momentum map J.
class MomentumObserver : public Observer {
 public:
  using Map = Vec (Problem::*)(const Vec&, const Vec&) const;
  MomentumObserver(Map map, const MetricDecl& column) : map_(map), column_(column) {}
  void begin(const Problem& problem, const State& state, double) override {
    initial_ = (problem.*map_)(state.q, state.p);
  }
  void observe(const Problem& problem, const State& state) override {
    err_max_ = std::max(err_max_, ((problem.*map_)(state.q, state.p) - initial_).norm());
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[column_.key()] = err_max_;
  }

 private:
  Map map_;
  const MetricDecl& column_;
  Vec initial_;
  double err_max_ = 0;
};

// casimir_err_max = max_k |C(q_k, p_k) − C₀| / |C₀| (absolute when C₀ = 0) on problems with a
// Casimir (|Π|² of a rigid body): relative, since |Π|² carries the square of the momentum's units.
// Kept to round-off by a Lie–Poisson integrator, drifting under a general-purpose ODE solver.
class CasimirObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double) override {
    initial_ = problem.casimir(state.q, state.p);
  }
  void observe(const Problem& problem, const State& state) override {
    const double scale = initial_ != 0 ? std::abs(initial_) : 1.0;
    err_max_ = std::max(err_max_, std::abs(problem.casimir(state.q, state.p) - initial_) / scale);
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::casimir_err_max.key()] = err_max_;
  }

 private:
  double initial_ = 0, err_max_ = 0;
};

// orthogonality_err_max = max_k ‖Q_kᵀQ_k − I‖_F on problems whose state holds an attitude Q
// (rigid_body, heavy_top): absolute, as QᵀQ − I is dimensionless. It reads the attitude as a
// matrix, where constraint_err_max reads the six constraint functions (the halved norms among
// them).
class OrthogonalityObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double) override {
    observe(problem, state);
  }
  void observe(const Problem& problem, const State& state) override {
    const Eigen::Matrix3d Q = problem.as<AttitudeStructure>()->attitude(state.q);
    err_max_ = std::max(err_max_, (Q.transpose() * Q - Eigen::Matrix3d::Identity()).norm());
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::orthogonality_err_max.key()] = err_max_;
  }

 private:
  double err_max_ = 0;
};

// magnetic_moment_err_max = max_k |μ_k − μ₀|/|μ₀| for a charged particle, μ = m v⊥²/(2|B|) with
// v = (p − qA(x))/m and v⊥ across the local B (../shared/MECHANICS.md §5): the adiabatic
// invariant of the magnetic bottle (exact in a uniform field), relative because μ carries the
// problem's units (an electron's is 1e-18 J/T). Absolute when μ₀ = 0 (motion along B).
class MagneticMomentObserver : public Observer {
 public:
  explicit MagneticMomentObserver(const ChargedParticleStructure& particle) : particle_(particle) {}
  void begin(const Problem&, const State& state, double) override {
    initial_ = magnetic_moment(state);
  }
  void observe(const Problem&, const State& state) override {
    const double scale = initial_ != 0 ? std::abs(initial_) : 1.0;
    err_max_ = std::max(err_max_, std::abs(magnetic_moment(state) - initial_) / scale);
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::magnetic_moment_err_max.key()] = err_max_;
  }

 private:
  double magnetic_moment(const State& state) const {
    const Eigen::Vector3d x = state.q.head<3>();
    const double m = particle_.particle_mass();
    const Eigen::Vector3d v = (Eigen::Vector3d(state.p.head<3>()) -
                               particle_.particle_charge() * particle_.vector_potential(x)) /
                              m;
    Eigen::Vector3d E, B;
    particle_.fields(x, E, B);
    const double field = B.norm();
    const double along = v.dot(B) / field;
    return m * (v.squaredNorm() - along * along) / (2 * field);
  }

  const ChargedParticleStructure& particle_;
  double initial_ = 0, err_max_ = 0;
};

// constraint_err_max = max_k ‖g(q_k)‖∞ and constraint_vel_err_max = max_k ‖G(q_k) M⁻¹p_k‖∞ on
// problems with holonomic constraints (docs/METHOD.md §3). Absolute, in the units of g (a length
// for the rod problems: the rod-length error) and of dg/dt: g = 0 is the reference, so there is
// no initial value to divide by as for the energy, and the problem's g already fixes the scale
// (docs/METHODS.md "Holonomic constraints"). The initial state counts: it is consistent to
// round-off.
class ConstraintObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double) override {
    observe(problem, state);
  }
  void observe(const Problem& problem, const State& state) override {
    position_ = std::max(position_, problem.constraint_residual(state.t, state.q));
    velocity_ =
        std::max(velocity_, problem.constraint_velocity_residual(state.t, state.q, state.p));
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::constraint_err_max.key()] = position_;
    metrics[metric::constraint_vel_err_max.key()] = velocity_;
  }

 private:
  double position_ = 0, velocity_ = 0;
};

// error_max, error_final: ‖(q_k − q(t_k), p_k − p(t_k))‖₂ against the exact solution.
class ExactErrorObserver : public Observer {
 public:
  void begin(const Problem&, const State&, double) override {}
  void observe(const Problem& problem, const State& state) override {
    const State exact = problem.exact(state.t);
    const double error = robust_norm(state.q - exact.q, state.p - exact.p);
    error_max_ = std::max(error_max_, error);
    error_final_ = error;
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::error_max.key()] = error_max_;
    metrics[metric::error_final.key()] = error_final_;
  }

 private:
  double error_max_ = 0, error_final_ = 0;
};

// phase_err: the time shift τ for which the exact solution best matches the computed state,
// min over τ of ‖(q_k, p_k) − exact(t_k + τ)‖₂, as the angle 2πτ/T in radians (positive: the
// computed motion is ahead). τ is followed through kPhaseCheckpoints checkpoints, each search
// centred on the previous shift, so it unwraps past half a period. period_err: relative error
// (T_computed − T)/T = −s/(1 + s) of the period, from the least-squares slope s of τ against t.
class PhaseObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double t_end) override {
    problem_ = &problem;
    period_ = problem.period();
    interval_ = (t_end - state.t) / kPhaseCheckpoints;
    next_checkpoint_ = state.t + interval_;
    times_ = {state.t};
    shifts_ = {0.0};
  }
  void observe(const Problem& problem, const State& state) override {
    if (!state.q.allFinite() || !state.p.allFinite()) return;
    last_ = state;
    if (state.t < next_checkpoint_ - 1e-9 * interval_) return;
    shifts_.push_back(best_shift(problem, state, shifts_.back()));
    times_.push_back(state.t);
    while (next_checkpoint_ <= state.t + 1e-9 * interval_) next_checkpoint_ += interval_;
  }
  void finish(std::map<std::string, double>& metrics) const override {
    std::vector<double> times = times_, shifts = shifts_;
    if (last_.q.size() > 0 && last_.t > times.back()) {
      shifts.push_back(best_shift(*problem_, last_, shifts.back()));
      times.push_back(last_.t);
    }
    if (times.size() < 2) return;
    const double slope = least_squares_slope(times, shifts);
    metrics[metric::phase_err.key()] = 2 * std::numbers::pi * shifts.back() / period_;
    metrics[metric::period_err.key()] = -slope / (1 + slope);
  }

 private:
  static constexpr int kPhaseCheckpoints = 32;
  static constexpr int kGrid = 2048;

  static double distance_squared(const Problem& problem, const State& state, double t) {
    const State exact = problem.exact(t);
    return (state.q - exact.q).squaredNorm() + (state.p - exact.p).squaredNorm();
  }
  // Grid over one period centred on `guess` (fine enough for the perihelion passage of
  // e = 0.99), then golden-section refinement around the three best local minima.
  double best_shift(const Problem& problem, const State& state, double guess) const {
    const double spacing = period_ / kGrid;
    std::vector<double> value(kGrid + 1);
    for (int i = 0; i <= kGrid; ++i) {
      value[i] = distance_squared(problem, state, state.t + guess + (i - kGrid / 2) * spacing);
    }
    std::vector<int> minima;
    for (int i = 0; i <= kGrid; ++i) {
      if ((i == 0 || value[i] <= value[i - 1]) && (i == kGrid || value[i] <= value[i + 1])) {
        minima.push_back(i);
      }
    }
    std::sort(minima.begin(), minima.end(), [&](int a, int b) { return value[a] < value[b]; });
    if (minima.size() > 3) minima.resize(3);
    double best = guess, best_value = std::numeric_limits<double>::infinity();
    const double golden = (std::sqrt(5.0) - 1) / 2;
    for (int i : minima) {
      double lo = guess + (i - kGrid / 2 - 1) * spacing, hi = lo + 2 * spacing;
      double x1 = hi - golden * (hi - lo), x2 = lo + golden * (hi - lo);
      double f1 = distance_squared(problem, state, state.t + x1);
      double f2 = distance_squared(problem, state, state.t + x2);
      for (int iteration = 0; iteration < 60; ++iteration) {
        if (f1 < f2) {
          hi = x2, x2 = x1, f2 = f1;
          x1 = hi - golden * (hi - lo);
          f1 = distance_squared(problem, state, state.t + x1);
        } else {
          lo = x1, x1 = x2, f1 = f2;
          x2 = lo + golden * (hi - lo);
          f2 = distance_squared(problem, state, state.t + x2);
        }
      }
      const double x = f1 < f2 ? x1 : x2;
      const double f = std::min(f1, f2);
      if (f < best_value) best = x, best_value = f;
    }
    return best;
  }

  const Problem* problem_ = nullptr;
  double period_ = 1, interval_ = 1, next_checkpoint_ = 0;
  std::vector<double> times_, shifts_;
  State last_;
};

// perihelion_err: precession of the apsidal line per orbit (radians, positive = prograde) of a
// planar orbit: the least-squares slope, over the passages, of the angle of the computed maxima
// of |q|, each refined by a parabola through the three step points around it. It is measured at
// the apocentre, where the step points are dense even when e = 0.99 sweeps radians per step
// through the pericentre. Needs two passages and an eccentric orbit
// ((r_max − r_min)/(r_max + r_min) ≥ 1e-3).
class PericentreObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double) override {
    double r_min = std::numeric_limits<double>::infinity(), r_max = 0;
    for (int i = 0; i < 256; ++i) {
      const double r = problem.exact(state.t + i * problem.period() / 256).q.norm();
      r_min = std::min(r_min, r), r_max = std::max(r_max, r);
    }
    eccentric_ = (r_max - r_min) >= 1e-3 * (r_max + r_min);
    push(state);
  }
  void observe(const Problem&, const State& state) override {
    if (!eccentric_ || !state.q.allFinite()) return;
    push(state);
    if (count_ < 3 || !(r_[1] > r_[0] && r_[1] >= r_[2])) return;
    // Vertex of the parabola through (t, r) at the three points, then the angle there by
    // quadratic interpolation.
    const double t0 = t_[0], t1 = t_[1], t2 = t_[2];
    const double d01 = (r_[1] - r_[0]) / (t1 - t0), d12 = (r_[2] - r_[1]) / (t2 - t1);
    const double curvature = (d12 - d01) / (t2 - t0);
    double vertex = curvature < 0 ? 0.5 * (t0 + t1) - d01 / (2 * curvature) : t1;
    vertex = std::clamp(vertex, t0, t2);
    double angle = 0;
    for (int i = 0; i < 3; ++i) {
      double weight = 1;
      for (int j = 0; j < 3; ++j) {
        if (j != i) weight *= (vertex - t_[j]) / (t_[i] - t_[j]);
      }
      angle += weight * angle_[i];
    }
    passages_.push_back(angle);
  }
  void finish(std::map<std::string, double>& metrics) const override {
    if (!eccentric_ || passages_.size() < 2) return;
    std::vector<double> index(passages_.size());
    for (size_t i = 0; i < index.size(); ++i) index[i] = static_cast<double>(i);
    // The unwrapped angle gains a whole turn per orbit; what is left is the precession.
    const double turn = 2 * std::numbers::pi;
    const double slope = least_squares_slope(index, passages_);
    metrics[metric::perihelion_err.key()] = slope - turn * std::round(slope / turn);
  }

 private:
  // Keeps the last three step points with the polar angle unwrapped along the trajectory.
  void push(const State& state) {
    double angle = std::atan2(state.q[1], state.q[0]);
    if (count_ > 0) {
      const double previous = angle_[count_ < 3 ? count_ - 1 : 2];
      angle = previous + std::remainder(angle - previous, 2 * std::numbers::pi);
    }
    if (count_ == 3) {
      for (int i = 0; i < 2; ++i) t_[i] = t_[i + 1], r_[i] = r_[i + 1], angle_[i] = angle_[i + 1];
    } else {
      ++count_;
    }
    t_[count_ - 1] = state.t, r_[count_ - 1] = state.q.norm(), angle_[count_ - 1] = angle;
  }

  bool eccentric_ = false;
  int count_ = 0;
  double t_[3] = {}, r_[3] = {}, angle_[3] = {};
  std::vector<double> passages_;
};

// At a step point on Problem::end_reference_time() (within 1e-9 relative; the run's t_end must
// be that time): error_final = ‖(q, p) − (q_ref, p_ref)‖₂ and scd = significant correct digits,
// the IVP Test Set's definition −log₁₀ maxᵢ |xᵢ − xᵢ_ref| / |xᵢ_ref| over every component of
// (q, p) (relative error, max norm; components with x_ref = 0 are left out). On Pleiades p = m v
// with exact masses, so p's relative errors are v's, as the Test Set states them.
class EndReferenceObserver : public Observer {
 public:
  void begin(const Problem& problem, const State&, double) override {
    time_ = problem.end_reference_time();
    reference_ = problem.end_reference();
  }
  void observe(const Problem&, const State& state) override {
    if (std::abs(state.t - time_) > 1e-9 * std::max(1.0, std::abs(time_))) return;
    reached_ = true;
    error_ = robust_norm(state.q - reference_.q, state.p - reference_.p);
    worst_relative_ =
        std::max(worst_relative(state.q, reference_.q), worst_relative(state.p, reference_.p));
  }
  void finish(std::map<std::string, double>& metrics) const override {
    if (!reached_) return;
    metrics[metric::error_final.key()] = error_;
    metrics[metric::scd.key()] = -std::log10(worst_relative_);
  }

 private:
  static double worst_relative(const Vec& x, const Vec& reference) {
    double worst = 0;
    for (Eigen::Index i = 0; i < reference.size(); ++i) {
      if (reference[i] == 0) continue;
      // A non-finite component counts as no correct digit at all.
      const double relative = std::abs(x[i] - reference[i]) / std::abs(reference[i]);
      worst = std::isnan(relative) ? std::numeric_limits<double>::infinity()
                                   : std::max(worst, relative);
    }
    return worst;
  }

  double time_ = 0, error_ = 0, worst_relative_ = 0;
  State reference_;
  bool reached_ = false;
};

}  // namespace

bool has_energy_reference(const Problem& problem) {
  if (problem.has(kFirstOrderOnly)) return false;  // no energy at all
  return !problem.has(kForce) || problem.has(kExact);
}

void add_energy_observers(const ObserverContext& context, ObserverList& observers) {
  const Problem& problem = context.problem;
  if (has_energy_reference(problem)) {
    observers.push_back(std::make_unique<EnergyObserver>(problem, context.diverge_factor));
  }
  const bool conservative = !problem.has(kForce) && !problem.has(kFirstOrderOnly);
  if (divergence_rule_on(context.diverge_factor) && !conservative) {
    observers.push_back(std::make_unique<StateNormRule>());
  }
}

void add_linear_momentum_observer(const ObserverContext& context, ObserverList& observers) {
  if (!context.problem.has(kLinearMomentum)) return;
  observers.push_back(
      std::make_unique<MomentumObserver>(&Problem::linear_momentum, metric::momentum_err_max));
}

void add_angular_momentum_observer(const ObserverContext& context, ObserverList& observers) {
  if (!context.problem.has(kAngularMomentum)) return;
  observers.push_back(std::make_unique<MomentumObserver>(&Problem::angular_momentum,
                                                         metric::angular_momentum_err_max));
}

void add_casimir_observer(const ObserverContext& context, ObserverList& observers) {
  if (context.problem.has(kCasimir)) observers.push_back(std::make_unique<CasimirObserver>());
}

void add_constraint_observer(const ObserverContext& context, ObserverList& observers) {
  if (context.problem.has(kConstraints)) {
    observers.push_back(std::make_unique<ConstraintObserver>());
  }
}

void add_orthogonality_observer(const ObserverContext& context, ObserverList& observers) {
  if (context.problem.as<AttitudeStructure>() != nullptr) {
    observers.push_back(std::make_unique<OrthogonalityObserver>());
  }
}

void add_magnetic_moment_observer(const ObserverContext& context, ObserverList& observers) {
  if (const auto* particle = context.problem.as<ChargedParticleStructure>()) {
    observers.push_back(std::make_unique<MagneticMomentObserver>(*particle));
  }
}

// error_final/error_max/scd against an end reference, the exact solution or a loaded reference.
void add_error_observers(const ObserverContext& context, ObserverList& observers) {
  const Problem& problem = context.problem;
  if (problem.has(kEndReference)) observers.push_back(std::make_unique<EndReferenceObserver>());
  if (problem.has(kExact)) {
    observers.push_back(std::make_unique<ExactErrorObserver>());
  } else if (context.reference) {
    observers.push_back(make_reference_observer(context.reference));
  }
}

namespace {
bool periodic_with_exact_solution(const Problem& problem) {
  return problem.has(kExact) && problem.has(kPeriod) && !problem.has(kForce);
}
}  // namespace

void add_phase_observer(const ObserverContext& context, ObserverList& observers) {
  if (periodic_with_exact_solution(context.problem)) {
    observers.push_back(std::make_unique<PhaseObserver>());
  }
}

void add_pericentre_observer(const ObserverContext& context, ObserverList& observers) {
  const Problem& problem = context.problem;
  if (periodic_with_exact_solution(problem) && problem.has(kAngularMomentum) &&
      problem.dof() == 2) {
    observers.push_back(std::make_unique<PericentreObserver>());
  }
}

ObserverList make_observers(const ObserverContext& context) {
  ObserverList observers;
  for (const MetricDecl* decl : metric_table()) {
    if (decl->observer != nullptr) decl->observer(context, observers);
  }
  return observers;
}

ObserverList make_metric_observers(const Problem& problem, double diverge_factor) {
  static const std::vector<std::string> kNoOptionalMetric;
  return make_observers(
      {.problem = problem, .metrics = kNoOptionalMetric, .diverge_factor = diverge_factor});
}

double least_squares_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  if (n < 2) return 0.0;
  double mean_x = 0, mean_y = 0;
  for (size_t i = 0; i < n; ++i) {
    mean_x += x[i] / n;
    mean_y += y[i] / n;
  }
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < n; ++i) {
    sxy += (x[i] - mean_x) * (y[i] - mean_y);
    sxx += (x[i] - mean_x) * (x[i] - mean_x);
  }
  return sxx > 0 ? sxy / sxx : 0.0;
}

}  // namespace geomint
