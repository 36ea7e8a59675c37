// Optional structure metrics (harness/structure_metrics.hpp; docs/USAGE.md "Optional structure
// metrics").
#include "harness/structure_metrics.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <utility>

#include "harness/metrics.hpp"
#include "harness/run_spec.hpp"
#include "problems/mass_operator.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// period_measured: mean interval between the upward zero crossings of the problem's
// period_observable(q, p) (default q[0]; problems/problem.hpp) at step points (each
// crossing time linearly interpolated between the two step points around it, an O(h²) error
// that is nearly the same at every crossing and so mostly cancels in the differences);
// period_err_rel = (period_measured − T)/T when the problem knows its period T. Needs two
// crossings.
class ZeroCrossingPeriodObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double) override {
    period_ = problem.has(kPeriod) ? problem.period() : kNaN;
    last_t_ = state.t;
    last_x_ = problem.period_observable(state.q, state.p);
  }
  void observe(const Problem& problem, const State& state) override {
    const double x = problem.period_observable(state.q, state.p);
    if (!std::isfinite(x)) return;
    if (last_x_ < 0 && x >= 0) {
      const double crossing = last_t_ + (-last_x_) / (x - last_x_) * (state.t - last_t_);
      if (crossings_ == 0) first_ = crossing;
      last_crossing_ = crossing;
      ++crossings_;
    }
    last_t_ = state.t;
    last_x_ = x;
  }
  void finish(std::map<std::string, double>& metrics) const override {
    if (crossings_ < 2) return;
    const double measured = (last_crossing_ - first_) / (crossings_ - 1);
    metrics[metric::period_measured.key()] = measured;
    if (!std::isnan(period_))
      metrics[metric::period_err_rel.key()] = (measured - period_) / period_;
  }

 private:
  double period_ = kNaN;
  double last_t_ = 0, last_x_ = 0, first_ = 0, last_crossing_ = 0;
  long crossings_ = 0;
};

// energy_growth_exponent: least-squares slope of log M(t) against log t, M(t) the running
// maximum of |H − H₀|/|H₀| up to time t (t from the run's start), at kGrowthCheckpoints
// log-spaced times over the last kGrowthDecades decades of the run (or from the first step when
// the run is shorter); the first checkpoint is skipped since M there reflects the start-up. A
// bounded error gives 0, a random walk of round-off ½, a linear drift 1. Reported only when the
// run spans at least a decade and M > 0 at the checkpoints used.
class EnergyGrowthObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double t_end) override {
    energy0_ = problem.energy(state.q, state.p);
    scale_ = std::abs(energy0_) > 0 ? std::abs(energy0_) : 1.0;
    t0_ = state.t;
    span_ = t_end;
  }
  void observe(const Problem& problem, const State& state) override {
    const double elapsed = state.t - t0_;
    if (checkpoints_.empty()) {  // the first step fixes the smallest time that can be resolved
      const double first = std::max(elapsed, span_ * std::pow(10.0, -kGrowthDecades));
      if (!(first > 0) || span_ < 10 * first) return;
      for (int i = 0; i < kGrowthCheckpoints; ++i) {
        checkpoints_.push_back(
            first * std::pow(span_ / first, static_cast<double>(i) / (kGrowthCheckpoints - 1)));
      }
    }
    running_max_ =
        std::max(running_max_, std::abs(problem.energy(state.q, state.p) - energy0_) / scale_);
    // Step points land on or after a checkpoint: M up to the step point is recorded for it.
    while (next_ < checkpoints_.size() && elapsed >= checkpoints_[next_] * (1 - 1e-12)) {
      times_.push_back(elapsed);
      maxima_.push_back(running_max_);
      ++next_;
    }
  }
  void finish(std::map<std::string, double>& metrics) const override {
    std::vector<double> log_t, log_max;
    for (size_t i = 1; i < times_.size(); ++i) {
      if (!(maxima_[i] > 0) || !std::isfinite(maxima_[i])) return;
      log_t.push_back(std::log(times_[i]));
      log_max.push_back(std::log(maxima_[i]));
    }
    if (log_t.size() < 2) return;
    metrics[metric::energy_growth_exponent.key()] = least_squares_slope(log_t, log_max);
  }

 private:
  static constexpr int kGrowthCheckpoints = 25;
  static constexpr double kGrowthDecades = 3;
  double energy0_ = 0, scale_ = 1, t0_ = 0, span_ = 0, running_max_ = 0;
  std::vector<double> checkpoints_, times_, maxima_;
  size_t next_ = 0;
};

