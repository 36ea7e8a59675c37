// Spherical pendulum: a point mass on a rigid rod of length L about a fixed pivot in 3D, gravity
// along −z, in Cartesian coordinates q = (x, y, z) with the length constraint |q| − L = 0
// (docs/METHOD.md §3; problems/rods.hpp). Rotations about the vertical keep V and g, so the
// vertical angular momentum is conserved; the conical motion is exact, with its period.
#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "problems/problem.hpp"
#include "problems/rods.hpp"

namespace geomint {
namespace {

struct SphericalParameters {
  double length, gravity, mass;
  double theta0, phi0, theta_dot0, phi_dot0;
  bool conical;  // θ̇₀ = 0 and φ̇₀ the conical rate: uniform circular motion, exact
};

class SphericalPendulum final : public rods::RodProblem {
 public:
  explicit SphericalPendulum(const SphericalParameters& parameters)
      : RodProblem({{rods::kPivot, 0, parameters.length}}, 3), parameters_(parameters) {
    set_mass(Vec::Constant(3, parameters.mass));
    unsigned capabilities = kHessian | kAngularMomentum | kConstraints;
    if (parameters.conical) capabilities |= kExact | kPeriod;
    set_capabilities(capabilities);
    // About 600 steps per small-oscillation period 2π√(L/g), a hundred periods.
    const double time_unit = std::sqrt(parameters.length / parameters.gravity);
    set_defaults(0.01 * time_unit, 600.0 * time_unit);
  }

  State initial_state() const override { return state_at(0.0); }

  double potential(const Vec& q) const override {
    return parameters_.mass * parameters_.gravity * q[2];
  }
  void gradient(const Vec&, Vec& g) const override {
    g = Vec::Zero(3);
    g[2] = parameters_.mass * parameters_.gravity;
  }
  // V is linear: ∇²V = 0 (declared so that Newton-based constrained steps can run).
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(3, 3);
    H.setZero();
    H.makeCompressed();
  }
  State exact(double t) const override {
    if (!parameters_.conical) return Problem::exact(t);  // throws: not declared
    return state_at(t);
  }
  double period() const override { return 2 * std::numbers::pi / std::abs(parameters_.phi_dot0); }
  // Only the vertical component: gravity breaks the symmetry about horizontal axes, so the
  // x and y components are not conserved and a metric on them would report physics as error.
  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    return Vec::Constant(1, q[0] * p[1] - q[1] * p[0]);
  }

  std::vector<std::string> multiplier_names() const override { return {"tension"}; }

 private:
  // (θ, φ) → Cartesian: θ from the downward vertical, φ the azimuth. Along the conical motion θ
  // stays θ₀ and φ = φ₀ + φ̇₀t; at t = 0 this is the initial state for every parameter set.
  State state_at(double t) const {
    const auto& P = parameters_;
    const double theta = P.theta0 + (P.conical ? 0.0 : P.theta_dot0 * t);
    const double phi = P.phi0 + P.phi_dot0 * t;
    const double st = std::sin(theta), ct = std::cos(theta);
    const double sp = std::sin(phi), cp = std::cos(phi);
    State state{t, Vec(3), Vec(3)};
    state.q << P.length * st * cp, P.length * st * sp, -P.length * ct;
    const double dtheta = P.theta_dot0, dphi = P.phi_dot0;
    state.p << P.length * (ct * cp * dtheta - st * sp * dphi),
        P.length * (ct * sp * dtheta + st * cp * dphi), P.length * st * dtheta;
    state.p *= P.mass;
    return state;
  }

  SphericalParameters parameters_;
};

}  // namespace

std::unique_ptr<Problem> make_spherical_pendulum(Params& params) {
  const auto positive = [](double x) { return x > 0; };
  SphericalParameters P{};
  P.length = params.real("length", 1.0, "rod length L", positive, "> 0");
  P.gravity =
      params.real("gravity", 1.0, "gravitational acceleration g (along -z)", positive, "> 0");
  P.mass = params.real("mass", 1.0, "bob mass", positive, "> 0");
  P.theta0 = params.real(
      "theta0", 1.0, "initial angle from the downward vertical (rad)",
      [](double x) { return std::abs(x) <= 1000; }, "|theta0| <= 1000");
  P.phi0 = params.real(
      "phi0", 0.0, "initial azimuth (rad)", [](double x) { return std::abs(x) <= 1000; },
      "|phi0| <= 1000");
  P.theta_dot0 = params.real("theta_dot0", 0.0, "initial polar angular velocity");
  const double cos_theta0 = std::cos(P.theta0);
  const bool can_be_conical = cos_theta0 > 0 && std::sin(P.theta0) != 0;
  // φ̇² = g/(L cos θ) balances gravity and the centripetal force on a horizontal circle.
  const double conical_rate = can_be_conical ? std::sqrt(P.gravity / (P.length * cos_theta0)) : 0;
  P.phi_dot0 = params.real(
      "phi_dot0", conical_rate,
      "initial azimuthal angular velocity (default: the conical rate sqrt(g/(L cos theta0)) "
      "when 0 < |theta0| < pi/2, with the exact solution and period; else 0)");
  P.conical = can_be_conical && P.theta_dot0 == 0 && P.phi_dot0 == conical_rate;
  return std::make_unique<SphericalPendulum>(P);
}

}  // namespace geomint
