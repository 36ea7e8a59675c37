// Andrews' squeezing mechanism of the IVP Test Set (Mazzia & Magherini, "andrews"; Hairer & Wanner,
// Solving ODEs II §VII.7; Schiehlen 1990): seven planar bodies in the seven joint angles
// q = (β, Θ, γ, Φ, δ, Ω, ε), six holonomic loop-closure constraints, index 3, t ∈ [0, 0.03].
// Restated on the general Lagrangian kind with constraints (problems/lagrangian.hpp,
// problems/constraints.hpp): T = ½vᵀM(q)v, V = ½c₀(|D − C| − l₀)² (the spring from the point D on
// body 3 to the fixed point C), the driving torque `mom` on β as a constant force, no gravity (the
// Test Set has none), so that d/dt(M v) = T_q − ∇V + F − Gᵀλ. Expanded, that is the Test Set's
// M q̈ = f(q, v) − Gᵀλ: its f is T_q − Ṁv − ∇V + F (the velocity terms are the Coriolis terms of
// this T), and its λ has our sign.
#include <array>
#include <cmath>

#include "problems/force.hpp"
#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

// The Test Set's data (andrews.f, SI units: kg, m, kg m², N/m, N m).
struct AndrewsParameters {
  double m1 = .04325, m2 = .00365, m3 = .02373, m4 = .00706, m5 = .07050, m6 = .00706, m7 = .05498;
  double xa = -.06934, ya = -.00227, xb = -.03635, yb = .03273, xc = .014, yc = .072;
  double i1 = 2.194e-6, i2 = 4.410e-7, i3 = 5.255e-6, i4 = 5.667e-7, i5 = 1.169e-5, i6 = 5.667e-7,
         i7 = 1.912e-5;
  double d = 28e-3, da = 115e-4, e = 2e-2, ea = 1421e-5, rr = 7e-3, ra = 92e-5;
  double ss = 35e-3, sa = 1874e-5, sb = 1043e-5, sc = 18e-3, sd = 2e-2;
  double ta = 2308e-5, tb = 916e-5, u = 4e-2, ua = 1228e-5, ub = 449e-5;
  double zf = 2e-2, zt = 4e-2, fa = 1421e-5;
  double c0 = 4530, l0 = 7785e-5, mom = 33e-3;  // the keys `c0`, `l0`, `mom`
};

// The Test Set's consistent initial angles (v = 0), 30 digits in its source.
constexpr std::array<double, 7> kInitialAngles = {
    -0.0617138900142764496358948458001, 0.0,
    0.455279819163070380255912382449,   0.222668390165885884674473185609,
    0.487364979543842550225598953530,   -0.222668390165885884674473185609,
    1.23054744454982119249735015568};

// The Test Set's reference at t = 0.03 (andsoln in andrews.f: PSIDE with rtol = atol = 1e-14 in
// Cray double precision): angles, then angular velocities.
constexpr double kReferenceTime = 0.03;
constexpr std::array<double, 7> kReferenceAngles = {
    0.1581077119629904e+2, -0.1575637105984298e+2, 0.4082224013073101e-1, -0.5347301163226948e+0,
    0.5244099658805304e+0, 0.5347301163226948e+0,  0.1048080741042263e+1};
constexpr std::array<double, 7> kReferenceRates = {
    0.1139920302151208e+4, -0.1424379294994111e+4, 0.1103291221937134e+2, 0.1929337464421385e+2,
    0.5735699284790808e+0, -0.1929337464421385e+2, 0.3231791658026955e+0};

// A constraint is a constant plus terms a·cos(s) or a·sin(s) of an angle sum s = Σ_{j∈S} q_j, so
// g, G, the curvature and the Hessian follow from one rule: d/ds cos = −sin, d/ds sin = cos.
struct TrigTerm {
  double coefficient;
  bool is_cosine;
  std::array<int, 2> angles;  // indices into q; -1 = unused
};
struct LoopConstraint {
  double constant;
  std::array<TrigTerm, 4> terms;
};