bool requested(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

const std::vector<std::string>& optional_metric_names() {
  static const std::vector<std::string> names = [] {
    std::vector<const MetricDecl*> options;
    for (const MetricDecl* decl : metric_table()) {
      if (decl->option_rank > 0) options.push_back(decl);
    }
    std::sort(options.begin(), options.end(),
              [](const auto* a, const auto* b) { return a->option_rank < b->option_rank; });
    std::vector<std::string> out;
    for (const MetricDecl* decl : options) out.push_back(decl->key());
    return out;
  }();
  return names;
}

void check_optional_metrics(const std::vector<std::string>& names, const std::string& option) {
  for (const auto& name : names) {
    if (!requested(optional_metric_names(), name)) {
      throw InputError(fmt::format("{}: unknown metric '{}' (one of: {})", option, name,
                                   fmt::join(optional_metric_names(), ", ")));
    }
  }
}

std::string symplecticity_defect_not_applicable(const Integrator& method, const Problem& problem) {
  // Checked before any dense 2n x 2n matrix is allocated: past the limit the allocation fails
  // (std::bad_alloc) or the O(n^3) solves take hours.
  if (problem.dof() > kMaxDenseTangentDof) {
    return fmt::format(
        "{} degrees of freedom is more than the {} the dense linearised step and eigensolver "
        "take",
        problem.dof(), kMaxDenseTangentDof);
  }
  if (method.info().flags & kAdaptive) return "adaptive method: no fixed one-step map";
  if (problem.has(kFirstOrderOnly)) return "first-order problem: no canonical (q, p) pair";
  if (problem.has(kForce)) return "forced problem: the step is not a Hamiltonian map";
  if (problem.has(kConstraints))
    return "constrained problem: the step acts on the constraint manifold";
  if (!problem.has(kHessian)) return "the problem offers no Hessian to linearise the step with";
  if (!method.has_step_tangent(problem)) return "the method has no linearised step (step_tangent)";
  return "";
}

bool symplecticity_defect_applies(const Integrator& method, const Problem& problem) {
  return symplecticity_defect_not_applicable(method, problem).empty();
}

double symplecticity_defect(const Eigen::MatrixXd& tangent) {
  if (!tangent.allFinite()) return kNaN;
  const long n = tangent.rows() / 2;
  Eigen::MatrixXd form = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  form.topRightCorner(n, n) = Eigen::MatrixXd::Identity(n, n);
  form.bottomLeftCorner(n, n) = -Eigen::MatrixXd::Identity(n, n);
  const double size = tangent.cwiseAbs().maxCoeff();
  return (tangent.transpose() * form * tangent - form).cwiseAbs().maxCoeff() /
         std::max(1.0, size * size);
}

double symplecticity_defect(const MethodFactory& factory, const Problem& problem,
                            const State& state, double h) {
  const auto method = factory.make();
  if (!symplecticity_defect_applies(*method, problem)) return kNaN;
  State start = state;
  method->reset(problem, start, h);
  Eigen::MatrixXd tangent;
  if (!method->step_tangent(problem, start, h, tangent).ok) return kNaN;
  return symplecticity_defect(tangent);
}

std::string normal_modes_not_applicable(const Integrator& method, const Problem& problem) {
  if (!problem.is_linear()) return "not a linear problem (Problem::is_linear)";
  return symplecticity_defect_not_applicable(method, problem);
}

namespace {

// One normal mode as a problem of its own: unit mass, stiffness ω², so that its one-step map is
// the mode's 2×2 block of DΦ in the M-orthonormal modal coordinates (every method here is a
// function of hM⁻¹K on a linear problem).
class ModalOscillator final : public Problem {
 public:
  explicit ModalOscillator(double stiffness) : stiffness_(stiffness) {
    set_mass(Vec::Ones(1));
    set_capabilities(kHessian);
  }
  State initial_state() const override { return {0.0, Vec::Ones(1), Vec::Zero(1)}; }
  double potential(const Vec& q) const override { return 0.5 * stiffness_ * q.squaredNorm(); }
  void gradient(const Vec& q, Vec& g) const override { g = stiffness_ * q; }
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(1, 1);
    H.setZero();
    H.insert(0, 0) = stiffness_;
    H.makeCompressed();
  }
  bool is_linear() const override { return true; }

 private:
  double stiffness_;
};

// ρ and θ of the eigenvalues λ = (a + d)/2 ± √δ of the block [[a, b], [c, d]]. The
// discriminant is formed as δ = ((a − d)/2)² + bc, not as ((a + d)/2)² − det: for a slow mode
// a ≈ d ≈ 1 and δ ≈ −(hω)², which the second form would leave with an absolute error of ε, a
// relative error of ε/(hω)² in ω̃.
void block_eigenvalues(double a, double b, double c, double d, DiscreteMode& mode, double h) {
  const double half_trace = (a + d) / 2;
  const double half_difference = (a - d) / 2;
  const std::complex<double> root =
      std::sqrt(std::complex<double>(half_difference * half_difference + b * c));
  const std::complex<double> plus = half_trace + root, minus = half_trace - root;
  mode.omega_discrete = std::max(std::abs(std::arg(plus)), std::abs(std::arg(minus))) / h;
  mode.amplitude = std::max(std::abs(plus), std::abs(minus));
}

// λ = vᵀKv / vᵀMv in long double. The dense solver's λ_j carries an absolute error of about
// ε λ_max, so the slow modes of a long chain lose (ω_max/ω_j)² in relative accuracy; the
// Rayleigh quotient of its eigenvector is off by only O(ε² λ_max²/gap), and long double keeps
// the cancellation in Kv (a second difference of a smooth shape) below double's rounding.
double rayleigh_quotient(const SparseMatrix& stiffness, const Vec& mass, const Vec& shape) {
  long double numerator = 0, denominator = 0;
  for (long k = 0; k < stiffness.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(stiffness, k); it; ++it) {
      numerator += static_cast<long double>(shape[it.row()]) * it.value() * shape[it.col()];
    }
  }
  for (long i = 0; i < shape.size(); ++i) {
    denominator += static_cast<long double>(shape[i]) * mass[i] * shape[i];
  }
  return static_cast<double>(numerator / denominator);
}

}  // namespace

