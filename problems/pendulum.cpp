// Planar pendulum θ̈ = −ω0² sin θ (unit mass, V = ω0²(1 − cos θ)), exact through Jacobi elliptic
// functions (DLMF §22.19(i)): librating, sin(θ/2) = k sn(u0 + ω0 t | k²); rotating (k > 1),
// θ/2 = am(u0 ± k ω0 t | 1/k²). Modulus and complementary modulus are kept apart so that the
// solution stays exact to rounding next to the separatrix k = 1.
#include "problems/pendulum.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_mode.h>
#include <gsl/gsl_sf_ellint.h>

#include <cfloat>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "problems/problem.hpp"

namespace geomint {
namespace {

constexpr double kPi = std::numbers::pi;

void check_gsl(int status, const char* function) {
  if (status != GSL_SUCCESS) {
    throw std::runtime_error(std::string("pendulum: ") + function +
                             " failed: " + gsl_strerror(status));
  }
}

// Carlson's R_F; K and F below use it with the complementary parameter m' = 1 − m given
// directly, which GSL's K(k) and F(φ, k) would recompute as 1 − k² and lose near k = 1.
double carlson_rf(double x, double y, double z) {
  gsl_sf_result result;
  check_gsl(gsl_sf_ellint_RF_e(x, y, z, GSL_PREC_DOUBLE, &result), "gsl_sf_ellint_RF_e");
  return result.val;
}

// K(m) = R_F(0, m', 1) (DLMF 19.25.1).
double complete_elliptic_k(double complementary_m) { return carlson_rf(0, complementary_m, 1); }

// F(φ | m) = sin φ R_F(cos²φ, cos²φ + m' sin²φ, 1) for |φ| ≤ π/2 (DLMF 19.25.5, with
// 1 − m sin²φ written without cancellation); the outer quarters use F(π − φ) = 2K − F(φ).
double incomplete_elliptic_f(double phi, double complementary_m, double quarter_period) {
  const bool outer_quarter = std::abs(phi) > kPi / 2;
  const double inner_phi = outer_quarter ? std::copysign(kPi, phi) - phi : phi;
  const double s = std::sin(inner_phi);
  const double c = std::cos(inner_phi);
  const double value = s * carlson_rf(c * c, c * c + complementary_m * s * s, 1);
  return outer_quarter ? std::copysign(2 * quarter_period, phi) - value : value;
}

struct Jacobi {
  double am, sn, cn, dn;
};

// am, sn, cn, dn of (u | m) by the descending Landen/AGM scheme (DLMF 22.20(ii)) started from
// b0 = √m' and c1 = m / (2(1 + √m')), so that nothing is formed as 1 − m. am is continuous in u.
Jacobi jacobi_elliptic(double u, double m, double complementary_m) {
  constexpr int kMaxLevels = 32;
  double a[kMaxLevels + 1], c[kMaxLevels + 1];
  a[0] = 1;
  double b = std::sqrt(complementary_m);
  c[1] = m / (2 * (1 + b));
  int levels = 0;
  while (levels < kMaxLevels && (levels == 0 || std::abs(c[levels]) > DBL_EPSILON * a[levels])) {
    ++levels;
    const double a_next = 0.5 * (a[levels - 1] + b);
    if (levels > 1) c[levels] = c[levels - 1] * c[levels - 1] / (4 * a_next);
    b = std::sqrt(a[levels - 1] * b);
    a[levels] = a_next;
    if (c[1] == 0) break;
  }
  double phi = std::ldexp(a[levels] * u, levels);
  for (int n = levels; n >= 1; --n) phi = 0.5 * (phi + std::asin(c[n] / a[n] * std::sin(phi)));
  const double sn = std::sin(phi);
  const double cn = std::cos(phi);
  // dn = √(1 − m sn²) = √(cn² + m' sn²) without cancellation.
  return {phi, sn, cn, std::sqrt(cn * cn + complementary_m * sn * sn)};
}

}  // namespace

PendulumMotion::PendulumMotion(double theta0, double omega0, double v0) : omega0_(omega0) {
  // k² = E / (2 ω0²) with E = ½ θ̇² + 2 ω0² sin²(θ/2); the motion librates iff k < 1. With
  // s = sin(θ0/2), c = |cos(θ0/2)|, w = |v0|/(2ω0): k² = s² + w² and 1 − k² = (c − w)(c + w),
  // which keeps its relative accuracy at θ0 = π − 1e-6 where 1 − k² ~ 1e-13.
  const double reduced_theta0 = std::remainder(theta0, 2 * kPi);  // in [−π, π]
  // The formulas live on [−π, π]; whole turns in θ0 are carried as an offset.
  turns_offset_ = theta0 - reduced_theta0;
  const double s = std::sin(reduced_theta0 / 2);
  const double c = std::cos(reduced_theta0 / 2);
  const double w = std::abs(v0) / (2 * omega0);
  const double modulus_squared = s * s + w * w;
  const double one_minus_k2 = (c - w) * (c + w);
  modulus_ = std::sqrt(modulus_squared);
  // On the separatrix itself (and within k' < 1e-10 of it) the period is infinite or too
  // ill-conditioned to call anything exact.
  has_exact_ = std::abs(one_minus_k2) >= 1e-20;
  librating_ = one_minus_k2 > 0;
  if (has_exact_ && librating_) {
    parameter_ = modulus_squared;
    complementary_parameter_ = one_minus_k2;
    quarter_period_ = complete_elliptic_k(complementary_parameter_);
    // am(u0) = φ0 with k sn(u0) = sin(θ0/2) and 2 k ω0 cn(u0) = v0; from rest at θ0 > 0
    // this gives φ0 = π/2 and u0 = K.
    const double phi0 = std::atan2(s, v0 / (2 * omega0));
    phase0_ = incomplete_elliptic_f(phi0, complementary_parameter_, quarter_period_);
  } else if (has_exact_) {
    // Rotation: θ/2 = am(u0 + σ k ω0 t | 1/k²), σ = sign(v0), u0 = F(θ0/2 | 1/k²);
    // 1 − 1/k² = (w − c)(w + c)/k².
    parameter_ = 1 / modulus_squared;
    complementary_parameter_ = -one_minus_k2 / modulus_squared;
    quarter_period_ = complete_elliptic_k(complementary_parameter_);
    direction_ = v0 < 0 ? -1.0 : 1.0;
    phase0_ = incomplete_elliptic_f(reduced_theta0 / 2, complementary_parameter_, quarter_period_);
  }
}

PendulumMotion::Angle PendulumMotion::at(double t) const {
  if (librating_) {
    // sn, cn are 4K-periodic; reducing the argument exactly (std::remainder) keeps the
    // Landen iteration accurate at large t.
    const double u = std::remainder(phase0_ + omega0_ * t, 4 * quarter_period_);
    const Jacobi f = jacobi_elliptic(u, parameter_, complementary_parameter_);
    // cos(θ/2) = dn, so atan2 stays well conditioned near θ = ±π where arcsin is not.
    return {turns_offset_ + 2 * std::atan2(modulus_ * f.sn, f.dn), 2 * modulus_ * omega0_ * f.cn};
  }
  // am(u + 2K) = am(u) + π: whole half-periods of am are counted, the rest is reduced.
  const double u = phase0_ + direction_ * modulus_ * omega0_ * t;
  const double half_turns = std::round(u / (2 * quarter_period_));
  const double reduced_u = u - half_turns * 2 * quarter_period_;
  const Jacobi f = jacobi_elliptic(reduced_u, parameter_, complementary_parameter_);
  return {turns_offset_ + 2 * f.am + 2 * kPi * half_turns,
          2 * direction_ * modulus_ * omega0_ * f.dn};
}

// Libration: 4K(k)/ω0; rotation: the time of one revolution, 2K(1/k)/(k ω0).
double PendulumMotion::period() const {
  if (librating_) return 4 * quarter_period_ / omega0_;
  return 2 * quarter_period_ / (modulus_ * omega0_);
}

namespace {

class Pendulum final : public Problem {
 public:
  Pendulum(double theta0, double omega0, double v0)
      : theta0_(theta0), omega0_(omega0), v0_(v0), motion_(theta0, omega0, v0) {
    unsigned capabilities = kHessian | kOmegaMax;
    if (motion_.has_exact()) capabilities |= kExact | kPeriod;
    set_mass(Vec::Ones(1));
    set_capabilities(capabilities);
    // Same steps per small-amplitude period for every ω0 (explicit stability needs h ω0 < 2).
    set_defaults(0.05 / omega0, 50.0 / omega0);
  }

