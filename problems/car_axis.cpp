// The car axis of the IVP Test Set (Mazzia & Magherini, release 2.4, "Car axis problem"; Schiehlen
// 1990): an index-3 mechanical DAE with constant mass matrix, restated here on the constraint API
// (docs/METHOD.md §3). q = (x_l, y_l, x_r, y_r), the two wheels of an axis of length L, each of
// mass k = Mε²/2; the left wheel hangs on a spring of rest length L0 from the origin, the right
// one on a spring of rest length L0 from the point B(t) = (x_b, y_b), y_b = r sin(wt),
// x_b = √(L² − y_b²), driven over a bumpy road. Constraints (rheonomic through B):
//   g1 = x_b(t) x_l + y_b(t) y_l = 0,   g2 = (x_l − x_r)² + (y_l − y_r)² − L² = 0,
// so that k q̈ = −∇V + F(q, t) − Gᵀλ with V = ½(|q_l| − L0)² + k g (y_l + y_r) and F the right
// spring (it depends on t through B). λ is the Test Set's (λ1, λ2) with the opposite sign (its
// equations read k q̈ = … + Gᵀλ).
#include <cmath>

#include "problems/force.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

struct CarAxisParameters {
  double eps, big_mass, length, rest_length, amplitude, frequency, gravity;
};

class CarAxis final : public Problem, public HolonomicConstraints, public NonConservativeForce {
 public:
  explicit CarAxis(const CarAxisParameters& p) : p_(p), mass_(p.big_mass * p.eps * p.eps / 2) {
    set_mass(Vec::Constant(4, mass_));
    set_capabilities(kHessian);
    // The Test Set's interval is [0, 3]; the wheels oscillate at ~√(1/k) ≈ 45 rad per time unit.
    set_defaults(1e-3, 3.0);
  }

  // The Test Set's consistent initial values (λ = 0): both wheels at height L0, moving left at
  // r w L0 / L so that dg1/dt = x_b ẋ_l + ẏ_b y_l = 0 (the Test Set's −L0/L has r w = 1).
  State initial_state() const override {
    Vec q(4), v(4);
    const double speed = p_.amplitude * p_.frequency * p_.rest_length / p_.length;
    q << 0, p_.rest_length, p_.length, p_.rest_length;
    v << -speed, 0, -speed, 0;
    return {0.0, q, mass_ * v};
  }

  double potential(const Vec& q) const override {
    const double stretch = std::hypot(q[0], q[1]) - p_.rest_length;
    return 0.5 * stretch * stretch + mass_ * p_.gravity * (q[1] + q[3]);
  }
  void gradient(const Vec& q, Vec& g) const override {
    const double radius = std::hypot(q[0], q[1]);
    const double factor = (radius - p_.rest_length) / radius;
    g.resize(4);
    g << factor * q[0], factor * q[1] + mass_ * p_.gravity, 0, mass_ * p_.gravity;
  }
  // ∇²½(|d| − L0)² = (1 − L0/|d|) I + (L0/|d|³) d dᵀ for the left spring d = q_l.
  void hessian(const Vec& q, SparseMatrix& H) const override {
    const double radius = std::hypot(q[0], q[1]);
    const double diagonal = 1 - p_.rest_length / radius;
    const double outer = p_.rest_length / (radius * radius * radius);
    H.resize(4, 4);
    H.setZero();
    H.insert(0, 0) = diagonal + outer * q[0] * q[0];
    H.insert(0, 1) = outer * q[0] * q[1];
    H.insert(1, 0) = outer * q[0] * q[1];
    H.insert(1, 1) = diagonal + outer * q[1] * q[1];
    H.makeCompressed();
  }
  // The right spring, from the driven point B(t): a force without a Jacobian (it depends on q
  // and t, not on v).
  const NonConservativeForce* as_forced() const override { return this; }
  void force(const Vec& q, const Vec&, double t, Vec& f) const override {
    const Driver b = driver(t);
    const double dx = q[2] - b.x, dy = q[3] - b.y;
    const double radius = std::hypot(dx, dy);
    const double factor = (p_.rest_length - radius) / radius;
    f.resize(4);
    f << 0, 0, factor * dx, factor * dy;
  }

