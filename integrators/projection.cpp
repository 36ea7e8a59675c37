// Projection onto the energy surface H(y) = H(y₀) over a Gauss base step (GNI §IV.4 standard
// projection; §V.4.1 symmetric projection, Hairer 2000, BIT 40 726–734): keeps H to round-off and
// the base's order; the symmetric variant keeps the base's symmetry too, neither is symplectic.
#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "problems/mass_operator.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// y = (q, p), ∇H(y) = (∇V(q), M⁻¹p) for separable H = ½pᵀM⁻¹p + V(q), projected along in the
// Euclidean metric of (q, p) as in GNI.
//  standard (symmetric=false): ỹ₁ = Φ_h(y₀), then y₁ = ỹ₁ + λ∇H(y₁) with H(y₁) = H(y₀).
//  symmetric (symmetric=true): ỹ₀ = y₀ + μ∇H(y₀), ỹ₁ = Φ_h(ỹ₀), y₁ = ỹ₁ + μ∇H(y₁), H(y₁) = H(y₀)
//  — the same μ at both ends makes the map symmetric whenever Φ_h is (GNI Thm V.4.2); the standard
//  projection is not, which is why its energy is exact but its long-time phase/angle errors are not
//  those of a symmetric method (GNI §V.4, Fig. 4.1): the negative control.
// The symmetric μ solves r(μ) = λ(μ) − μ = 0, λ(μ) the multiplier of the end projection of
// ỹ₁(μ) at its own λ: λ(μ) ≈ λ(0) − μ to first order (DΦ_h = I + O(h)), so the first pass takes
// the average μ + r/2 (which contracts by O(h)) and the next ones the secant. It stops when μ and λ
// agree to round-off in the state; the returned y₁ is the end projection with λ, so H(y₁) = H(y₀)
// to round-off whatever the base's Newton tolerance, and the symmetry holds to |λ − μ|·|∇H|
// (round-off).
class EnergyProjection final : public Integrator {
 public:
  EnergyProjection(std::string base_spec, std::unique_ptr<Integrator> base, bool symmetric)
      : base_spec_(std::move(base_spec)), base_(std::move(base)), symmetric_(symmetric) {}

  MethodInfo info() const override {
    const MethodInfo base = base_->info();
    unsigned flags = kImplicit | kNeedsHessian | kConservativeOnly | kEnergyPreserving;
    if (symmetric_ && (base.flags & kSymmetric)) flags |= kSymmetric;
    return {"projection", base.order, flags,
            fmt::format("{} projection onto H = H(y0) over {}; {}",
                        symmetric_ ? "symmetric" : "standard (non-symmetric)", base_spec_,
                        symmetric_ ? "Hairer 2000, GNI §V.4.1" : "GNI §IV.4")};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return base_->predicted_linear_stability();  // the projection only rescales onto H = H₀
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    base_->reset(problem, state, h);
    own_ = Counters{};
    // The surface is H = H(y₀) of the run's start: projecting onto each step's own H(y_k) would
    // let the rounding of H random-walk (measured: 2e-13 relative after 6 000 steps on Kepler).
    target_energy_ = energy(problem, state.q, state.p);
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    const StepStatus status =
        symmetric_ ? symmetric_step(problem, state, h) : standard_step(problem, state, h);
    // The base counts its own evaluations and solves; the projection adds its gradients and
    // potentials. A projected step is one step.
    const long steps = counters_.steps + (status.ok ? 1 : 0);
    counters_ = base_->counters();
    counters_.force_evals += own_.force_evals;
    counters_.energy_evals += own_.energy_evals;
    counters_.steps = steps;
    return status;
  }

 private:
  StepStatus standard_step(const Problem& problem, State& state, double h) {
    const double energy0 = target_energy_;
    const double t0 = state.t;
    const StepStatus status = base_->step(problem, state, h);
    if (!status.ok) return status;
    double lambda = 0.0;
    if (!project(problem, energy0, state, lambda)) return projection_failure();
    state.t = t0 + h;
    return StepStatus::success();
  }

  StepStatus symmetric_step(const Problem& problem, State& state, double h) {
    const double energy0 = target_energy_;
    Vec grad_q0, grad_p0;
    projection_direction(problem, state.q, state.p, grad_q0, grad_p0);
    double mu = 0.0, previous_mu = 0.0, previous_residual = 0.0;
    State end;
    for (int pass = 0; pass < kMaxPasses; ++pass) {
      end = state;
      end.q += mu * grad_q0;
      end.p += mu * grad_p0;
      const StepStatus status = base_->step(problem, end, h);
      if (!status.ok) return status;
      double lambda = mu;
      if (!project(problem, energy0, end, lambda)) return projection_failure();
      // λ − μ moves y₁ by (λ − μ)∇H(y₁): done when that is lost in the rounding of y₁.
      const double state_size = robust_norm(end.q, end.p);
      if (std::abs(lambda - mu) * last_gradient_norm_ <= 4 * kEpsilon * state_size) {
        state.q = end.q;
        state.p = end.p;
        state.t += h;
        return StepStatus::success();
      }
      // Secant on r(μ) = λ(μ) − μ once two passes exist (r′ ≈ −2 + O(h) is well away from 0);
      // the damped average μ + r/2 on the first pass.
      const double residual = lambda - mu;
      double next = mu + 0.5 * residual;
      if (pass > 0 && residual != previous_residual) {
        const double secant = mu - residual * (mu - previous_mu) / (residual - previous_residual);
        if (std::isfinite(secant)) next = secant;
      }
      previous_mu = mu;
      previous_residual = residual;
      mu = next;
    }
    return StepStatus::failure(
        "projection_max_iter",
        fmt::format("symmetric projection: the multiplier did not settle in {} passes",
                    kMaxPasses));
  }