std::vector<DiscreteMode> discrete_normal_modes(const MethodFactory& factory,
                                                const Problem& problem, double h) {
  const auto method = factory.make();
  if (!normal_modes_not_applicable(*method, problem).empty()) return {};
  State state = problem.initial_state();
  method->reset(problem, state, h);
  Eigen::MatrixXd tangent;
  if (!method->step_tangent(problem, state, h, tangent).ok || !tangent.allFinite()) return {};
  const long n = problem.dof();
  SparseMatrix hessian;
  problem.hessian(problem.initial_state().q, hessian);
  const Eigen::MatrixXd stiffness(hessian);
  const Eigen::MatrixXd mass = MassOperator(problem).constant_diagonal().asDiagonal();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(stiffness, mass);
  const Eigen::MatrixXd& shapes = solver.eigenvectors();  // VᵀMV = I
  // Modal coordinates: (x, y) = (VᵀM q, Vᵀp), inverse (q, p) = (V x, M V y).
  const Eigen::MatrixXd modal_q = shapes.transpose() * mass;
  const Eigen::MatrixXd mass_shapes = mass * shapes;
  // Entries of the projected blocks carry rounding of about n ε ‖DΦ‖; a block of the modal
  // oscillator further away than this bound means the method is no function of hM⁻¹K.
  const double block_tolerance = 1e-8 * std::max(1.0, tangent.cwiseAbs().maxCoeff());
  const auto modal_method = factory.make();
  std::vector<DiscreteMode> modes;
  for (long j = 0; j < n; ++j) {
    const double x_x = modal_q.row(j) * tangent.topLeftCorner(n, n) * shapes.col(j);
    const double x_y = modal_q.row(j) * tangent.topRightCorner(n, n) * mass_shapes.col(j);
    const double y_x = shapes.col(j).transpose() * tangent.bottomLeftCorner(n, n) * shapes.col(j);
    const double y_y =
        shapes.col(j).transpose() * tangent.bottomRightCorner(n, n) * mass_shapes.col(j);
    DiscreteMode mode;
    const double eigenvalue = std::max(
        0.0, rayleigh_quotient(hessian, MassOperator(problem).constant_diagonal(), shapes.col(j)));
    mode.omega = std::sqrt(eigenvalue);
    // The projected block inherits the rounding of every entry of DΦ (ε ‖K‖ against the mode's
    // own hω² in its lower left entry); the step of the mode's oscillator has only its own.
    block_eigenvalues(x_x, x_y, y_x, y_y, mode, h);
    const ModalOscillator oscillator(eigenvalue);
    State modal_state = oscillator.initial_state();
    modal_method->reset(oscillator, modal_state, h);
    Eigen::MatrixXd block;
    if (modal_method->has_step_tangent(oscillator) &&
        modal_method->step_tangent(oscillator, modal_state, h, block).ok && block.allFinite() &&
        std::max({std::abs(block(0, 0) - x_x), std::abs(block(0, 1) - x_y),
                  std::abs(block(1, 0) - y_x), std::abs(block(1, 1) - y_y)}) <= block_tolerance) {
      block_eigenvalues(block(0, 0), block(0, 1), block(1, 0), block(1, 1), mode, h);
    }
    modes.push_back(mode);
  }
  return modes;
}