class Andrews final : public Problem,
                      public LagrangianSystem,
                      public HolonomicConstraints,
                      public NonConservativeForce {
 public:
  explicit Andrews(const AndrewsParameters& p) : p_(p) {
    set_dof(7);  // no constant mass: M(q)
    // The Test Set's interval; β turns at up to ~1.4e3 rad/s, so steps of 1e-5 resolve it.
    set_defaults(1e-5, kReferenceTime);
    if (is_test_set_instance()) set_capabilities(kEndReference);
    build_constant_mass();
    build_constraints();
  }

  const LagrangianSystem* as_lagrangian() const override { return this; }
  const HolonomicConstraints* as_constrained() const override { return this; }
  const NonConservativeForce* as_forced() const override { return this; }

  // At rest in the Test Set's consistent configuration (p = M(q)·0 = 0).
  State initial_state() const override {
    return {0.0, Eigen::Map<const Vec>(kInitialAngles.data(), 7), Vec::Zero(7)};
  }

  double end_reference_time() const override { return kReferenceTime; }
  State end_reference() const override {
    const Vec q = Eigen::Map<const Vec>(kReferenceAngles.data(), 7);
    const Vec v = Eigen::Map<const Vec>(kReferenceRates.data(), 7);
    return {kReferenceTime, q, static_cast<const LagrangianSystem&>(*this).momentum(q, v)};
  }

  // ---- The mass M(q) = M₀ + cos Θ·P_Θ + sin Φ·P_Φ + sin Ω·P_Ω (the Test Set's m(i, j)) ----
  void mass_matrix(const Vec& q, DenseMatrix& M) const override {
    M = constant_mass_;
    for (const Dependence& dep : dependences()) M += dep.value(q[dep.angle]) * dep.pattern;
  }
  // T_q[k] = ½ f_k'(q_k) vᵀP_k v for the three angles M depends on.
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override {
    T_q = Vec::Zero(7);
    for (const Dependence& dep : dependences()) {
      T_q[dep.angle] = 0.5 * dep.rate(q[dep.angle]) * v.dot(dep.pattern * v);
    }
  }
  // D_ij = Σ_k ∂M_ik/∂q_j v_k: column j is f_j'(q_j) P_j v.
  void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const override {
    D = DenseMatrix::Zero(7, 7);
    for (const Dependence& dep : dependences()) {
      D.col(dep.angle) = dep.rate(q[dep.angle]) * (dep.pattern * v);
    }
  }
  void kinetic_hessian(const Vec& q, const Vec& v, DenseMatrix& T_qq) const override {
    T_qq = DenseMatrix::Zero(7, 7);
    for (const Dependence& dep : dependences()) {
      T_qq(dep.angle, dep.angle) = 0.5 * dep.curvature(q[dep.angle]) * v.dot(dep.pattern * v);
    }
  }

  // ---- The spring V = ½c₀(|r| − l₀)², r = D(γ) − C; it acts on γ alone ----
  double potential(const Vec& q) const override {
    const Spring s = spring(q[2]);
    return 0.5 * p_.c0 * (s.length - p_.l0) * (s.length - p_.l0);
  }
  void gradient(const Vec& q, Vec& g) const override {
    const Spring s = spring(q[2]);
    g = Vec::Zero(7);
    g[2] = p_.c0 * (s.length - p_.l0) * s.r_dot_rate / s.length;
  }
  // d²V/dγ² = c₀[(r·r')²/|r|² + (|r| − l₀)((|r'|² + r·r'')/|r| − (r·r')²/|r|³)].
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    const Spring s = spring(q[2]);
    const double radial = s.r_dot_rate / s.length;
    K = DenseMatrix::Zero(7, 7);
    K(2, 2) = p_.c0 *
              (radial * radial + (s.length - p_.l0) * (s.rate_squared + s.r_dot_second) / s.length -
               (s.length - p_.l0) * radial * radial / s.length);
  }

  // ---- The driving torque on β: a constant generalized force (its work is mom·Δβ) ----
  void force(const Vec& q, const Vec&, double, Vec& f) const override {
    f = Vec::Zero(q.size());
    f[0] = p_.mom;
  }
  bool has_force_jacobian() const override { return true; }
  void force_jacobian_v(const Vec& q, const Vec&, double, SparseMatrix& C) const override {
    C.resize(q.size(), q.size());
    C.setZero();
    C.makeCompressed();
  }

  // ---- The six loop closures (the Test Set's g and gp) ----
  int constraint_count() const override { return 6; }
  void constraint(const Vec& q, Vec& g) const override {
    g.resize(6);
    for (int i = 0; i < 6; ++i) {
      g[i] = constraints_[i].constant;
      for (const TrigTerm& term : constraints_[i].terms) {
        if (term.coefficient != 0) g[i] += term.coefficient * trig(term, angle_sum(term, q), 0);
      }
    }
  }
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override {
    DenseMatrix dense = DenseMatrix::Zero(6, 7);
    for (int i = 0; i < 6; ++i) {
      for (const TrigTerm& term : constraints_[i].terms) {
        if (term.coefficient == 0) continue;
        const double slope = term.coefficient * trig(term, angle_sum(term, q), 1);
        for (int j : term.angles) {
          if (j >= 0) dense(i, j) += slope;
        }
      }
    }
    G = dense.sparseView();
    G.makeCompressed();
  }
  // c_i = Σ_terms a f''(s) (Σ_{j∈S} v_j)².
  void constraint_curvature(const Vec& q, const Vec& v, Vec& c) const override {
    c = Vec::Zero(6);
    for (int i = 0; i < 6; ++i) {
      for (const TrigTerm& term : constraints_[i].terms) {
        if (term.coefficient == 0) continue;
        const double rate = angle_sum(term, v);
        c[i] += term.coefficient * trig(term, angle_sum(term, q), 2) * rate * rate;
      }
    }
  }
  void constraint_hessian(const Vec& q, const Vec& lambda, SparseMatrix& K) const override {
    DenseMatrix dense = DenseMatrix::Zero(7, 7);
    for (int i = 0; i < 6; ++i) {
      for (const TrigTerm& term : constraints_[i].terms) {
        if (term.coefficient == 0) continue;
        const double second = lambda[i] * term.coefficient * trig(term, angle_sum(term, q), 2);
        for (int j : term.angles) {
          for (int k : term.angles) {
            if (j >= 0 && k >= 0) dense(j, k) += second;
          }
        }
      }
    }
    K = dense.sparseView();
    K.makeCompressed();
  }

 private:
  // One angle k on which M depends: M += f(q_k) P with f = cos or sin.
  struct Dependence {
    int angle;
    bool is_cosine;
    DenseMatrix pattern;
    double value(double x) const { return is_cosine ? std::cos(x) : std::sin(x); }
    double rate(double x) const { return is_cosine ? -std::sin(x) : std::cos(x); }
    double curvature(double x) const { return -value(x); }
  };
  const std::array<Dependence, 3>& dependences() const { return dependences_; }

  struct Spring {
    double length, r_dot_rate, rate_squared, r_dot_second;
  };
  // D = (sd cos γ + sc sin γ + xb, sd sin γ − sc cos γ + yb), r = D − C, r' = dr/dγ,
  // r'' = −(D − B).
  Spring spring(double gamma) const {
    const double c = std::cos(gamma), s = std::sin(gamma);
    const double arm_x = p_.sd * c + p_.sc * s, arm_y = p_.sd * s - p_.sc * c;
    const double rx = arm_x + p_.xb - p_.xc, ry = arm_y + p_.yb - p_.yc;
    const double rate_x = -p_.sd * s + p_.sc * c, rate_y = p_.sd * c + p_.sc * s;
    return {std::hypot(rx, ry), rx * rate_x + ry * rate_y, rate_x * rate_x + rate_y * rate_y,
            -(rx * arm_x + ry * arm_y)};
  }

  static double angle_sum(const TrigTerm& term, const Vec& x) {
    double sum = 0;
    for (int j : term.angles) {
      if (j >= 0) sum += x[j];
    }
    return sum;
  }
  // The derivative of order `order` (0, 1, 2) of cos or sin at s.
  static double trig(const TrigTerm& term, double s, int order) {
    const double c = std::cos(s), sn = std::sin(s);
    if (term.is_cosine) return order == 0 ? c : order == 1 ? -sn : -c;
    return order == 0 ? sn : order == 1 ? c : -sn;
  }

  bool is_test_set_instance() const {
    const AndrewsParameters defaults;
    return p_.c0 == defaults.c0 && p_.l0 == defaults.l0 && p_.mom == defaults.mom;
  }

  void build_constant_mass() {
    const AndrewsParameters& p = p_;
    const double ee = p.e - p.ea, zz = p.zf - p.fa;
    DenseMatrix& M = constant_mass_;
    M = DenseMatrix::Zero(7, 7);
    M(0, 0) = p.m1 * p.ra * p.ra + p.m2 * (p.rr * p.rr + p.da * p.da) + p.i1 + p.i2;
    M(0, 1) = M(1, 0) = p.m2 * p.da * p.da + p.i2;
    M(1, 1) = p.m2 * p.da * p.da + p.i2;
    M(2, 2) = p.m3 * (p.sa * p.sa + p.sb * p.sb) + p.i3;
    M(3, 3) = p.m4 * ee * ee + p.i4;
    M(3, 4) = M(4, 3) = p.m4 * ee * ee + p.i4;
    M(4, 4) = p.m4 * (p.zt * p.zt + ee * ee) + p.m5 * (p.ta * p.ta + p.tb * p.tb) + p.i4 + p.i5;
    M(5, 5) = p.m6 * zz * zz + p.i6;
    M(5, 6) = M(6, 5) = p.m6 * zz * zz + p.i6;
    M(6, 6) = p.m6 * (zz * zz + p.u * p.u) + p.m7 * (p.ua * p.ua + p.ub * p.ub) + p.i6 + p.i7;
    // Body 2's offset couples β and Θ through cos Θ; body 4's through sin Φ, body 6's sin Ω.
    const double a = p.m2 * p.da * p.rr, b = p.m4 * p.zt * ee, c = p.m6 * p.u * zz;
    auto pattern = [](int i, int j, double off_diagonal, double diagonal) {
      DenseMatrix P = DenseMatrix::Zero(7, 7);
      P(i, j) = P(j, i) = off_diagonal;
      P(i, i) = diagonal;
      return P;
    };
    dependences_ = {Dependence{1, true, pattern(0, 1, -a, -2 * a)},
                    Dependence{3, false, pattern(4, 3, b, 2 * b)},
                    Dependence{5, false, pattern(6, 5, -c, -2 * c)}};
  }

  // g1, g2: the loop through B; g3, g4 and g5, g6: the two loops through A.
  void build_constraints() {
    const AndrewsParameters& p = p_;
    const TrigTerm none{0, true, {-1, -1}};
    const TrigTerm crank_x{p.rr, true, {0, -1}}, crank_y{p.rr, false, {0, -1}};
    const TrigTerm rod_x{-p.d, true, {0, 1}}, rod_y{-p.d, false, {0, 1}};
    constraints_ = {
        LoopConstraint{-p.xb, {crank_x, rod_x, TrigTerm{-p.ss, false, {2, -1}}, none}},
        LoopConstraint{-p.yb, {crank_y, rod_y, TrigTerm{p.ss, true, {2, -1}}, none}},
        LoopConstraint{
            -p.xa, {crank_x, rod_x, TrigTerm{-p.e, false, {3, 4}}, TrigTerm{-p.zt, true, {4, -1}}}},
        LoopConstraint{
            -p.ya, {crank_y, rod_y, TrigTerm{p.e, true, {3, 4}}, TrigTerm{-p.zt, false, {4, -1}}}},
        LoopConstraint{
            -p.xa, {crank_x, rod_x, TrigTerm{-p.zf, true, {5, 6}}, TrigTerm{-p.u, false, {6, -1}}}},
        LoopConstraint{
            -p.ya, {crank_y, rod_y, TrigTerm{-p.zf, false, {5, 6}}, TrigTerm{p.u, true, {6, -1}}}},
    };
  }

  AndrewsParameters p_;
  DenseMatrix constant_mass_;
  std::array<Dependence, 3> dependences_;
  std::array<LoopConstraint, 6> constraints_;
};

}  // namespace

std::unique_ptr<Problem> make_andrews(Params& params) {
  AndrewsParameters p;
  p.mom = params.real("mom", p.mom, "driving torque on the crank angle beta (N m)",
                      Range::magnitude(1e3));
  p.c0 = params.real("c0", p.c0, "spring stiffness (N/m)", Range::at_least(0));
  p.l0 = params.real("l0", p.l0, "spring rest length (m)", Range::above(0));
  return std::make_unique<Andrews>(p);
}

}  // namespace geomint
