// Two-scale linear system: wall —k_soft— m₁ —k_stiff— m₂, V = ½k_soft q₁² + ½k_stiff (q₂ − q₁)²,
// stiffness ratio k_stiff/k_soft up to 1e8 and beyond (the stiff-problem test of GNI §XIII.1 in its
// simplest form). Exact solution by the two normal modes; ω_max is the stiff mode's frequency.
#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "problems/problem.hpp"

namespace geomint {
namespace {

class StiffSpring final : public Problem {
 public:
  StiffSpring(double soft, double ratio, double mass, double q0, double stretch, double v0)
      : soft_(soft), stiff_(soft * ratio), mass_(mass) {
    set_mass(Vec::Constant(2, mass));
    set_capabilities(kHessian | kExact | kOmegaMax);
    // Eigen-decomposition of K = [[a, b], [b, c]] by the Jacobi rotation angle θ: the columns
    // (cos θ, sin θ) and (−sin θ, cos θ) are orthonormal to rounding however large the ratio.
    // λ_fast has no cancellation; λ_slow = det K/λ_fast avoids the one in (a + c)/2 − root.
    const double a = soft_ + stiff_, b = -stiff_, c = stiff_;
    const double theta = 0.5 * std::atan2(2 * b, a - c);
    fast_.shape << std::cos(theta), std::sin(theta);
    slow_.shape << -std::sin(theta), std::cos(theta);
    const double lambda_fast = 0.5 * (a + c) + std::hypot(0.5 * (a - c), b);
    const double lambda_slow = soft_ * stiff_ / lambda_fast;
    fast_.omega = std::sqrt(lambda_fast / mass);
    slow_.omega = std::sqrt(lambda_slow / mass);
    initial_.q = Eigen::Vector2d(q0, q0 + stretch);
    initial_.p = Vec::Constant(2, mass * v0);
    for (Mode* mode : {&fast_, &slow_}) {
      mode->a = mode->shape.dot(initial_.q);
      mode->b = mode->shape.dot(Eigen::Vector2d(initial_.p / mass));
    }
    // hω_max = 0.1 (inside every explicit method's limit), ten periods of the slow mode.
    set_defaults(0.1 / fast_.omega, 10 * 2 * std::numbers::pi / slow_.omega);
  }

  State initial_state() const override { return initial_; }

  double potential(const Vec& q) const override {
    const double stretch = q[1] - q[0];
    return 0.5 * soft_ * q[0] * q[0] + 0.5 * stiff_ * stretch * stretch;
  }
  void gradient(const Vec& q, Vec& g) const override {
    const double tension = stiff_ * (q[1] - q[0]);
    g.resize(2);
    g << soft_ * q[0] - tension, tension;
  }
  bool is_linear() const override { return true; }
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(2, 2);
    H.setZero();
    H.insert(0, 0) = soft_ + stiff_;
    H.insert(0, 1) = -stiff_;
    H.insert(1, 0) = -stiff_;
    H.insert(1, 1) = stiff_;
    H.makeCompressed();
  }

  State exact(double t) const override {
    State state{t, Vec::Zero(2), Vec::Zero(2)};
    for (const Mode* mode : {&fast_, &slow_}) {
      const double c = std::cos(mode->omega * t);
      const double s = std::sin(mode->omega * t);
      state.q += (mode->a * c + mode->b / mode->omega * s) * mode->shape;
      state.p += (mass_ * (-mode->a * mode->omega * s + mode->b * c)) * mode->shape;
    }
    return state;
  }
  double omega_max(const Vec&) const override { return fast_.omega; }

 private:
  struct Mode {
    Eigen::Vector2d shape;
    double omega = 0;
    double a = 0, b = 0;  // modal displacement and velocity at t = 0
  };

  double soft_, stiff_, mass_;
  Mode fast_, slow_;
  State initial_;
};

}  // namespace

std::unique_ptr<Problem> make_stiff_spring(Params& params) {
  const double soft = params.real("k_soft", 1.0, "soft spring (wall to mass 1)", Range::above(0));
  const double ratio =
      params.real("ratio", 1e4, "stiffness ratio k_stiff/k_soft (stiff spring between the masses)",
                  Range::closed(1, 1e12));
  const double mass = params.real("mass", 1.0, "mass of each of the two bodies", Range::above(0));
  const double q0 = params.real("q0", 1.0, "initial displacement of both masses");
  const double stretch =
      params.real("stretch", 0.0, "initial elongation of the stiff spring (excites the fast mode)");
  const double v0 = params.real("v0", 0.0, "initial velocity of both masses");
  return std::make_unique<StiffSpring>(soft, ratio, mass, q0, stretch, v0);
}

}  // namespace geomint
