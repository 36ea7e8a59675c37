// Harmonic oscillator H = p²/(2m) + ½ m ω² q² (Hairer, Lubich & Wanner, GNI §I.1): the linear
// test problem with exact solution q = q0 cos ωt + (v0/ω) sin ωt, p = m q̇.
#include <cmath>
#include <numbers>

#include "problems/problem.hpp"

namespace geomint {
namespace {

class Harmonic final : public Problem {
 public:
  Harmonic(double omega, double mass, double q0, double v0)
      : omega_(omega), mass_(mass), q0_(q0), v0_(v0) {
    set_mass(Vec::Constant(1, mass));
    set_capabilities(kHessian | kExact | kPeriod | kOmegaMax);
    // The step scales with 1/ω so that every ω gets the same 125 steps per period and stays
    // inside the explicit methods' stability limits (hω < 2 for Störmer–Verlet); ten periods.
    set_defaults(0.05 / omega, 10 * period());
  }

  State initial_state() const override {
    return {0.0, Vec::Constant(1, q0_), Vec::Constant(1, mass_ * v0_)};
  }

  double potential(const Vec& q) const override { return 0.5 * stiffness() * q[0] * q[0]; }
  void gradient(const Vec& q, Vec& g) const override { HarmonicGradient{stiffness()}(q, g); }
  FixedGradient fixed_gradient() const override { return HarmonicGradient{stiffness()}; }
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(1, 1);
    H.setZero();
    H.insert(0, 0) = stiffness();
    H.makeCompressed();
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

 private:
  double stiffness() const { return mass_ * omega_ * omega_; }

  double omega_;
  double mass_;
  double q0_;
  double v0_;
};

}  // namespace

std::unique_ptr<Problem> make_harmonic(Params& params) {
  const auto positive = [](double x) { return x > 0; };
  const double omega = params.real("omega", 1.0, "angular frequency", positive, "> 0");
  const double mass = params.real("mass", 1.0, "mass m", positive, "> 0");
  const double q0 = params.real("q0", 1.0, "initial position");
  const double v0 = params.real("v0", 0.0, "initial velocity");
  return std::make_unique<Harmonic>(omega, mass, q0, v0);
}

}  // namespace geomint