  // y ← ỹ + λ∇H(y) with H(y) = energy0, from `state` = ỹ and the guess λ; Newton on the scalar
  // H(ỹ + λg) = energy0 for a frozen g = ∇H(y), then g updated, until y settles.
  bool project(const Problem& problem, double energy0, State& state, double& lambda) {
    // H is quadratic in the state: below ~1e-154 or above ~1e154 it under- or overflows and no
    // surface can be resolved, so the base step stands unprojected there (scale-free tests).
    const double energy_tilde = energy(problem, state.q, state.p);
    if (!std::isfinite(energy_tilde) || !std::isfinite(energy0) ||
        !(energy_scale_ > 1e-290 && energy_scale_ < 1e290)) {
      last_gradient_norm_ = 0.0;
      return true;
    }
    const Vec q_tilde = state.q, p_tilde = state.p;
    Vec q = q_tilde, p = p_tilde, gq, gp, hq, hp;
    for (int outer = 0; outer < kMaxPasses; ++outer) {
      projection_direction(problem, q, p, gq, gp);
      for (int inner = 0; inner < kMaxPasses; ++inner) {
        const Vec q_trial = q_tilde + lambda * gq, p_trial = p_tilde + lambda * gp;
        const double residual = energy(problem, q_trial, p_trial) - energy0;
        if (std::abs(residual) <= 2 * kEpsilon * energy_scale_) break;
        energy_gradient(problem, q_trial, p_trial, hq, hp);
        const double slope = hq.dot(gq) + hp.dot(gp);
        if (!(std::abs(slope) > 0.0) || !std::isfinite(residual)) return false;
        const double change = residual / slope;
        lambda -= change;
        if (std::abs(change) <= kEpsilon * std::abs(lambda)) break;
      }
      const Vec q_new = q_tilde + lambda * gq, p_new = p_tilde + lambda * gp;
      const bool settled =
          robust_norm(q_new - q, p_new - p) <= 4 * kEpsilon * robust_norm(q_new, p_new);
      q = q_new;
      p = p_new;
      last_gradient_norm_ = robust_norm(gq, gp);
      if (settled) {
        state.q = q;
        state.p = p;
        return true;
      }
    }
    return false;
  }

  // H = ½pᵀM⁻¹p + V(q), and the size |T| + |V| of its terms for the round-off tests.
  double energy(const Problem& problem, const Vec& q, const Vec& p) {
    ++own_.energy_evals;
    const double kinetic = 0.5 * p.dot(MassOperator(problem).solve(q, p));
    const double potential = problem.potential(q);
    energy_scale_ = std::abs(kinetic) + std::abs(potential);
    return kinetic + potential;
  }

  void energy_gradient(const Problem& problem, const Vec& q, const Vec& p, Vec& grad_q,
                       Vec& grad_p) {
    ++own_.force_evals;
    problem.gradient(q, grad_q);
    grad_p = MassOperator(problem).solve(q, p);
  }

  // The direction G⁻¹∇H = (M⁻¹∇V(q), p) of the mass metric G = diag(M, M⁻¹): scaling M and V by
  // c (p by c) scales it exactly like the state, so the projected motion is the same (the
  // Euclidean ∇H would mix units of q and p; any constant metric keeps the symmetric variant
  // symmetric).
  void projection_direction(const Problem& problem, const Vec& q, const Vec& p, Vec& dir_q,
                            Vec& dir_p) {
    ++own_.force_evals;
    problem.gradient(q, dir_q);
    dir_q = MassOperator(problem).solve(q, dir_q);
    dir_p = p;
  }

  static StepStatus projection_failure() {
    return StepStatus::failure("projection_failed",
                               "energy projection: H(ỹ + λ∇H) = H(y₀) did not converge");
  }

  static constexpr int kMaxPasses = 50;
  std::string base_spec_;
  std::unique_ptr<Integrator> base_;
  bool symmetric_;
  Counters own_;
  double energy_scale_ = 0.0;
  double target_energy_ = 0.0;       // H(y₀) at reset()
  double last_gradient_norm_ = 0.0;  // |∇H| of the last projection's direction
};

}  // namespace

std::unique_ptr<Integrator> make_projection(Params& params) {
  const std::string base =
      params.choice("base", "gauss", {"gauss"},
                    "base step (Gauss–Legendre collocation; its order is the method's order)");
  const long stages = params.integer("s", 1, "Gauss stages of the base (order 2s)", 1, 3);
  const bool symmetric = params.flag(
      "symmetric", true,
      "symmetric projection (Hairer 2000); false: standard projection after the step, the "
      "non-symmetric negative control");
  std::string base_spec = fmt::format("{}:s={}", base, stages);
  base_spec = with_base_max_iter(params, base_spec, "projection");
  return std::make_unique<EnergyProjection>(base_spec, make_integrator(base_spec), symmetric);
}

}  // namespace geomint
