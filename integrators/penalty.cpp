// Quadratic penalty (docs/METHOD.md §3, the contrast PAPER.md §3 names): the constraints are
// dropped and ½k‖g(q)‖² is added to the potential, and an unconstrained base method integrates
// the result. It changes the Lagrangian (g ~ λ/k instead of 0) and adds stiffness (frequencies
// ~ √(k/m)), which is what it is here to show.
#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// The constrained problem seen without its constraints and with the penalty in V; everything
// else (masses, force, initial state) is forwarded. No exact solution: the penalised motion is
// not the constrained one (the harness measures against the real problem anyway).
class PenalisedProblem final : public Problem {
 public:
  PenalisedProblem(const Problem& base, double stiffness)
      : base_(base), constraints_(constraints_of(base)), stiffness_(stiffness) {
    set_mass(MassOperator(base).constant_diagonal());
    set_capabilities(base.capabilities() & (kHessian | kLinearMomentum | kAngularMomentum));
    set_defaults(base.default_dt(), base.default_t_end());
  }

  State initial_state() const override { return base_.initial_state(); }

  double potential(const Vec& q) const override {
    constraints_.constraint(q, g_);
    return base_.potential(q) + 0.5 * stiffness_ * g_.squaredNorm();
  }
  // ∇V + k Gᵀg.
  void gradient(const Vec& q, Vec& gradient) const override {
    base_.gradient(q, gradient);
    constraints_.constraint(q, g_);
    constraints_.constraint_jacobian(q, G_);
    gradient += stiffness_ * (G_.transpose() * g_);
  }
  // ∇²V + k(GᵀG + Σ gᵢ∇²gᵢ); the last sum is the constraint Hessian at λ = k g.
  void hessian(const Vec& q, SparseMatrix& H) const override {
    base_.hessian(q, H);
    constraints_.constraint(q, g_);
    constraints_.constraint_jacobian(q, G_);
    SparseMatrix curvature;
    constraints_.constraint_hessian(q, stiffness_ * g_, curvature);
    const SparseMatrix gauss_newton = SparseMatrix(G_.transpose() * G_);
    H = H + stiffness_ * gauss_newton + curvature;
    H.makeCompressed();
  }
  // The base's force and its Jacobian, unchanged (kForce, kForceJacobian follow from it).
  const NonConservativeForce* as_forced() const override { return base_.as_forced(); }
  Vec linear_momentum(const Vec& q, const Vec& p) const override {
    return base_.linear_momentum(q, p);
  }
  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    return base_.angular_momentum(q, p);
  }

 private:
  const Problem& base_;
  const HolonomicConstraints& constraints_;  // the base problem's, left out of this one
  double stiffness_;
  // Scratch (the Problem interface is const).
  mutable Vec g_;
  mutable SparseMatrix G_;
};

class Penalty final : public Integrator {
 public:
  Penalty(double stiffness, std::string base_name, std::unique_ptr<Integrator> base)
      : stiffness_(stiffness), base_name_(std::move(base_name)), base_(std::move(base)) {}

  // The base's order, which holds for the penalised system: against the constrained motion the
  // error levels off at the O(1/k) rod stretch as h → 0. The base's symplecticity and symmetry
  // also hold for the penalised Lagrangian only, so they are not declared (the registry suites
  // check declared flags).
  MethodInfo info() const override {
    const unsigned kept = kExplicit | kImplicit | kAdaptive | kNeedsHessian;
    return {"penalty", base_->info().order,
            (base_->info().flags & kept) | kConstrained | kConstraintsOnly,
            fmt::format("quadratic penalty k/2 |g(q)|^2 (k = {:g}) integrated by {} (PAPER.md §3 "
                        "contrast; Hairer, Lubich & Wanner, GNI §VII.1)",
                        stiffness_, base_name_)};
  }

  // The base's bound holds for h·ω with ω ~ √(k/m)|G| from the penalty, a property of the
  // problem and k, not of the harmonic test problem the prediction is checked on.
  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "penalty: the base method's limit applies to the penalty frequency sqrt(k/m)|G|, which "
        "depends on the constrained problem");
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    penalised_ = std::make_unique<PenalisedProblem>(problem, stiffness_);
    base_->reset(*penalised_, state, h);
  }

  StepStatus step(const Problem&, State& state, double h) override {
    const StepStatus status = base_->step(*penalised_, state, h);
    counters_ = base_->counters();
    return status;
  }

  StepStatus adaptive_step(const Problem&, State& state, double t_stop) override {
    const StepStatus status = base_->adaptive_step(*penalised_, state, t_stop);
    counters_ = base_->counters();
    return status;
  }

 private:
  double stiffness_;
  std::string base_name_;
  std::unique_ptr<Integrator> base_;
  std::unique_ptr<PenalisedProblem> penalised_;
};

}  // namespace

std::unique_ptr<Integrator> make_penalty(Params& params) {
  const double stiffness = params.real(
      "k", 1e4, "penalty stiffness k in k/2 |g(q)|^2 (the constraint error goes like 1/k)",
      Range::above(0));
  // Any registered method that does not handle constraints itself, with its default parameters
  // (a spec with its own parameters would clash with this spec's commas).
  std::vector<std::string> bases;
  for (const auto& entry : integrator_registry()) {
    if (entry.name == "penalty") continue;
    if (!(make_integrator(entry.name)->info().flags & kConstrained)) bases.push_back(entry.name);
  }
  const std::string base = params.choice(
      "base", "stormer_verlet", bases,
      "unconstrained method (registry name, default parameters) that integrates the penalised "
      "system");
  const std::string base_spec = with_base_max_iter(params, base, "penalty");
  return std::make_unique<Penalty>(stiffness, base, make_integrator(base_spec));
}

}  // namespace geomint
