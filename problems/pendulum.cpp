// Planar pendulum θ̈ = −ω0² sin θ (unit mass, V = ω0²(1 − cos θ)). While it librates the exact
// solution is sin(θ/2) = k sn(u0 + ω0 t | k²), θ̇ = 2 k ω0 cn(u0 + ω0 t | k²) (DLMF §22.19(i)).
#include <gsl/gsl_errno.h>
#include <gsl/gsl_mode.h>
#include <gsl/gsl_sf_ellint.h>
#include <gsl/gsl_sf_elljac.h>

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

double complete_elliptic_k(double k) {
  gsl_sf_result result;
  check_gsl(gsl_sf_ellint_Kcomp_e(k, GSL_PREC_DOUBLE, &result), "gsl_sf_ellint_Kcomp_e");
  return result.val;
}

// Incomplete F(φ, k) for φ in [−π, π]. The outer quarters are reflected into |φ| ≤ π/2 with
// F(π − φ) = 2K − F(φ), so nothing depends on how a GSL version treats larger |φ|.
double incomplete_elliptic_f(double phi, double k, double quarter_period) {
  const bool outer_quarter = std::abs(phi) > kPi / 2;
  const double inner_phi = outer_quarter ? std::copysign(kPi, phi) - phi : phi;
  gsl_sf_result result;
  check_gsl(gsl_sf_ellint_F_e(inner_phi, k, GSL_PREC_DOUBLE, &result), "gsl_sf_ellint_F_e");
  return outer_quarter ? std::copysign(2 * quarter_period, phi) - result.val : result.val;
}

class Pendulum final : public Problem {
 public:
  Pendulum(double theta0, double omega0, double v0) : theta0_(theta0), omega0_(omega0), v0_(v0) {
    // k² = E / (2 ω0²) with E = ½ θ̇² + 2 ω0² sin²(θ/2); the motion librates iff k < 1.
    const double half_angle_sine = std::sin(theta0 / 2);
    modulus_ = std::hypot(half_angle_sine, v0 / (2 * omega0));
    // Closer to the separatrix K(k) and the phase become too ill-conditioned to be "exact".
    librating_ = modulus_ < 1 - 1e-12;

    unsigned capabilities = kHessian | kOmegaMax;
    if (librating_) {
      capabilities |= kExact | kPeriod;
      quarter_period_ = complete_elliptic_k(modulus_);
      // The formula lives on (−π, π]; whole turns in θ0 are carried as an offset.
      const double reduced_theta0 = std::remainder(theta0, 2 * kPi);
      turns_offset_ = theta0 - reduced_theta0;
      // am(u0) = φ0 with k sn(u0) = sin(θ0/2) and 2 k ω0 cn(u0) = v0; from rest at θ0 > 0
      // this gives φ0 = π/2 and u0 = K.
      const double phi0 = std::atan2(std::sin(reduced_theta0 / 2), v0 / (2 * omega0));
      phase0_ = incomplete_elliptic_f(phi0, modulus_, quarter_period_);
    }
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
  void gradient(const Vec& q, Vec& g) const override {
    g = Vec::Constant(1, omega0_ * omega0_ * std::sin(q[0]));
  }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    H.resize(1, 1);
    H.setZero();
    H.insert(0, 0) = omega0_ * omega0_ * std::cos(q[0]);
    H.makeCompressed();
  }

  State exact(double t) const override {
    if (!librating_) return Problem::exact(t);
    // sn, cn are 4K-periodic; reducing the argument exactly (std::remainder) keeps GSL's
    // Landen iteration accurate at large t.
    const double u = std::remainder(phase0_ + omega0_ * t, 4 * quarter_period_);
    double sn = 0, cn = 0, dn = 0;
    check_gsl(gsl_sf_elljac_e(u, modulus_ * modulus_, &sn, &cn, &dn), "gsl_sf_elljac_e");
    // cos(θ/2) = dn, so atan2 stays well conditioned near θ = ±π where arcsin is not.
    const double theta = turns_offset_ + 2 * std::atan2(modulus_ * sn, dn);
    return {t, Vec::Constant(1, theta), Vec::Constant(1, 2 * modulus_ * omega0_ * cn)};
  }
  double period() const override {
    if (!librating_) return Problem::period();
    return 4 * quarter_period_ / omega0_;
  }
  // The linearised frequency ω0 √(cos θ) is largest at the bottom (on the upper half the
  // linearisation is unstable, not oscillatory), so ω0 bounds it for every θ.
  double omega_max(const Vec&) const override { return omega0_; }

 private:
  double theta0_;
  double omega0_;
  double v0_;
  double modulus_ = 0;  // k of the elliptic functions (GSL's parameter is m = k²)
  bool librating_ = false;
  double quarter_period_ = 0;  // K(k)
  double phase0_ = 0;          // u0
  double turns_offset_ = 0;    // θ0 minus its representative in [−π, π]
};

}  // namespace

std::unique_ptr<Problem> make_pendulum(Params& params) {
  const double theta0 = params.real("theta0", 0.5, "initial angle from the bottom (rad)");
  const double omega0 = params.real(
      "omega0", 1.0, "small-amplitude angular frequency sqrt(g/L)", [](double x) { return x > 0; },
      "> 0");
  const double v0 =
      params.real("v0", 0.0, "initial angular velocity (released from rest by default)");
  return std::make_unique<Pendulum>(theta0, omega0, v0);
}

}  // namespace geomint
