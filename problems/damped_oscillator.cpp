// Damped, optionally driven oscillator q̈ + 2ζω q̇ + ω² q = A cos(Ωt), unit mass, every ζ ≥ 0
// (docs/METHOD.md §2): exact solution = steady state + transient (under-, critically and
// over-damped), so discrete Lagrange–d'Alembert forcing is checked against a closed form with
// time in it; undriven, H = ½p² + ½ω²q² decays at exactly dH/dt = −2ζω v².
#include <cmath>

#include "problems/force.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

class DampedOscillator final : public Problem, public NonConservativeForce {
 public:
  DampedOscillator(double omega, double zeta, double q0, double v0, double drive_amplitude,
                   double drive_omega)
      : omega_(omega),
        zeta_(zeta),
        q0_(q0),
        v0_(v0),
        decay_rate_(zeta * omega),
        drive_amplitude_(drive_amplitude),
        drive_omega_(drive_omega) {
    set_mass(Vec::Ones(1));
    set_capabilities(kHessian | kExact | kOmegaMax);
    // 0.05 and 50 at ω = 1; scaled by 1/ω so that every ω gets the same steps per cycle and
    // stays inside the explicit methods' stability limits (hω < 2).
    set_defaults(0.05 / omega, 50.0 / omega);
    steady_state_at_zero_ = steady_state(0.0);
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

  // Without damping and driving this is the harmonic oscillator, and the harness can use the
  // conserved H: no force then.
  const NonConservativeForce* as_forced() const override {
    return zeta_ > 0 || drive_amplitude_ != 0 ? this : nullptr;
  }
  bool has_force_jacobian() const override { return true; }
  void force(const Vec&, const Vec& v, double t, Vec& f) const override {
    f = Vec::Constant(1, -2 * decay_rate_ * v[0] + drive(t));
  }
  void force_jacobian_v(const Vec&, const Vec&, double, SparseMatrix& C) const override {
    C.resize(1, 1);
    C.setZero();
    C.insert(0, 0) = 2 * decay_rate_;
    C.makeCompressed();
  }

  // Steady state plus the free motion that starts from the difference of the initial state and
  // the steady state at t = 0.
  State exact(double t) const override {
    const Phase particular = steady_state(t);
    const Phase free = free_motion(q0_ - steady_state_at_zero_.q, v0_ - steady_state_at_zero_.v, t);
    return {t, Vec::Constant(1, free.q + particular.q), Vec::Constant(1, free.v + particular.v)};
  }
  // The undamped frequency bounds the damped one and is what explicit stability depends on.
  double omega_max(const Vec&) const override { return omega_; }

 private:
  struct Phase {
    double q = 0;
    double v = 0;
  };

  double drive(double t) const {
    return drive_amplitude_ == 0 ? 0.0 : drive_amplitude_ * std::cos(drive_omega_ * t);
  }

  // Solution of the homogeneous equation from (a, b) at t = 0. With a = ζω and
  // C(t), S(t) = cos(ω_d t), sin(ω_d t)/ω_d (ζ < 1), 1, t (ζ = 1) or cosh(μt), sinh(μt)/μ (ζ > 1,
  // μ = ω√(ζ² − 1)):  q = e^{−at}(a₀C + (b + a·a₀)S),  q̇ = e^{−at}(bC − (ω²a₀ + a·b)S).
  // The q̇ form avoids subtracting the two nearly equal terms of the product rule.
  Phase free_motion(double q_start, double v_start, double t) const {
    const double a = decay_rate_;
    const double q_rate_coefficient = v_start + a * q_start;
    const double v_rate_coefficient = omega_ * omega_ * q_start + a * v_start;
    double damped_c = 0;  // e^{−at}C(t)
    double damped_s = 0;  // e^{−at}S(t)
    if (zeta_ < 1) {
      // (1 − ζ)(1 + ζ) keeps ω_d accurate as ζ → 1, where 1 − ζ² cancels.
      const double omega_d = omega_ * std::sqrt((1 - zeta_) * (1 + zeta_));
      const double envelope = std::exp(-a * t);
      damped_c = envelope * std::cos(omega_d * t);
      damped_s = envelope * std::sin(omega_d * t) / omega_d;
    } else if (zeta_ == 1) {
      const double envelope = std::exp(-a * t);
      damped_c = envelope;
      damped_s = envelope * t;
    } else {
      const double mu = omega_ * std::sqrt((zeta_ - 1) * (zeta_ + 1));
      if (mu * t < 1) {
        const double envelope = std::exp(-a * t);
        damped_c = envelope * std::cosh(mu * t);
        damped_s = envelope * std::sinh(mu * t) / mu;
      } else {
        // e^{−at}cosh(μt) overflows in pieces at large t; the slow root −a + μ = −ω/(ζ + √(ζ²−1))
        // is written without the cancellation of −a + μ.
        const double slow = std::exp(-omega_ / (zeta_ + std::sqrt((zeta_ - 1) * (zeta_ + 1))) * t);
        const double fast = std::exp(-(a + mu) * t);
        damped_c = 0.5 * (slow + fast);
        damped_s = 0.5 * (slow - fast) / mu;
      }
    }
    return {q_start * damped_c + q_rate_coefficient * damped_s,
            v_start * damped_c - v_rate_coefficient * damped_s};
  }

  // Response to A cos(Ωt): Re(A e^{iΩt}/(ω² − Ω² + 2iζωΩ)); at resonance without damping
  // (Ω = ω, ζ = 0) the secular A t sin(ωt)/(2ω).
  Phase steady_state(double t) const {
    if (drive_amplitude_ == 0) return {};
    const double w = drive_omega_;
    const double detuning = omega_ * omega_ - w * w;
    const double friction = 2 * decay_rate_ * w;
    const double denominator = detuning * detuning + friction * friction;
    const double c = std::cos(w * t);
    const double s = std::sin(w * t);
    if (denominator == 0) {
      const double k = drive_amplitude_ / (2 * omega_);
      return {k * t * s, k * (s + omega_ * t * c)};
    }
    const double in_phase = drive_amplitude_ * detuning / denominator;
    const double quadrature = drive_amplitude_ * friction / denominator;
    return {in_phase * c + quadrature * s, w * (quadrature * c - in_phase * s)};
  }

  double omega_;
  double zeta_;
  double q0_;
  double v0_;
  double decay_rate_;  // ζω
  double drive_amplitude_;
  double drive_omega_;
  Phase steady_state_at_zero_;
};

}  // namespace

std::unique_ptr<Problem> make_damped_oscillator(Params& params) {
  const double omega = params.real("omega", 1.0, "undamped angular frequency", Range::above(0));
  const double zeta = params.real(
      "zeta", 0.05, "damping ratio (< 1 under-, 1 critically, > 1 overdamped)", Range::at_least(0));
  const double q0 = params.real("q0", 1.0, "initial position");
  const double v0 = params.real("v0", 0.0, "initial velocity");
  const double drive_amplitude =
      params.real("drive", 0.0, "amplitude A of the driving force A cos(Ωt) (0: undriven)");
  const double drive_omega =
      params.real("drive_omega", 1.0, "driving angular frequency Ω", Range::at_least(0));
  // The driving was added after undriven runs were committed: an undriven spec stays as it was.
  params.omit_default_from_canonical("drive");
  if (drive_amplitude == 0) params.omit_default_from_canonical("drive_omega");
  return std::make_unique<DampedOscillator>(omega, zeta, q0, v0, drive_amplitude, drive_omega);
}

}  // namespace geomint
