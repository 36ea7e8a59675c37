// The elastic (spring) pendulum in polar coordinates q = (r, φ), φ from the downward vertical:
// L = ½m(ṙ² + r²φ̇²) − ½k(r − l₀)² + mgr cos φ (../shared/MECHANICS.md §5), mass m diag(1, r²),
// singular at r = 0; ω_spring = 2ω_pendulum is the resonance that trades energy between the modes.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

struct SpringPendulumParameters {
  double mass, stiffness, rest_length, gravity;
  double r0, phi0, rdot0, phidot0;
};

class SpringPendulum final : public Problem, public LagrangianSystem {
 public:
  const LagrangianSystem* as_lagrangian() const override { return this; }
  explicit SpringPendulum(const SpringPendulumParameters& parameters) : P_(parameters) {
    set_dof(2);  // no constant mass: the mass is m diag(1, r²)
    set_capabilities(kOmegaMax);
    // About 125 steps per period of the faster mode, ten periods of the slower.
    const double fastest = omega_max(Vec());
    const double slowest = std::min(spring_rate(), pendulum_rate());
    set_defaults(0.05 / fastest, 10 * 2 * std::numbers::pi / slowest);
  }

  std::vector<PositiveCoordinate> positive_coordinates() const override {
    return {{0, "r (the spring length)"}};
  }
  State initial_state() const override {
    State state{0.0, Vec(2), Vec(2)};
    state.q << P_.r0, P_.phi0;
    state.p << P_.mass * P_.rdot0, P_.mass * P_.r0 * P_.r0 * P_.phidot0;
    return state;
  }

  // The two small-oscillation rates about the hanging equilibrium r = l₀ + mg/k: the spring's
  // √(k/m) and the pendulum's √(g/r_eq); independent of q because a fixed step has to resolve
  // the whole motion.
  double omega_max(const Vec&) const override { return std::max(spring_rate(), pendulum_rate()); }

  void mass_matrix(const Vec& q, DenseMatrix& M) const override {
    M = DenseMatrix::Zero(2, 2);
    M(0, 0) = P_.mass;
    M(1, 1) = P_.mass * q[0] * q[0];
  }
  // ∂(½mr²φ̇²)/∂r = m r φ̇² (the centrifugal term).
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override {
    T_q.resize(2);
    T_q << P_.mass * q[0] * v[1] * v[1], 0;
  }
  void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const override {
    D = DenseMatrix::Zero(2, 2);
    D(1, 0) = 2 * P_.mass * q[0] * v[1];  // ∂(mr²φ̇)/∂r
  }
  void kinetic_hessian(const Vec&, const Vec& v, DenseMatrix& T_qq) const override {
    T_qq = DenseMatrix::Zero(2, 2);
    T_qq(0, 0) = P_.mass * v[1] * v[1];
  }
  double potential(const Vec& q) const override {
    const double stretch = q[0] - P_.rest_length;
    return 0.5 * P_.stiffness * stretch * stretch - weight() * q[0] * std::cos(q[1]);
  }
  void gradient(const Vec& q, Vec& g) const override {
    g.resize(2);
    g << P_.stiffness * (q[0] - P_.rest_length) - weight() * std::cos(q[1]),
        weight() * q[0] * std::sin(q[1]);
  }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    K.resize(2, 2);
    const double s = weight() * std::sin(q[1]);
    K << P_.stiffness, s, s, weight() * q[0] * std::cos(q[1]);
  }

 private:
  double weight() const { return P_.mass * P_.gravity; }
  double spring_rate() const { return std::sqrt(P_.stiffness / P_.mass); }
  double pendulum_rate() const {
    return std::sqrt(P_.gravity / (P_.rest_length + weight() / P_.stiffness));
  }

  SpringPendulumParameters P_;
};

}  // namespace

std::unique_ptr<Problem> make_spring_pendulum(Params& params) {
  SpringPendulumParameters P{};
  P.mass = params.real("m", 1.0, "bob mass", Range::above(0));
  P.stiffness = params.real("k", 40.0, "spring stiffness", Range::above(0));
  P.rest_length = params.real("l0", 1.0, "spring rest length", Range::above(0));
  P.gravity = params.real("g", 9.81, "gravitational acceleration", Range::above(0));
  P.r0 =
      params.real("r0", 1.4, "initial spring length (the mass m diag(1, r^2) is singular at r = 0)",
                  Range::above(0));
  P.phi0 = params.real("phi0", 0.5, "initial angle from the downward vertical (rad)",
                       Range::magnitude(1000));
  P.rdot0 = params.real("rdot0", 0.0, "initial rate of r", Range::magnitude(1e6));
  P.phidot0 =
      params.real("phidot0", 0.0, "initial rate of phi (rad per time)", Range::magnitude(1e6));
  return std::make_unique<SpringPendulum>(P);
}

}  // namespace geomint
