// A user's integrators, written outside the geomint tree against its installed headers
// (docs/VERIFY.md "Verify your own integrator"): a drift–kick–drift position Verlet from scratch
// (GNI §I.3.1), a deliberately broken velocity Verlet that reuses the stale force in its second
// kick, and an implicit midpoint rule that claims the general Lagrangian kind
// (docs/MECHANICS_GENERAL.md §3).
#include <memory>

#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"
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

// The implicit midpoint rule z₁ = z₀ + h f((z₀ + z₁)/2) on the Hamiltonian view of any
// L = ½vᵀM(q)v + a(q)ᵀv − V(q), through geomint's general step (dense Newton, tolerance 1e-12):
// it claims kGeneralLagrangian, so the verify kit also checks it on polar Kepler, the double
// pendulum and the charged particle. On constant-mass problems lagrangian_view() adapts them.
class GeneralMidpoint final : public Integrator {
 public:
  MethodInfo info() const override {
    return {"user_general_midpoint", 2,
            geomint::kImplicit | geomint::kSymplectic | geomint::kSymmetric |
                geomint::kVariational | geomint::kGeneralLagrangian,
            "implicit midpoint on the Hamiltonian view of a general L (user wrapper)"};
  }
  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    system_ = geomint::lagrangian_view(problem);
  }
  StepStatus step(const Problem& problem, State& state, double h) override {
    if (!system_) system_ = geomint::lagrangian_view(problem);
    return geomint::general_implicit_midpoint_step(*system_, state, h, {}, counters_);
  }

 private:
  std::shared_ptr<const geomint::LagrangianSystem> system_;
};

std::unique_ptr<Integrator> make_position_verlet(geomint::Params&) {
  return std::make_unique<PositionVerlet>();
}
std::unique_ptr<Integrator> make_stale_verlet(geomint::Params&) {
  return std::make_unique<StaleVerlet>();
}
std::unique_ptr<Integrator> make_general_midpoint(geomint::Params&) {
  return std::make_unique<GeneralMidpoint>();
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
  geomint::register_method({"user_general_midpoint",
                            "implicit midpoint on general Lagrangians (user wrapper)",
                            &make_general_midpoint,
                            {}});
}

}  // namespace user