void add_normal_mode_metrics(const MethodFactory& factory, const Problem& problem, double h,
                             const std::vector<std::string>& names,
                             std::map<std::string, double>& metrics) {
  const bool frequency = requested(names, metric::mode_freq_err_max);
  const bool damping = requested(names, metric::mode_damping_max);
  if (!frequency && !damping) return;
  const std::vector<DiscreteMode> modes = discrete_normal_modes(factory, problem, h);
  if (modes.empty()) return;
  // Rigid modes (ω = 0 to rounding, a free chain's translation) have no relative error.
  const double rigid = 1e-8 * modes.back().omega;
  double frequency_error = 0, damping_error = 0;
  for (const DiscreteMode& mode : modes) {
    if (mode.omega > rigid) {
      frequency_error =
          std::max(frequency_error, std::abs(mode.omega_discrete - mode.omega) / mode.omega);
    }
    damping_error = std::max(damping_error, std::abs(mode.amplitude - 1));
  }
  if (frequency) metrics[metric::mode_freq_err_max.key()] = frequency_error;
  if (damping) metrics[metric::mode_damping_max.key()] = damping_error;
}

void add_period_observer(const ObserverContext& context, ObserverList& observers) {
  const Problem& problem = context.problem;
  if (requested(context.metrics, metric::period_measured) && !problem.has(kForce) &&
      problem.dof() >= 1) {
    observers.push_back(std::make_unique<ZeroCrossingPeriodObserver>());
  }
}

void add_energy_growth_observer(const ObserverContext& context, ObserverList& observers) {
  if (requested(context.metrics, metric::energy_growth_exponent) && !context.problem.has(kForce)) {
    observers.push_back(std::make_unique<EnergyGrowthObserver>());
  }
}

namespace {

// symplecticity_defect and the normal-mode metrics read the method's one-step map, not the
// trajectory: computed in finish() from the problem's initial state, whatever the run did.
class StepMapObserver : public Observer {
 public:
  StepMapObserver(const Problem& problem, MethodFactory method, double h,
                  std::vector<std::string> names, bool defect)
      : problem_(problem),
        method_(std::move(method)),
        h_(h),
        names_(std::move(names)),
        defect_(defect) {}
  void begin(const Problem&, const State&, double) override {}
  void observe(const Problem&, const State&) override {}
  void finish(std::map<std::string, double>& metrics) const override {
    if (defect_) {
      metrics[metric::symplecticity_defect.key()] =
          symplecticity_defect(method_, problem_, problem_.initial_state(), h_);
    }
    add_normal_mode_metrics(method_, problem_, h_, names_, metrics);
  }

 private:
  const Problem& problem_;
  MethodFactory method_;
  double h_;
  std::vector<std::string> names_;
  bool defect_;
};

}  // namespace

std::unique_ptr<Observer> make_step_map_observer(const MethodFactory& method,
                                                 const Problem& problem, double h,
                                                 const std::vector<std::string>& names) {
  const bool defect = requested(names, metric::symplecticity_defect) &&
                      symplecticity_defect_applies(method.prototype(), problem);
  const bool modes =
      requested(names, metric::mode_freq_err_max) || requested(names, metric::mode_damping_max);
  if (!defect && !modes) return nullptr;
  return std::make_unique<StepMapObserver>(problem, method, h, names, defect);
}

void add_step_map_observer(const ObserverContext& context, ObserverList& observers) {
  if (context.method == nullptr) return;
  if (auto observer =
          make_step_map_observer(*context.method, context.problem, context.dt, context.metrics)) {
    observers.push_back(std::move(observer));
  }
}

}  // namespace geomint
