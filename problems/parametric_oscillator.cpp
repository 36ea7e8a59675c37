// Time-dependent Hamiltonian H(q, p, t) = p²/2m + ½ m ω² (1 + ε cos νt) q² (a Mathieu
// oscillator, the modulated-stiffness case of SUNDIALS' ARKODE SPRKStep damped-harmonic example
// without the damping). Problem's potential has no t, so the modulation enters as the external
// force F(q, t) = −m ω² ε cos(νt) q, exact in the Lagrange–d'Alembert view (docs/METHOD.md §2,
// forcing); the reported energy is the unmodulated part. No closed form: errors come from the
// long-double reference generator (`geomint reference`, harness/reference_generator.hpp).
#include <cmath>
#include <numbers>

#include "problems/force.hpp"
#include "problems/oscillator_base.hpp"

namespace geomint {
namespace {

class ParametricOscillator final : public OscillatorBase, public NonConservativeForce {
 public:
  ParametricOscillator(double omega, double epsilon, double nu, double mass, double q0, double v0)
      : OscillatorBase(omega, mass, q0, v0), epsilon_(epsilon), nu_(nu) {
    set_capabilities(kHessian | kOmegaMax);
    // 125 steps per unmodulated period, ten periods.
    set_defaults(0.05 / omega, 20 * std::numbers::pi / omega);
  }

  // No has_force_jacobian(): it would claim ∂F/∂v is the whole force derivative; F depends on q
  // here, so the implicit solvers difference it instead.
  const NonConservativeForce* as_forced() const override { return this; }
  void force(const Vec& q, const Vec&, double t, Vec& f) const override {
    f = Vec::Constant(1, -stiffness() * epsilon_ * std::cos(nu_ * t) * q[0]);
  }
  // The stiffness peaks at m ω² (1 + |ε|).
  double omega_max(const Vec&) const override { return omega_ * std::sqrt(1 + std::abs(epsilon_)); }

 private:
  double epsilon_, nu_;
};

}  // namespace

std::unique_ptr<Problem> make_parametric_oscillator(Params& params) {
  const double omega =
      params.real("omega", 1.0, "unmodulated angular frequency ω", Range::above(0));
  const double epsilon =
      params.real("epsilon", 0.1, "relative stiffness modulation ε", Range::open(-1, 1));
  const double nu = params.real("nu", 1.3, "modulation frequency ν (ν = 2ω: parametric resonance)",
                                Range::at_least(0));
  const double mass = params.real("mass", 1.0, "mass m", Range::above(0));
  const double q0 = params.real("q0", 1.0, "initial position");
  const double v0 = params.real("v0", 0.0, "initial velocity");
  return std::make_unique<ParametricOscillator>(omega, epsilon, nu, mass, q0, v0);
}

}  // namespace geomint
