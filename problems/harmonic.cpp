// Harmonic oscillator H = p²/(2m) + ½ m ω² q² (Hairer, Lubich & Wanner, GNI §I.1): the linear
// test problem with exact solution q = q0 cos ωt + (v0/ω) sin ωt, p = m q̇.
#include <cmath>
#include <numbers>

#include "problems/oscillator_base.hpp"

namespace geomint {
namespace {

class Harmonic final : public OscillatorBase {
 public:
  Harmonic(double omega, double mass, double q0, double v0) : OscillatorBase(omega, mass, q0, v0) {
    set_capabilities(kHessian | kExact | kPeriod | kOmegaMax);
    // The step scales with 1/ω so that every ω gets the same 125 steps per period and stays
    // inside the explicit methods' stability limits (hω < 2 for Störmer–Verlet); ten periods.
    set_defaults(0.05 / omega, 10 * period());
  }

  State exact(double t) const override {
    const double c = std::cos(omega_ * t);
    const double s = std::sin(omega_ * t);
    const double q = q0_ * c + (v0_ / omega_) * s;
    const double v = -q0_ * omega_ * s + v0_ * c;
    return {t, Vec::Constant(1, q), Vec::Constant(1, mass_ * v)};
  }
  double period() const override { return 2 * std::numbers::pi / omega_; }
  double omega_max(const Vec&) const override { return omega_; }
};

}  // namespace

std::unique_ptr<Problem> make_harmonic(Params& params) {
  const double omega = params.real("omega", 1.0, "angular frequency", Range::above(0));
  const double mass = params.real("mass", 1.0, "mass m", Range::above(0));
  const double q0 = params.real("q0", 1.0, "initial position");
  const double v0 = params.real("v0", 0.0, "initial velocity");
  return std::make_unique<Harmonic>(omega, mass, q0, v0);
}

}  // namespace geomint
