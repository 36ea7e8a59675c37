// Damped oscillator q̈ + 2ζω q̇ + ω² q = 0, unit mass (docs/METHOD.md §2): exact underdamped solution
// q = e^{−ζωt}(A cos ω_d t + B sin ω_d t), ω_d = ω√(1 − ζ²); the energy H = ½p² + ½ω²q² decays
// at exactly dH/dt = −2ζω v², the rate a forced variational integrator should reproduce.
#include <cmath>

#include "problems/problem.hpp"

namespace geomint {
namespace {

class DampedOscillator final : public Problem {
 public:
  DampedOscillator(double omega, double zeta, double q0, double v0)
      : omega_(omega),
        q0_(q0),
        v0_(v0),
        decay_rate_(zeta * omega),
        // (1 − ζ)(1 + ζ) keeps ω_d accurate as ζ → 1, where 1 − ζ² cancels.
        omega_d_(omega * std::sqrt((1 - zeta) * (1 + zeta))) {
    set_mass(Vec::Ones(1));
    unsigned capabilities = kHessian | kExact | kOmegaMax;
    // Without damping this is the harmonic oscillator, and the harness can use the conserved H.
    if (zeta > 0) capabilities |= kForce | kForceJacobian;
    set_capabilities(capabilities);
    // 0.05 and 50 at ω = 1; scaled by 1/ω so that every ω gets the same steps per cycle and
    // stays inside the explicit methods' stability limits (hω < 2).
    set_defaults(0.05 / omega, 50.0 / omega);
  }

  State initial_state() const override {
    return {0.0, Vec::Constant(1, q0_), Vec::Constant(1, v0_)};
  }

  double potential(const Vec& q) const override { return 0.5 * omega_ * omega_ * q[0] * q[0]; }
  void gradient(const Vec& q, Vec& g) const override {
    g = Vec::Constant(1, omega_ * omega_ * q[0]);
  }
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(1, 1);
    H.setZero();
    H.insert(0, 0) = omega_ * omega_;
    H.makeCompressed();
  }

  void force(const Vec&, const Vec& v, double, Vec& f) const override {
    f = Vec::Constant(1, -2 * decay_rate_ * v[0]);
  }
  void force_jacobian_v(const Vec&, const Vec&, double, SparseMatrix& C) const override {
    C.resize(1, 1);
    C.setZero();
    C.insert(0, 0) = 2 * decay_rate_;
    C.makeCompressed();
  }

  // A = q0, B = (v0 + ζω q0)/ω_d; differentiating and simplifying with ω_d² + ζ²ω² = ω² gives
  // q̇ = e^{−ζωt}(v0 cos ω_d t − ((ω² q0 + ζω v0)/ω_d) sin ω_d t), which avoids subtracting
  // the two nearly equal terms of the product rule.
  State exact(double t) const override {
    const double envelope = std::exp(-decay_rate_ * t);
    const double c = std::cos(omega_d_ * t);
    const double s = std::sin(omega_d_ * t);
    const double sine_amplitude = (v0_ + decay_rate_ * q0_) / omega_d_;
    const double velocity_sine_amplitude = (omega_ * omega_ * q0_ + decay_rate_ * v0_) / omega_d_;
    const double q = envelope * (q0_ * c + sine_amplitude * s);
    const double v = envelope * (v0_ * c - velocity_sine_amplitude * s);
    return {t, Vec::Constant(1, q), Vec::Constant(1, v)};
  }
  // The undamped frequency bounds the damped one ω_d and is what explicit stability depends on.
  double omega_max(const Vec&) const override { return omega_; }

 private:
  double omega_;
  double q0_;
  double v0_;
  double decay_rate_;  // ζω
  double omega_d_;     // damped angular frequency ω√(1 − ζ²)
};

}  // namespace

std::unique_ptr<Problem> make_damped_oscillator(Params& params) {
  const double omega = params.real(
      "omega", 1.0, "undamped angular frequency", [](double x) { return x > 0; }, "> 0");
  const double zeta = params.real(
      "zeta", 0.05, "damping ratio (underdamped only)", [](double x) { return x >= 0 && x < 1; },
      "in [0, 1)");
  const double q0 = params.real("q0", 1.0, "initial position");
  const double v0 = params.real("v0", 0.0, "initial velocity");
  return std::make_unique<DampedOscillator>(omega, zeta, q0, v0);
}

}  // namespace geomint
