// Modified energies H̃ = H + h²H₂ (GNI §IX.3; derivation in docs/METHOD.md §10):
// a symplectic method of order 2 keeps H̃ to O(h⁴) over exponentially long times, so the error of
// H̃ falls like h⁴ where the error of H falls like h².
#include "harness/modified_energy.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "harness/metrics.hpp"
#include "harness/run_spec.hpp"
#include "problems/lagrangian.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {

std::optional<ModifiedEnergyCorrection> modified_energy_correction(const std::string& method_name) {
  // Strang splitting with the kicks outside (velocity Verlet): H₂ = −(1/24){V,{V,T}} +
  // (1/12){T,{T,V}} in the bracket form, which for separable H reads as below.
  if (method_name == "stormer_verlet") return ModifiedEnergyCorrection{1.0 / 12, -1.0 / 24};
  // The same splitting with T and V exchanged (drifts outside).
  if (method_name == "position_verlet") return ModifiedEnergyCorrection{-1.0 / 24, 1.0 / 12};
  // H₂ = −(1/24)∇²H(f, f) with f = J⁻¹∇H = (M⁻¹p, −∇V).
  if (method_name == "implicit_midpoint") return ModifiedEnergyCorrection{-1.0 / 24, -1.0 / 24};
  return std::nullopt;
}

std::string modified_energy_not_applicable(const Integrator& method, const Problem& problem,
                                           double h) {
  const MethodInfo info = method.info();
  if (!modified_energy_correction(info.name)) {
    return fmt::format(
        "no known h² correction for {} (known: stormer_verlet, position_verlet, "
        "implicit_midpoint)",
        info.name);
  }
  if ((info.flags & kAdaptive) != 0 || !(h > 0)) return "needs a fixed step h > 0";
  if (problem.has(kFirstOrderOnly)) return "first-order problem: no Hamiltonian";
  if (problem.has(kForce)) return "forced problem: no conserved Hamiltonian";
  if (problem.has(kConstraints)) return "constrained problem: the correction is for free motion";
  if (problem.kind() == ProblemKind::kLagrangian)
    return "non-separable problem: the correction assumes ½pᵀM⁻¹p + V";
  if (!problem.has(kHessian)) return "problem has no Hessian ∇²V";
  return "";
}

double modified_energy(const ModifiedEnergyCorrection& correction, const Problem& problem,
                       const Vec& q, const Vec& p, double h) {
  const Vec velocity = MassOperator(problem).solve(q, p);
  Vec gradient;
  problem.gradient(q, gradient);
  SparseMatrix hessian;
  problem.hessian(q, hessian);
  const double curvature = velocity.dot(hessian * velocity);
  const double force = gradient.dot(MassOperator(problem).solve(q, gradient));
  return problem.energy(q, p) +
         h * h * (correction.curvature * curvature + correction.force * force);
}

namespace {

// The largest |H(q_k, p_k) − H(q_0, p_0)| and |H̃(q_k, p_k) − H̃(q_0, p_0)| over a run.
struct EnergyErrors {
  double energy = 0, modified = 0;
  void add(double energy_error, double modified_error) {
    // A NaN state (a failed step) makes the errors NaN rather than being skipped by max().
    energy = std::isnan(energy_error) ? energy_error : std::max(energy, energy_error);
    modified = std::isnan(modified_error) ? modified_error : std::max(modified, modified_error);
  }
};

// Observes the run at h; in finish() it integrates the same span again at h/2 and h/4 (fresh
// integrators, the same number of steps times 2 and 4) so that the slopes of both errors against
// h are fitted over three steps: modified_energy_err_slope ≈ 4 and energy_err_slope ≈ 2 for the
// three methods with a known correction (docs/METHOD.md §10).
class ModifiedEnergyObserver : public Observer {
 public:
  ModifiedEnergyObserver(MethodFactory method, ModifiedEnergyCorrection correction, double h)
      : method_(std::move(method)), correction_(correction), h_(h) {}
  void begin(const Problem& problem, const State& state, double) override {
    problem_ = &problem;
    initial_ = state;
  }
  void observe(const Problem& problem, const State& state) override {
    if (state.t <= initial_.t) return;
    ++steps_;
    add(problem, state, h_, at_h_);
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[metric::modified_energy_err_max.key()] = at_h_.modified / scale(*problem_);
    std::vector<double> log_steps = {std::log(h_)}, log_energy = {std::log(at_h_.energy)},
                        log_modified = {std::log(at_h_.modified)};
    for (int refinement : {2, 4}) {
      const auto errors = rerun(refinement);
      if (!errors || !(errors->energy > 0) || !(errors->modified > 0)) return;
      log_steps.push_back(std::log(h_ / refinement));
      log_energy.push_back(std::log(errors->energy));
      log_modified.push_back(std::log(errors->modified));
    }
    if (!(at_h_.energy > 0) || !(at_h_.modified > 0)) return;
    metrics[metric::modified_energy_err_slope.key()] = least_squares_slope(log_steps, log_modified);
    metrics[metric::energy_err_slope.key()] = least_squares_slope(log_steps, log_energy);
  }

 private:
  static double scale(const Problem& problem, const State& state) {
    const double energy0 = problem.energy(state.q, state.p);
    return std::abs(energy0) > 0 ? std::abs(energy0) : 1.0;
  }
  double scale(const Problem& problem) const { return scale(problem, initial_); }

  // Absolute errors (the common scale cancels in the slopes).
  void add(const Problem& problem, const State& state, double h, EnergyErrors& errors) const {
    errors.add(std::abs(problem.energy(state.q, state.p) - problem.energy(initial_.q, initial_.p)),
               std::abs(modified_energy(correction_, problem, state.q, state.p, h) -
                        modified_energy(correction_, problem, initial_.q, initial_.p, h)));
  }

  // The errors of the run at h/refinement over the same span; nullopt when a step fails.
  std::optional<EnergyErrors> rerun(int refinement) const {
    const double h = h_ / refinement;
    auto method = method_.make();
    State state = initial_;
    method->reset(*problem_, state, h);
    EnergyErrors errors;
    for (long k = 0; k < steps_ * refinement; ++k) {
      if (!method->step(*problem_, state, h).ok) return std::nullopt;
      add(*problem_, state, h, errors);
    }
    return errors;
  }

  MethodFactory method_;
  ModifiedEnergyCorrection correction_;
  double h_;
  const Problem* problem_ = nullptr;
  State initial_;
  long steps_ = 0;
  EnergyErrors at_h_;
};

}  // namespace

std::unique_ptr<Observer> make_modified_energy_observer(const MethodFactory& method,
                                                        const Problem& problem, double h,
                                                        const std::vector<std::string>& names) {
  if (!requested(names, metric::modified_energy_err_max)) return nullptr;
  if (!modified_energy_not_applicable(method.prototype(), problem, h).empty()) return nullptr;
  return std::make_unique<ModifiedEnergyObserver>(
      method, *modified_energy_correction(method.info().name), h);
}

void add_modified_energy_observer(const ObserverContext& context, ObserverList& observers) {
  if (context.method == nullptr) return;
  if (auto observer = make_modified_energy_observer(*context.method, context.problem, context.dt,
                                                    context.metrics)) {
    observers.push_back(std::move(observer));
  }
}

}  // namespace geomint
