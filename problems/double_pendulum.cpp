// The planar double pendulum in absolute angles from the downward vertical (as rod_chain):
// T = ½(m₁+m₂)l₁²θ̇₁² + ½m₂l₂²θ̇₂² + m₂l₁l₂θ̇₁θ̇₂cos(θ₁−θ₂), V = −(m₁+m₂)gl₁cos θ₁ − m₂gl₂cos θ₂
// (../shared/MECHANICS.md §5): a position-dependent mass M(θ), canonical p = M(θ)θ̇.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

class DoublePendulum final : public Problem, public LagrangianSystem {
 public:
  const LagrangianSystem* as_lagrangian() const override { return this; }
  DoublePendulum(double m1, double m2, double l1, double l2, double g, Vec theta, Vec omega)
      : m1_(m1),
        m2_(m2),
        l1_(l1),
        l2_(l2),
        g_(g),
        theta_(std::move(theta)),
        omega_(std::move(omega)) {
    set_dof(2);  // no constant mass: the mass is M(θ)
    set_capabilities(kOmegaMax);
    // The faster small-amplitude mode of the equal pendulum is √(g/l)·√(2 + √2) ≈ 1.85 √(g/l).
    set_defaults(0.01 * std::sqrt(std::min(l1, l2) / g), 10.0);
  }

  State initial_state() const override {
    return {0.0, theta_, static_cast<const LagrangianSystem&>(*this).momentum(theta_, omega_)};
  }

  // The faster small-oscillation mode about the hanging equilibrium, K v = ω²M(0)v with
  // K = diag((m₁+m₂)gl₁, m₂gl₂) (for m₁ = m₂, l₁ = l₂: ω² = (g/l)(2 + √2)); independent of q, as
  // Kepler's, because a fixed step has to resolve the whole motion.
  double omega_max(const Vec&) const override {
    DenseMatrix M, K;
    mass_matrix(Vec::Zero(2), M);
    potential_hessian(Vec::Zero(2), K);
    const Eigen::GeneralizedSelfAdjointEigenSolver<DenseMatrix> modes(K, M, Eigen::EigenvaluesOnly);
    return std::sqrt(modes.eigenvalues().maxCoeff());
  }

  void mass_matrix(const Vec& q, DenseMatrix& M) const override {
    const double coupling = m2_ * l1_ * l2_ * std::cos(q[0] - q[1]);
    M.resize(2, 2);
    M << (m1_ + m2_) * l1_ * l1_, coupling, coupling, m2_ * l2_ * l2_;
  }
  // T depends on θ only through cos(θ₁ − θ₂): ∂T/∂θ₁ = −k v₁v₂ sin(θ₁−θ₂) = −∂T/∂θ₂, k = m₂l₁l₂.
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override {
    const double d = m2_ * l1_ * l2_ * v[0] * v[1] * std::sin(q[0] - q[1]);
    T_q.resize(2);
    T_q << -d, d;
  }
  // M v = ((m₁+m₂)l₁²v₁ + k c v₂, k c v₁ + m₂l₂²v₂), c = cos(θ₁−θ₂), ∂c/∂θ₁ = −s = −∂c/∂θ₂.
  void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const override {
    const double ks = m2_ * l1_ * l2_ * std::sin(q[0] - q[1]);
    D.resize(2, 2);
    D << -ks * v[1], ks * v[1], -ks * v[0], ks * v[0];
  }
  void kinetic_hessian(const Vec& q, const Vec& v, DenseMatrix& T_qq) const override {
    const double d = m2_ * l1_ * l2_ * v[0] * v[1] * std::cos(q[0] - q[1]);
    T_qq.resize(2, 2);
    T_qq << -d, d, d, -d;
  }
  double potential(const Vec& q) const override {
    return -(m1_ + m2_) * g_ * l1_ * std::cos(q[0]) - m2_ * g_ * l2_ * std::cos(q[1]);
  }
  void gradient(const Vec& q, Vec& g) const override {
    g.resize(2);
    g << (m1_ + m2_) * g_ * l1_ * std::sin(q[0]), m2_ * g_ * l2_ * std::sin(q[1]);
  }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    K = DenseMatrix::Zero(2, 2);
    K(0, 0) = (m1_ + m2_) * g_ * l1_ * std::cos(q[0]);
    K(1, 1) = m2_ * g_ * l2_ * std::cos(q[1]);
  }

 private:
  double m1_, m2_, l1_, l2_, g_;
  Vec theta_, omega_;
};

}  // namespace

std::unique_ptr<Problem> make_double_pendulum(Params& params) {
  const double m1 = params.real("m1", 1.0, "upper bob mass", Range::above(0));
  const double m2 = params.real("m2", 1.0, "lower bob mass", Range::above(0));
  const double l1 = params.real("l1", 1.0, "upper rod length", Range::above(0));
  const double l2 = params.real("l2", 1.0, "lower rod length", Range::above(0));
  const double g = params.real("g", 9.81, "gravitational acceleration", Range::above(0));
  Vec theta(2), omega(2);
  theta[0] = params.real("theta1", 0.3, "upper rod angle from the downward vertical (rad)",
                         Range::magnitude(1000));
  theta[1] = params.real("theta2", -0.2, "lower rod angle from the downward vertical (rad)",
                         Range::magnitude(1000));
  omega[0] =
      params.real("omega1", 0.0, "initial rate of theta1 (rad per time)", Range::magnitude(1e6));
  omega[1] =
      params.real("omega2", 0.0, "initial rate of theta2 (rad per time)", Range::magnitude(1e6));
  return std::make_unique<DoublePendulum>(m1, m2, l1, l2, g, theta, omega);
}

}  // namespace geomint