  const HolonomicConstraints* as_constrained() const override { return this; }
  bool time_dependent() const override { return true; }
  int constraint_count() const override { return 2; }
  void constraint(const Vec& q, Vec& g) const override { constraint_at(0.0, q, g); }
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override {
    constraint_jacobian_at(0.0, q, G);
  }
  void constraint_at(double t, const Vec& q, Vec& g) const override {
    const Driver b = driver(t);
    const double dx = q[0] - q[2], dy = q[1] - q[3];
    g.resize(2);
    g << b.x * q[0] + b.y * q[1], (dx * dx + dy * dy) - p_.length * p_.length;
  }
  void constraint_jacobian_at(double t, const Vec& q, SparseMatrix& G) const override {
    const Driver b = driver(t);
    const double dx = q[0] - q[2], dy = q[1] - q[3];
    G.resize(2, 4);
    G.setZero();
    G.insert(0, 0) = b.x;
    G.insert(0, 1) = b.y;
    G.insert(1, 0) = 2 * dx;
    G.insert(1, 1) = 2 * dy;
    G.insert(1, 2) = -2 * dx;
    G.insert(1, 3) = -2 * dy;
    G.makeCompressed();
  }
  // g1 is linear in q; g2 = |q_l − q_r|² − L² has the Hessian 2[[I, −I], [−I, I]].
  void constraint_curvature(const Vec&, const Vec& v, Vec& c) const override {
    const double du = v[0] - v[2], dv = v[1] - v[3];
    c.resize(2);
    c << 0, 2 * (du * du + dv * dv);
  }
  void constraint_hessian(const Vec&, const Vec& lambda, SparseMatrix& K) const override {
    K.resize(4, 4);
    K.setZero();
    for (int i = 0; i < 2; ++i) {
      K.insert(i, i) = 2 * lambda[1];
      K.insert(i + 2, i + 2) = 2 * lambda[1];
      K.insert(i, i + 2) = -2 * lambda[1];
      K.insert(i + 2, i) = -2 * lambda[1];
    }
    K.makeCompressed();
  }
  // Only g1 moves with B: g_t = ẋ_b x_l + ẏ_b y_l, a_t = 2(ẋ_b u_l + ẏ_b v_l) + ẍ_b x_l + ÿ_b y_l.
  void constraint_time_terms(double t, const Vec& q, const Vec& v, Vec& g_t,
                             Vec& a_t) const override {
    const Driver b = driver(t);
    g_t.resize(2);
    a_t.resize(2);
    g_t << b.x_rate * q[0] + b.y_rate * q[1], 0;
    a_t << 2 * (b.x_rate * v[0] + b.y_rate * v[1]) + b.x_accel * q[0] + b.y_accel * q[1], 0;
  }

 private:
  struct Driver {
    double x, y, x_rate, y_rate, x_accel, y_accel;
  };
  // B(t) on the circle x_b² + y_b² = L²: differentiating it twice gives ẋ_b and ẍ_b.
  Driver driver(double t) const {
    const double w = p_.frequency;
    const double y = p_.amplitude * std::sin(w * t);
    const double y_rate = p_.amplitude * w * std::cos(w * t);
    const double y_accel = -w * w * y;
    const double x = std::sqrt((p_.length - y) * (p_.length + y));
    const double x_rate = -y * y_rate / x;
    const double x_accel = -(x_rate * x_rate + y_rate * y_rate + y * y_accel) / x;
    return {x, y, x_rate, y_rate, x_accel, y_accel};
  }

  CarAxisParameters p_;
  double mass_;  // k = Mε²/2, every coordinate
};

}  // namespace

std::unique_ptr<Problem> make_car_axis(Params& params) {
  CarAxisParameters p{};
  p.eps = params.real("eps", 1e-2, "epsilon: the wheel mass is M eps^2 / 2", Range::above(0));
  p.big_mass = params.real("M", 10, "M (wheel mass M eps^2 / 2)", Range::above(0));
  p.length = params.real("L", 1, "axis length L", Range::above(0));
  p.rest_length = params.real("L0", 0.5, "rest length L0 of both springs", Range::above(0));
  p.amplitude = params.real("r", 0.1, "amplitude of the road excitation y_b = r sin(w t), below L",
                            Range::at_least(0));
  p.frequency = params.real("w", 10, "angular frequency w of the road excitation");
  p.gravity = params.real("g", 1, "gravitational acceleration");
  if (!(p.amplitude < p.length)) {
    throw InputError("problem 'car_axis': r must be below L (the driven point lies on |B| = L)");
  }
  return std::make_unique<CarAxis>(p);
}

}  // namespace geomint
