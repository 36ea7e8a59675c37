// A user's integrators, written outside the geomint tree against its installed headers
// (docs/VERIFY.md "Verify your own integrator"): a drift–kick–drift position Verlet from scratch
// (GNI §I.3.1), and a deliberately broken velocity Verlet that reuses the stale force in its second
// kick.
#include <memory>

#include "integrators/integrator.hpp"
#include "user_extensions.hpp"

namespace user {
namespace {

using geomint::Integrator;
using geomint::MethodInfo;
using geomint::Problem;
using geomint::State;
using geomint::StepStatus;
using geomint::Vec;

// q_{1/2} = q + (h/2) M⁻¹p, p⁺ = p − h∇V(q_{1/2}), q⁺ = q_{1/2} + (h/2) M⁻¹p⁺: symplectic,
// symmetric, variational (the midpoint-type discrete Lagrangian), second order.
class PositionVerlet final : public Integrator {
 public:
  MethodInfo info() const override {
    return {"user_position_verlet", 2,
            geomint::kExplicit | geomint::kSymplectic | geomint::kSymmetric | geomint::kVariational,
            "drift-kick-drift, Hairer-Lubich-Wanner GNI (I.3.1)"};
  }
  StepStatus step(const Problem& problem, State& state, double h) override {
    state.q += 0.5 * h * problem.inverse_mass().cwiseProduct(state.p);
    eval_gradient(problem, state.q, gradient_);
    state.p -= h * gradient_;
    state.q += 0.5 * h * problem.inverse_mass().cwiseProduct(state.p);
    return StepStatus::success();
  }

 private:
  Vec gradient_;
};

// The bug: p_{1/2} = p − (h/2)∇V(q), q⁺ = q + h M⁻¹p_{1/2}, then p⁺ = p_{1/2} − (h/2)∇V(q) with
// the force of the old position instead of ∇V(q⁺). It claims what velocity Verlet is, but the
// momentum update is first order and the map's Jacobian determinant is 1 + h²V''/(2m) ≠ 1, so
// energy drifts: the verify kit must flag its order and energy checks.
class StaleVerlet final : public Integrator {
 public:
  MethodInfo info() const override {
    return {"user_stale_verlet", 2, geomint::kExplicit | geomint::kSymplectic | geomint::kSymmetric,
            "velocity Verlet with a stale second kick (broken on purpose)"};
  }
  StepStatus step(const Problem& problem, State& state, double h) override {
    eval_gradient(problem, state.q, gradient_);
    state.p -= 0.5 * h * gradient_;
    state.q += h * problem.inverse_mass().cwiseProduct(state.p);
    state.p -= 0.5 * h * gradient_;  // should be ∇V at the new q
    return StepStatus::success();
  }

 private:
  Vec gradient_;
};

std::unique_ptr<Integrator> make_position_verlet(geomint::Params&) {
  return std::make_unique<PositionVerlet>();
}
std::unique_ptr<Integrator> make_stale_verlet(geomint::Params&) {
  return std::make_unique<StaleVerlet>();
}

}  // namespace

void register_methods() {
  geomint::register_method({"user_position_verlet",
                            "drift-kick-drift position Verlet (user-written)",
                            &make_position_verlet,
                            {}});
  geomint::register_method({"user_stale_verlet",
                            "velocity Verlet with a stale force (broken on purpose)",
                            &make_stale_verlet,
                            {}});
}

}  // namespace user