  State initial_state() const override {
    return {0.0, Vec::Constant(1, theta0_), Vec::Constant(1, v0_)};
  }

  // 2 sin²(θ/2) instead of 1 − cos θ keeps relative accuracy for small angles.
  double potential(const Vec& q) const override {
    const double s = std::sin(q[0] / 2);
    return 2 * omega0_ * omega0_ * s * s;
  }
  void gradient(const Vec& q, Vec& g) const override { PendulumGradient{omega0_}(q, g); }
  FixedGradient fixed_gradient() const override { return PendulumGradient{omega0_}; }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    H.resize(1, 1);
    H.setZero();
    H.insert(0, 0) = omega0_ * omega0_ * std::cos(q[0]);
    H.makeCompressed();
  }

  State exact(double t) const override {
    if (!has(kExact)) return Problem::exact(t);
    const PendulumMotion::Angle angle = motion_.at(t);
    return {t, Vec::Constant(1, angle.theta), Vec::Constant(1, angle.theta_dot)};
  }
  double period() const override {
    if (!has(kPeriod)) return Problem::period();
    return motion_.period();
  }
  // The linearised frequency ω0 √(cos θ) is largest at the bottom (on the upper half the
  // linearisation is unstable, not oscillatory), so ω0 bounds it for every θ.
  double omega_max(const Vec&) const override { return omega0_; }

 private:
  double theta0_;
  double omega0_;
  double v0_;
  PendulumMotion motion_;
};

}  // namespace

std::unique_ptr<Problem> make_pendulum(Params& params) {
  // An angle of 1e3 rad still resolves 1e-13 rad; far beyond, θ + hθ̇ loses the step.
  const double theta0 =
      params.real("theta0", 0.5, "initial angle from the bottom (rad)", Range::magnitude(1000));
  const double omega0 =
      params.real("omega0", 1.0, "small-amplitude angular frequency sqrt(g/L)", Range::above(0));
  const double v0 = params.real(
      "v0", 0.0, "initial angular velocity (released from rest by default)", Range::magnitude(1e6));
  return std::make_unique<Pendulum>(theta0, omega0, v0);
}

}  // namespace geomint
