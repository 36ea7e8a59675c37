// A charged particle in 3D, L = ½m|v|² + q v·A(x) − qφ(x) (../shared/MECHANICS.md §5): B = f(z)ẑ on
// the axis with A = ½f(z)(−y, x, 0), f = B (uniform) or B(1 + z²/L²) (magnetic bottle), φ = −E·x.
// Uniform fields: exact gyration at ω = qB/m about a guiding centre drifting at E×B/B².
#include "problems/charged_particle.hpp"

#include <cmath>
#include <complex>
#include <numbers>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

using Vector3 = Eigen::Vector3d;

struct ChargedParticleParameters {
  bool bottle = false;
  double mass = 1, charge = 1, field = 1, bottle_length = 1;
  Vector3 electric = Vector3::Zero();
  Vector3 velocity = Vector3::Zero();
  double centre_x = 0, centre_y = 0, z0 = 0;
};

class ChargedParticle final : public Problem,
                              public LagrangianSystem,
                              public ChargedParticleStructure {
 public:
  const LagrangianSystem* as_lagrangian() const override { return this; }
  const void* structure(const StructureKey& key) const override {
    if (const void* offered = offer<ChargedParticleStructure>(key, this)) return offered;
    return Problem::structure(key);
  }
  explicit ChargedParticle(const ChargedParticleParameters& parameters) : p_(parameters) {
    set_dof(3);  // no constant mass: the Lagrangian is non-separable
    const bool axisymmetric = p_.electric[0] == 0 && p_.electric[1] == 0;
    unsigned capabilities = kOmegaMax;
    if (!p_.bottle) capabilities |= kExact;
    // Rotations about the field axis leave L unchanged (A = ½f(z)(−y, x, 0), φ = −E_z z): the
    // canonical angular momentum x p_y − y p_x is Noether's invariant.
    if (axisymmetric) capabilities |= kAngularMomentum;
    // Periodic only without E and without motion along B (otherwise a helix or a drift).
    if (!p_.bottle && p_.electric.isZero(0) && p_.velocity[2] == 0) capabilities |= kPeriod;
    set_capabilities(capabilities);
    const double gyration = std::abs(gyrofrequency(p_.z0));
    // 0.05 rad per step (~126 steps per gyration); ten gyrations, or a hundred in the bottle,
    // whose bounce between the mirrors is slower.
    set_defaults(0.05 / gyration, (p_.bottle ? 100 : 10) * 2 * std::numbers::pi / gyration);
  }

  State initial_state() const override {
    const Vector3 x = initial_position();
    const Vec q = x;
    return {0.0, q, momentum(q, Vec(p_.velocity))};
  }

  // ---- LagrangianSystem: T = ½m|v|² (constant mass), a(x) = q A(x), V = qφ = −q E·x ----
  void mass_matrix(const Vec&, DenseMatrix& M) const override {
    M = p_.mass * DenseMatrix::Identity(3, 3);
  }
  void kinetic_gradient(const Vec&, const Vec&, Vec& T_q) const override { T_q = Vec::Zero(3); }
  void mass_velocity_jacobian(const Vec&, const Vec&, DenseMatrix& D) const override {
    D = DenseMatrix::Zero(3, 3);
  }
  void kinetic_hessian(const Vec&, const Vec&, DenseMatrix& T_qq) const override {
    T_qq = DenseMatrix::Zero(3, 3);
  }
  void gyroscopic(const Vec& q, Vec& a) const override { a = p_.charge * vector_potential(q); }
  // a = c f(z)(−y, x, 0), c = q/2.
  void gyroscopic_jacobian(const Vec& q, DenseMatrix& A) const override {
    const double c = p_.charge / 2, f = axial_field(q[2]), df = axial_field_slope(q[2]);
    A = DenseMatrix::Zero(3, 3);
    A(0, 1) = -c * f;
    A(0, 2) = -c * q[1] * df;
    A(1, 0) = c * f;
    A(1, 2) = c * q[0] * df;
  }
  // a·v = c f(z)(x v_y − y v_x): only the z-derivatives of f couple.
  void gyroscopic_hessian(const Vec& q, const Vec& v, DenseMatrix& a_qq) const override {
    const double c = p_.charge / 2, df = axial_field_slope(q[2]);
    a_qq = DenseMatrix::Zero(3, 3);
    a_qq(0, 2) = a_qq(2, 0) = c * df * v[1];
    a_qq(1, 2) = a_qq(2, 1) = -c * df * v[0];
    a_qq(2, 2) = c * axial_field_curvature() * (q[0] * v[1] - q[1] * v[0]);
  }
  double potential(const Vec& q) const override {
    return -p_.charge * p_.electric.dot(Vector3(q.head<3>()));
  }
  void gradient(const Vec&, Vec& g) const override { g = -p_.charge * p_.electric; }
  void potential_hessian(const Vec&, DenseMatrix& K) const override { K = DenseMatrix::Zero(3, 3); }

  // ---- ChargedParticleStructure ----
  double particle_mass() const override { return p_.mass; }
  double particle_charge() const override { return p_.charge; }
  // B = curl A = (−x f′/2, −y f′/2, f): divergence-free, as a magnetic field must be.
  void fields(const Vector3& x, Vector3& E, Vector3& B) const override {
    E = p_.electric;
    const double df = axial_field_slope(x[2]);
    B << -x[0] * df / 2, -x[1] * df / 2, axial_field(x[2]);
  }
  Vector3 vector_potential(const Vector3& x) const override {
    const double f = axial_field(x[2]);
    return {-x[1] * f / 2, x[0] * f / 2, 0.0};
  }
  Vec vector_potential(const Vec& q) const { return vector_potential(Vector3(q.head<3>())); }

  // ---- Problem ----
  double omega_max(const Vec& q) const override { return std::abs(gyrofrequency(q[2])); }
  double period() const override { return 2 * std::numbers::pi / std::abs(gyrofrequency(0)); }
  // x − x_c crosses zero upwards once per gyration whatever the guiding centre.
  double period_observable(const Vec& q, const Vec&) const override { return q[0] - p_.centre_x; }
  // The canonical angular momentum about the field axis, m(x v_y − y v_x) + (q f/2)(x² + y²).
  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    return Vec::Constant(1, q[0] * p[1] - q[1] * p[0]);
  }

  // Uniform B ẑ and E: v∥ accelerates at qE_z/m; w = v⊥ − u (u = E×B/B²) turns at −ω, so in the
  // complex plane w(t) = w₀e^{−iωt} and x⊥(t) = x⊥(0) + ut + i w₀(e^{−iωt} − 1)/ω.
  State exact(double t) const override {
    using Complex = std::complex<double>;
    const double omega = gyrofrequency(0);
    const Vector3 x0 = initial_position();
    const Complex drift(p_.electric[1] / p_.field, -p_.electric[0] / p_.field);
    const Complex w0 = Complex(p_.velocity[0], p_.velocity[1]) - drift;
    const Complex turn = std::polar(1.0, -omega * t);
    const Complex position =
        Complex(x0[0], x0[1]) + drift * t + Complex(0, 1) * w0 * (turn - 1.0) / omega;
    const Complex velocity = drift + w0 * turn;
    const double acceleration = p_.charge * p_.electric[2] / p_.mass;
    Vec q(3), v(3);
    q << position.real(), position.imag(), x0[2] + p_.velocity[2] * t + acceleration * t * t / 2;
    v << velocity.real(), velocity.imag(), p_.velocity[2] + acceleration * t;
    return {t, q, momentum(q, v)};
  }

  // The magnetic moment m v⊥²/(2|B|), v⊥ across the local field: an adiabatic invariant in the
  // bottle (constant in a uniform field).
  std::vector<std::string> series_names() const override { return {"magnetic_moment"}; }
  void series_values(const Vec& q, const Vec& p, std::vector<double>& values) const override {
    const Vector3 v = velocity(q, p);
    Vector3 E, B;
    fields(Vector3(q.head<3>()), E, B);
    const double along = v.dot(B) / B.norm();
    values = {p_.mass * (v.squaredNorm() - along * along) / (2 * B.norm())};
  }

 private:
  double axial_field(double z) const {
    return p_.bottle ? p_.field * (1 + z * z / (p_.bottle_length * p_.bottle_length)) : p_.field;
  }
  double axial_field_slope(double z) const {
    return p_.bottle ? 2 * p_.field * z / (p_.bottle_length * p_.bottle_length) : 0.0;
  }
  double axial_field_curvature() const {
    return p_.bottle ? 2 * p_.field / (p_.bottle_length * p_.bottle_length) : 0.0;
  }
  double gyrofrequency(double z) const { return p_.charge * axial_field(z) / p_.mass; }
  // The guiding centre (centre_x, centre_y) plus the gyration radius vector i w₀/ω (complex
  // notation, w₀ = v⊥ − u), so the particle circles about the given centre.
  Vector3 initial_position() const {
    const double omega = gyrofrequency(p_.z0), f = axial_field(p_.z0);
    const double wx = p_.velocity[0] - p_.electric[1] / f;
    const double wy = p_.velocity[1] + p_.electric[0] / f;
    return {p_.centre_x - wy / omega, p_.centre_y + wx / omega, p_.z0};
  }

  ChargedParticleParameters p_;
};

}  // namespace

