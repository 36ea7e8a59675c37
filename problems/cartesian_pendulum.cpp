// The planar pendulum as a constrained system (docs/METHOD.md §3): a point mass m at q = (x, y),
// pivot at the origin, gravity −g ŷ, rod |q| = L held by g(q) = (|q|² − L²)/(2L) = 0. Exact
// motion from the angle pendulum with ω0 = √(g/L) (problems/pendulum.hpp).
#include <cmath>

#include "problems/pendulum.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

class CartesianPendulum final : public Problem, public HolonomicConstraints {
 public:
  CartesianPendulum(double theta0, double v0, double length, double mass, double gravity)
      : theta0_(theta0),
        v0_(v0),
        length_(length),
        mass_(mass),
        gravity_(gravity),
        omega0_(std::sqrt(gravity / length)),
        motion_(theta0, omega0_, v0) {
    unsigned capabilities = kHessian | kOmegaMax;
    if (motion_.has_exact()) capabilities |= kExact | kPeriod;
    set_mass(Vec::Constant(2, mass));
    set_capabilities(capabilities);
    set_defaults(0.05 / omega0_, 50.0 / omega0_);
  }

  State initial_state() const override { return state_at(0.0, theta0_, v0_); }

  // Height above the lowest point, so V = 0 at rest at the bottom.
  double potential(const Vec& q) const override { return mass_ * gravity_ * (q[1] + length_); }
  void gradient(const Vec&, Vec& g) const override {
    g.resize(2);
    g << 0.0, mass_ * gravity_;
  }
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(2, 2);
    H.setZero();
    H.makeCompressed();
  }

  // Scaled by 1/L so that G = qᵀ/L is the unit rod direction on the manifold and the multiplier
  // λ in M q̈ = −∇V − Gᵀλ is the rod tension itself (force units), not tension/L.
  const HolonomicConstraints* as_constrained() const override { return this; }
  int constraint_count() const override { return 1; }
  void constraint(const Vec& q, Vec& g) const override {
    // (|q| − L)(|q| + L) instead of |q|² − L² keeps relative accuracy on the manifold.
    const double radius = q.norm();
    g = Vec::Constant(1, (radius - length_) * (radius + length_) / (2 * length_));
  }
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override {
    G.resize(1, 2);
    G.setZero();
    G.insert(0, 0) = q[0] / length_;
    G.insert(0, 1) = q[1] / length_;
    G.makeCompressed();
  }
  // ∇²g = I/L: c = |v|²/L, K = λ I/L.
  void constraint_curvature(const Vec&, const Vec& v, Vec& c) const override {
    c = Vec::Constant(1, v.squaredNorm() / length_);
  }
  void constraint_hessian(const Vec&, const Vec& lambda, SparseMatrix& K) const override {
    K.resize(2, 2);
    K.setZero();
    K.insert(0, 0) = lambda[0] / length_;
    K.insert(1, 1) = lambda[0] / length_;
    K.makeCompressed();
  }
  std::vector<std::string> multiplier_names() const override { return {"tension"}; }

  State exact(double t) const override {
    if (!has(kExact)) return Problem::exact(t);
    const PendulumMotion::Angle angle = motion_.at(t);
    return state_at(t, angle.theta, angle.theta_dot);
  }
  // The rod tension from the angle motion: the radial part of M q̈ = −∇V − Gᵀλ with G = q̂ᵀ
  // gives −mLθ̇² = mg cos θ − λ, so λ = m(Lθ̇² + g cos θ) — a closed form independent of
  // multipliers()' index reduction.
  std::optional<Vec> exact_multipliers(double t) const override {
    if (!has(kExact)) return std::nullopt;
    const PendulumMotion::Angle angle = motion_.at(t);
    return Vec::Constant(1, mass_ * (length_ * angle.theta_dot * angle.theta_dot +
                                     gravity_ * std::cos(angle.theta)));
  }
  double period() const override {
    if (!has(kPeriod)) return Problem::period();
    return motion_.period();
  }
  // The angle's linearised frequency is at most ω0 (problems/pendulum.cpp); the Cartesian
  // coordinates add no other motion.
  double omega_max(const Vec&) const override { return omega0_; }

 private:
  // θ from the downward vertical: q = L(sin θ, −cos θ), p = m L θ̇ (cos θ, sin θ).
  State state_at(double t, double theta, double theta_dot) const {
    const double s = std::sin(theta);
    const double c = std::cos(theta);
    Vec q(2), p(2);
    q << length_ * s, -length_ * c;
    p << mass_ * length_ * theta_dot * c, mass_ * length_ * theta_dot * s;
    return {t, q, p};
  }

  double theta0_;
  double v0_;
  double length_;
  double mass_;
  double gravity_;
  double omega0_;
  PendulumMotion motion_;
};

}  // namespace

std::unique_ptr<Problem> make_cartesian_pendulum(Params& params) {
  const double theta0 = params.real("theta0", 0.5, "initial angle from the downward vertical (rad)",
                                    Range::magnitude(1000));
  const double v0 = params.real(
      "v0", 0.0, "initial angular velocity (rad per time unit; released from rest by default)",
      Range::magnitude(1e6));
  const double length = params.real("length", 1.0, "rod length L", Range::above(0));
  const double mass = params.real("mass", 1.0, "point mass m", Range::above(0));
  const double gravity =
      params.real("gravity", 1.0, "gravitational acceleration g", Range::above(0));
  return std::make_unique<CartesianPendulum>(theta0, v0, length, mass, gravity);
}

}  // namespace geomint
