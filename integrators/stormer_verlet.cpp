// Störmer–Verlet, kick–drift–kick (velocity Verlet): the VI of L_d = (h/2)[L(q_k, v) +
// L(q_{k+1}, v)] (docs/METHOD.md §1; Hairer, Lubich & Wanner, GNI §I.1.4 and §VI.3, eq. (3.4)).
#include "integrators/integrator.hpp"

namespace geomint {
namespace {

//   p½ = p + (h/2)[−∇V(q) + F(q, M⁻¹p, t)]
//   q⁺ = q + h M⁻¹p½
//   p⁺ = p½ + (h/2)[−∇V(q⁺) + F(q⁺, M⁻¹p½, t + h)]
// Without F this is symmetric, symplectic and second order. A velocity-dependent F would make
// the second half-kick implicit in v⁺; taking the half-step velocity M⁻¹p½ keeps the scheme
// explicit ("Verlet with forces") at the price of first order in the force coupling and of
// symmetry. Position- and time-dependent forces keep second order.
//
// First same as last: ∇V(q⁺) of one step is ∇V(q) of the next, so after the first step each
// step costs one gradient. The cached gradient is used only when the incoming q is bitwise the
// q⁺ it was computed at (and the problem is the same object), so a caller that edits the state
// between steps gets a fresh evaluation, never a stale one.
class StormerVerlet final : public Integrator {
 public:
  MethodInfo info() const override {
    return {"stormer_verlet", 2, kExplicit | kSymplectic | kSymmetric | kVariational,
            "Stormer-Verlet (velocity Verlet), GNI §I.1.4, §VI.3; docs/METHOD.md §1"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(2.0);  // trace of the step matrix 2 − (hω)² (GNI §I.5)
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    cached_problem_ = nullptr;
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    const Vec& inverse_mass = problem.inverse_mass();
    const bool cache_hit =
        cached_problem_ == &problem && cached_q_.size() == state.q.size() && cached_q_ == state.q;
    if (!cache_hit) eval_gradient(problem, state.q, gradient_);
    const bool forced = problem.has(kForce);

    if (forced) {
      eval_force(problem, state.q, inverse_mass.cwiseProduct(state.p), state.t, force_);
      // eval_force is not counted; it is a force-field evaluation of its own when the gradient
      // at this point came from the cache.
      if (cache_hit) ++counters_.force_evals;
    }
    state.p -= (h / 2) * gradient_;
    if (forced) state.p += (h / 2) * force_;
    state.q += h * inverse_mass.cwiseProduct(state.p);
    state.t += h;
    eval_gradient(problem, state.q, gradient_);
    if (forced) {
      eval_force(problem, state.q, inverse_mass.cwiseProduct(state.p), state.t, force_);
      state.p += (h / 2) * force_;
    }
    state.p -= (h / 2) * gradient_;

    cached_problem_ = &problem;
    cached_q_ = state.q;
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  const Problem* cached_problem_ = nullptr;
  Vec cached_q_;  // q at which gradient_ = ∇V(q) was evaluated
  Vec gradient_, force_;
};

}  // namespace

std::unique_ptr<Integrator> make_stormer_verlet(Params&) {
  return std::make_unique<StormerVerlet>();
}

}  // namespace geomint
