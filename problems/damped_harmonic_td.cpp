// SUNDIALS' ark_damped_harmonic_symplectic (Struckmeier & Riedel 2002, Ann. Phys. 11, ex. 7.2):
// H(q, p, t) = ½p²e^{−F(t)} + ½ω(t)²q²e^{F(t)}, ω = cos(t/2), F = F₀ sin(t/π), a time-dependent
// Hamiltonian offered as problems/structures/time_dependent.hpp; no exact solution.
#include <cmath>
#include <numbers>

#include "problems/problem.hpp"
#include "problems/structures/time_dependent.hpp"

namespace geomint {
namespace {

// form=hamiltonian: Hamilton's equations of H, q̇ = p e^{−F}, ṗ = −ω² q e^{F} (so
// q̈ + Ḟ q̇ + ω² q = 0, the damped oscillator the example is named after). form=sundials: the
// right-hand side the example's code integrates, q̇ = p e^{−F}, ṗ = −(F p + ω² q); it is not
// Hamilton's equations of that H (nor of any H: ṗ reads p), and the H the example prints is not
// conserved by either. Mass 1; potential() and gradient() are V(q, 0) = ½q², for the catalogue's
// checks only (no method that treats time reads them).
class DampedHarmonicTd final : public Problem, public TimeDependentHamiltonian {
 public:
  DampedHarmonicTd(bool sundials_form, double amplitude, double q0, double p0)
      : sundials_form_(sundials_form), amplitude_(amplitude), q0_(q0), p0_(p0) {
    set_mass(Vec::Ones(1));
    // SUNDIALS' own configuration: dt = 10⁻³ on [0, 10π].
    set_defaults(1e-3, 10 * std::numbers::pi);
  }

  const void* structure(const StructureKey& key) const override {
    if (const void* s = offer<TimeDependentHamiltonian>(key, this)) return s;
    return Problem::structure(key);
  }

  State initial_state() const override {
    return {0.0, Vec::Constant(1, q0_), Vec::Constant(1, p0_)};
  }
  double potential(const Vec& q) const override { return 0.5 * q[0] * q[0]; }
  void gradient(const Vec& q, Vec& g) const override { g = q; }

  double hamiltonian(const Vec& q, const Vec& p, double t) const override {
    const double omega = frequency(t), f = damping(t);
    return 0.5 * p[0] * p[0] * std::exp(-f) + 0.5 * omega * omega * q[0] * q[0] * std::exp(f);
  }
  void velocity(const Vec& p, double t, Vec& qdot) const override {
    qdot = Vec::Constant(1, p[0] * std::exp(-damping(t)));
  }
  void momentum_rate(const Vec& q, const Vec& p, double t, Vec& pdot) const override {
    const double omega = frequency(t), f = damping(t);
    pdot = Vec::Constant(1, sundials_form_ ? -(f * p[0] + omega * omega * q[0])
                                           : -omega * omega * q[0] * std::exp(f));
  }
  bool is_hamiltonian() const override { return !sundials_form_; }

 private:
  static double frequency(double t) { return std::cos(t / 2); }
  double damping(double t) const { return amplitude_ * std::sin(t / std::numbers::pi); }

  bool sundials_form_;
  double amplitude_, q0_, p0_;
};

}  // namespace

std::unique_ptr<Problem> make_damped_harmonic_td(Params& params) {
  const bool sundials_form =
      params.choice("form", "hamiltonian", {"hamiltonian", "sundials"},
                    "hamiltonian: Hamilton's equations of H; sundials: the example's code, "
                    "p' = -(F p + omega^2 q), which is not Hamiltonian") == "sundials";
  const double amplitude =
      params.real("amplitude", 0.018, "F0 in F(t) = F0 sin(t/pi)", Range::magnitude(1));
  const double q0 = params.real("q0", 1.0, "initial position");
  const double p0 = params.real("p0", 0.0, "initial momentum");
  return std::make_unique<DampedHarmonicTd>(sundials_form, amplitude, q0, p0);
}

}  // namespace geomint
