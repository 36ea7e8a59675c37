// Spherical pendulum: a point mass on a rigid rod of length L about a fixed pivot in 3D, gravity
// along −z, in Cartesian coordinates q = (x, y, z) with the length constraint |q| − L = 0
// (docs/METHOD.md §3; problems/rods.hpp). Rotations about the vertical keep V and g, so the
// vertical angular momentum is conserved; the conical motion is exact, with its period.
// `coordinates=angles`: q = (θ, φ), L = ½mL²(θ̇² + sin²θ φ̇²) + mgL cos θ (../shared/MECHANICS.md
// §5), the position-dependent mass mL² diag(1, sin²θ), singular at the poles θ = 0, π.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "problems/lagrangian.hpp"
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
    unsigned capabilities = kHessian | kAngularMomentum;
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

// The same pendulum in q = (θ, φ), p = (p_θ, p_φ) = mL²(θ̇, sin²θ φ̇): φ is cyclic, so p_φ (the
// vertical angular momentum x p_y − y p_x of the Cartesian variant) is kept.
class SphericalPendulumAngles final : public Problem, public LagrangianSystem {
 public:
  const LagrangianSystem* as_lagrangian() const override { return this; }
  explicit SphericalPendulumAngles(const SphericalParameters& parameters)
      : parameters_(parameters), inertia_(parameters.mass * parameters.length * parameters.length) {
    set_dof(2);  // no constant mass: the mass is mL² diag(1, sin²θ)
    unsigned capabilities = kAngularMomentum | kOmegaMax;
    if (parameters.conical) capabilities |= kExact | kPeriod;
    set_capabilities(capabilities);
    const double time_unit = std::sqrt(parameters.length / parameters.gravity);
    set_defaults(0.01 * time_unit, 600.0 * time_unit);
  }

  State initial_state() const override { return state_at(0.0); }

  void mass_matrix(const Vec& q, DenseMatrix& M) const override {
    const double s = std::sin(q[0]);
    M = DenseMatrix::Zero(2, 2);
    M(0, 0) = inertia_;
    M(1, 1) = inertia_ * s * s;
  }
  // T = ½I(θ̇² + sin²θ φ̇²): ∂T/∂θ = I sin θ cos θ φ̇² = ½I sin 2θ φ̇².
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override {
    T_q.resize(2);
    T_q << 0.5 * inertia_ * std::sin(2 * q[0]) * v[1] * v[1], 0;
  }
  // ∂(I sin²θ φ̇)/∂θ = I sin 2θ φ̇.
  void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const override {
    D = DenseMatrix::Zero(2, 2);
    D(1, 0) = inertia_ * std::sin(2 * q[0]) * v[1];
  }
  void kinetic_hessian(const Vec& q, const Vec& v, DenseMatrix& T_qq) const override {
    T_qq = DenseMatrix::Zero(2, 2);
    T_qq(0, 0) = inertia_ * std::cos(2 * q[0]) * v[1] * v[1];
  }
  double potential(const Vec& q) const override { return -weight() * std::cos(q[0]); }
  void gradient(const Vec& q, Vec& g) const override {
    g.resize(2);
    g << weight() * std::sin(q[0]), 0;
  }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    K = DenseMatrix::Zero(2, 2);
    K(0, 0) = weight() * std::cos(q[0]);
  }

  State exact(double t) const override {
    if (!parameters_.conical) return Problem::exact(t);  // throws: not declared
    return state_at(t);
  }
  double period() const override { return 2 * std::numbers::pi / std::abs(parameters_.phi_dot0); }
  Vec angular_momentum(const Vec&, const Vec& p) const override { return Vec::Constant(1, p[1]); }
  // The Cartesian variant's x = L sin θ cos φ, which crosses 0 upwards once per turn.
  double period_observable(const Vec& q, const Vec&) const override {
    return std::sin(q[0]) * std::cos(q[1]);
  }
  // The polar rate: the small-oscillation √(g/L) or, on a cone, the faster of the azimuthal rate
  // and the θ-oscillation about the cone √(g/(L cos θ₀)·(1 + 3cos²θ₀)); independent of q, as
  // Kepler's, because a fixed step has to resolve the whole motion.
  double omega_max(const Vec&) const override {
    const auto& P = parameters_;
    const double c = std::abs(std::cos(P.theta0));
    const double small = std::sqrt(P.gravity / P.length);
    const double about_cone =
        c > 0 ? std::sqrt(P.gravity / (P.length * c) * (1 + 3 * c * c)) : small;
    return std::max({small, about_cone, std::abs(P.phi_dot0), std::abs(P.theta_dot0)});
  }

 private:
  double weight() const { return parameters_.mass * parameters_.gravity * parameters_.length; }
  // Along the conical motion θ stays θ₀ and φ = φ₀ + φ̇₀t; at t = 0 the initial state.
  State state_at(double t) const {
    const auto& P = parameters_;
    const double s = std::sin(P.theta0);
    State state{t, Vec(2), Vec(2)};
    state.q << P.theta0, P.phi0 + P.phi_dot0 * t;
    state.p << inertia_ * P.theta_dot0, inertia_ * s * s * P.phi_dot0;
    return state;
  }

  SphericalParameters parameters_;
  double inertia_;  // mL²
};

}  // namespace

std::unique_ptr<Problem> make_spherical_pendulum(Params& params) {
  SphericalParameters P{};
  P.length = params.real("length", 1.0, "rod length L", Range::above(0));
  P.gravity =
      params.real("gravity", 1.0, "gravitational acceleration g (along -z)", Range::above(0));
  P.mass = params.real("mass", 1.0, "bob mass", Range::above(0));
  P.theta0 = params.real("theta0", 1.0, "initial angle from the downward vertical (rad)",
                         Range::magnitude(1000));
  P.phi0 = params.real("phi0", 0.0, "initial azimuth (rad)", Range::magnitude(1000));
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
  const std::string coordinates =
      params.choice("coordinates", "cartesian", {"cartesian", "angles"},
                    "q = (x, y, z) with the length constraint, or q = (theta, phi) with the mass "
                    "m L^2 diag(1, sin^2 theta) (non_separable; singular at the poles)");
  // Every Cartesian spec (and committed result) stays as it was.
  params.omit_default_from_canonical("coordinates");
  if (coordinates == "cartesian") return std::make_unique<SphericalPendulum>(P);
  // sin θ₀ = 0 makes M singular and p_φ = 0 whatever φ̇₀; 1e-8 keeps M's condition number
  // (1/sin²θ) below 1e16, where the velocity solve would lose every digit.
  if (std::abs(std::sin(P.theta0)) < 1e-8) {
    throw InputError(fmt::format(
        "problem 'spherical_pendulum': theta0 = {} is on a pole (theta0 = 0 or pi, |sin theta0| < "
        "1e-8), where the angle coordinates are singular (the mass m L^2 diag(1, sin^2 theta) has "
        "no inverse); start off the pole or use coordinates=cartesian",
        P.theta0));
  }
  return std::make_unique<SphericalPendulumAngles>(P);
}

}  // namespace geomint