std::unique_ptr<Problem> make_charged_particle(Params& params) {
  ChargedParticleParameters p;
  p.bottle = params.choice("field", "uniform", {"uniform", "bottle"},
                           "uniform B along z, or a magnetic bottle B_z = B(1 + z²/length²) on "
                           "the axis") == "bottle";
  p.mass = params.real("mass", 1.0, "particle mass m", Range::above(0));
  p.charge = params.real("charge", 1.0, "particle charge q (either sign)", Range::non_zero());
  p.field =
      params.real("B", 1.0, "magnetic field on the axis at z = 0 (along z)", Range::non_zero());
  p.bottle_length =
      params.real("length", 1.0, "bottle: distance over which B_z grows by B (field=bottle only)",
                  Range::above(0));
  p.electric[0] = params.real("Ex", 0.0, "uniform electric field, x component");
  p.electric[1] = params.real("Ey", 0.0, "uniform electric field, y component");
  p.electric[2] = params.real("Ez", 0.0, "uniform electric field, z component (along B)");
  p.velocity[0] = params.real("vx", 1.0, "initial velocity, x component");
  p.velocity[1] = params.real("vy", 0.0, "initial velocity, y component");
  p.velocity[2] = params.real("vz", 0.3, "initial velocity along the field axis");
  p.centre_x = params.real("xc", 0.0,
                           "initial guiding centre, x (the particle starts one gyration "
                           "radius from it)");
  p.centre_y = params.real("yc", 0.0, "initial guiding centre, y");
  p.z0 = params.real("z0", 0.0, "initial z");
  return std::make_unique<ChargedParticle>(p);
}

}  // namespace geomint
