// Kepler problem V = −1/|q| in the plane, started at perihelion as in Hairer, Lubich & Wanner,
// GNI (I.2.12): a = 1, period 2π, H = −½. Exact solution from Kepler's equation E − e sin E = t.
// `coordinates=polar`: the same orbit in q = (r, φ), L = ½(ṙ² + r²φ̇²) + 1/r, a position-dependent
// mass diag(1, r²) (../shared/MECHANICS.md §5), exact solution mapped from the Cartesian one.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"
#include "problems/structures/kepler_orbit.hpp"

namespace geomint {
namespace {

constexpr double kPi = std::numbers::pi;

// E − sin E without the cancellation of the direct difference for small E (Taylor series),
// which near perihelion of a very eccentric orbit is all of the residual of Kepler's equation.
double e_minus_sin(double E) {
  if (std::abs(E) >= 1) return E - std::sin(E);
  double term = E * E * E / 6;
  double sum = 0;
  for (int n = 0; std::abs(term) > DBL_EPSILON * std::abs(sum) || n == 0; ++n) {
    sum += term;
    term *= -E * E / ((2 * n + 4) * (2 * n + 5));
  }
  return sum;
}

// 1 − e cos E written as (1 − e) + 2e sin²(E/2), exact to rounding even when e → 1 and E → 0.
double one_minus_e_cos(double E, double e) {
  const double s = std::sin(E / 2);
  return (1 - e) + 2 * e * s * s;
}

// Eccentric anomaly E for mean anomaly M in [−π, π]: safeguarded Newton. On [0, π] the root lies
// in [M, M + e] (because E − M = e sin E ∈ [0, e]) and the residual is increasing and convex,
// so bisection inside that bracket catches every step Newton would throw out of it.
double eccentric_anomaly(double mean_anomaly, double e) {
  const double M = std::abs(mean_anomaly);
  double lo = M;
  double hi = std::min(M + e, kPi);
  // Danby's starting value M + 0.85 e (sin M ≥ 0 here).
  double E = std::min(M + 0.85 * e, hi);
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double residual = (1 - e) * E + e * e_minus_sin(E) - M;
    if (residual > 0) {
      hi = E;
    } else {
      lo = E;
    }
    double next = E - residual / one_minus_e_cos(E, e);
    if (!(next >= lo && next <= hi)) next = 0.5 * (lo + hi);
    const double change = std::abs(next - E);
    E = next;
    // Also stop when the bracket has shrunk to a few ulps of E: for E in [2, π] an ulp is 2ε, and
    // Newton can alternate between two floats 4ε apart, which the absolute test never accepts
    // (e = 0.3, M = 2.7888146928201127).
    if (change < 4 * DBL_EPSILON || hi - lo <= 4 * DBL_EPSILON * E) {
      return std::copysign(E, mean_anomaly);
    }
  }
  throw std::logic_error("kepler: Newton iteration for Kepler's equation did not converge");
}

class Kepler final : public Problem, public KeplerOrbitStructure {
 public:
  explicit Kepler(double e) : e_(e), minor_axis_(std::sqrt((1 - e) * (1 + e))) {
    set_mass(Vec::Ones(2));
    set_capabilities(kHessian | kExact | kPeriod | kAngularMomentum | kOmegaMax);
    set_defaults(0.01, 10 * 2 * kPi);
  }

  State initial_state() const override {
    State state{0.0, Vec(2), Vec(2)};
    state.q << 1 - e_, 0;
    state.p << 0, std::sqrt((1 + e_) / (1 - e_));
    return state;
  }

  double potential(const Vec& q) const override { return -1 / q.norm(); }
  void gradient(const Vec& q, Vec& g) const override { KeplerGradient()(q, g); }
  FixedGradient fixed_gradient() const override { return KeplerGradient(); }
  // ∇²V = I/r³ − 3 q qᵀ/r⁵.
  void hessian(const Vec& q, SparseMatrix& H) const override {
    const double r = q.norm();
    const double inv_r3 = 1 / (r * r * r);
    const double inv_r5 = inv_r3 / (r * r);
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        entries.emplace_back(i, j, (i == j ? inv_r3 : 0.0) - 3 * q[i] * q[j] * inv_r5);
      }
    }
    H.resize(2, 2);
    H.setFromTriplets(entries.begin(), entries.end());
  }

  // Mean motion 1 and perihelion at t = 0, so the mean anomaly is t itself; the exact reduction
  // to [−π, π] makes exact(t + 2π) agree with exact(t) to rounding for any t.
  State exact(double t) const override {
    const double E = eccentric_anomaly(std::remainder(t, 2 * kPi), e_);
    const double half_sine = std::sin(E / 2);
    const double sine = std::sin(E);
    const double cosine = std::cos(E);
    const double anomaly_rate = 1 / one_minus_e_cos(E, e_);  // dE/dt
    State state{t, Vec(2), Vec(2)};
    state.q << (1 - e_) - 2 * half_sine * half_sine, minor_axis_ * sine;  // (cos E − e, b sin E)
    state.p << -sine * anomaly_rate, minor_axis_ * cosine * anomaly_rate;
    return state;
  }
  double period() const override { return 2 * kPi; }
  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    return Vec::Constant(1, q[0] * p[1] - q[1] * p[0]);
  }
  const void* structure(const StructureKey& key) const override {
    if (auto* s = offer<KeplerOrbitStructure>(key, this)) return s;
    return Problem::structure(key);
  }
  // Unit masses and μ = 1: x and v are q and p.
  Eigen::Vector3d eccentricity_vector(const Vec& q, const Vec& p) const override {
    return geomint::eccentricity_vector({q[0], q[1], 0}, {p[0], p[1], 0}, 1.0);
  }
  // The fastest rate on the orbit, the angular velocity at perihelion L/r² = √((1+e)/(1−e)³),
  // which also bounds the linearised tangential frequency r^(−3/2) there; independent of q
  // because a fixed step has to resolve the whole orbit.
  double omega_max(const Vec&) const override { return std::sqrt((1 + e_) / std::pow(1 - e_, 3)); }

 private:
  double e_;
  double minor_axis_;  // b = √(1 − e²) for a = 1
};

// Polar coordinates q = (r, φ), p = (p_r, p_φ) = (ṙ, r²φ̇); unit mass and μ = 1 as Kepler.
class KeplerPolar final : public Problem, public LagrangianSystem, public KeplerOrbitStructure {
 public:
  const LagrangianSystem* as_lagrangian() const override { return this; }
  explicit KeplerPolar(double e) : cartesian_(e), e_(e) {
    set_dof(2);  // no constant mass: the mass is diag(1, r²)
    // p_φ is the angular momentum (φ is cyclic): the momentum observer reads it through
    // angular_momentum().
    set_capabilities(kExact | kPeriod | kAngularMomentum | kOmegaMax);
    set_defaults(0.01, 10 * 2 * kPi);
  }

  std::vector<PositiveCoordinate> positive_coordinates() const override {
    return {{0, "r (the radius)"}};
  }
  State initial_state() const override { return to_polar(cartesian_.initial_state()); }

  void mass_matrix(const Vec& q, DenseMatrix& M) const override {
    M = DenseMatrix::Zero(2, 2);
    M(0, 0) = 1;
    M(1, 1) = q[0] * q[0];
  }
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override {
    T_q.resize(2);
    T_q << q[0] * v[1] * v[1], 0;  // ∂(½r²φ̇²)/∂r
  }
  void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const override {
    D = DenseMatrix::Zero(2, 2);
    D(1, 0) = 2 * q[0] * v[1];  // ∂(r²φ̇)/∂r
  }
  void kinetic_hessian(const Vec&, const Vec& v, DenseMatrix& T_qq) const override {
    T_qq = DenseMatrix::Zero(2, 2);
    T_qq(0, 0) = v[1] * v[1];
  }
  double potential(const Vec& q) const override { return -1 / q[0]; }
  void gradient(const Vec& q, Vec& g) const override {
    g.resize(2);
    g << 1 / (q[0] * q[0]), 0;
  }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    K = DenseMatrix::Zero(2, 2);
    K(0, 0) = -2 / (q[0] * q[0] * q[0]);
  }

  // φ continuous in t: the true anomaly of the reduced time plus the whole turns before it.
  State exact(double t) const override {
    State state = to_polar(cartesian_.exact(t));
    state.q[1] += 2 * kPi * std::round((t - std::remainder(t, 2 * kPi)) / (2 * kPi));
    return state;
  }
  double period() const override { return 2 * kPi; }
  Vec angular_momentum(const Vec&, const Vec& p) const override { return Vec::Constant(1, p[1]); }
  const void* structure(const StructureKey& key) const override {
    if (auto* s = offer<KeplerOrbitStructure>(key, this)) return s;
    return Problem::structure(key);
  }
  // x = r r̂ and v = ṙ r̂ + rφ̇ φ̂ with ṙ = p_r, rφ̇ = p_φ/r.
  Eigen::Vector3d eccentricity_vector(const Vec& q, const Vec& p) const override {
    const Eigen::Vector3d radial(std::cos(q[1]), std::sin(q[1]), 0);
    const Eigen::Vector3d angular(-radial[1], radial[0], 0);
    return geomint::eccentricity_vector(q[0] * radial, p[0] * radial + (p[1] / q[0]) * angular,
                                        1.0);
  }
  // The observable that crosses 0 upwards once per orbit, as Kepler's x: r cos φ.
  double period_observable(const Vec& q, const Vec&) const override {
    return q[0] * std::cos(q[1]);
  }
  double omega_max(const Vec&) const override { return std::sqrt((1 + e_) / std::pow(1 - e_, 3)); }

 private:
  // (x, y, p_x, p_y) → (r, φ ∈ (−π, π], p_r = (x p_x + y p_y)/r, p_φ = x p_y − y p_x).
  static State to_polar(const State& cartesian) {
    const Vec& x = cartesian.q;
    const Vec& p = cartesian.p;
    const double r = x.norm();
    State state{cartesian.t, Vec(2), Vec(2)};
    state.q << r, std::atan2(x[1], x[0]);
    state.p << x.dot(p) / r, x[0] * p[1] - x[1] * p[0];
    return state;
  }

  Kepler cartesian_;
  double e_;
};

}  // namespace

std::unique_ptr<Problem> make_kepler(Params& params) {
  const double e = params.real("e", 0.6, "eccentricity (semi-major axis 1, period 2pi)",
                               Range::closed_open(0, 1));
  const std::string coordinates =
      params.choice("coordinates", "cartesian", {"cartesian", "polar"},
                    "q = (x, y), or q = (r, phi) with the mass diag(1, r^2) (non_separable)");
  // Every Cartesian Kepler spec (and committed result) stays as it was.
  params.omit_default_from_canonical("coordinates");
  if (coordinates == "polar") return std::make_unique<KeplerPolar>(e);
  return std::make_unique<Kepler>(e);
}

}  // namespace geomint
