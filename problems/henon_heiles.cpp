// Hénon–Heiles system (GNI §I.3): H = ½(p₁² + p₂²) + ½(q₁² + q₂²) + q₁²q₂ − q₂³/3, bounded for
// energies below the saddle value 1/6, regular or chaotic depending on the orbit.
#include <fmt/format.h>

#include <cmath>

#include "problems/problem.hpp"

namespace geomint {
namespace {

class HenonHeiles final : public Problem {
 public:
  explicit HenonHeiles(const State& initial) : initial_(initial) {
    set_mass(Vec::Ones(2));
    set_capabilities(kHessian | kOmegaMax);
    // The linear frequencies are ~1: 60 steps per period, a few hundred periods.
    set_defaults(0.1, 1000.0);
  }

  State initial_state() const override { return initial_; }

  double potential(const Vec& q) const override { return value(q[0], q[1]); }
  void gradient(const Vec& q, Vec& g) const override { HenonHeilesGradient()(q, g); }
  FixedGradient fixed_gradient() const override { return HenonHeilesGradient(); }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    H.resize(2, 2);
    H.setZero();
    H.insert(0, 0) = 1 + 2 * q[1];
    H.insert(0, 1) = 2 * q[0];
    H.insert(1, 0) = 2 * q[0];
    H.insert(1, 1) = 1 - 2 * q[1];
    H.makeCompressed();
  }
  // The Hessian's eigenvalues are 1 ± 2|q|; the larger one is exact.
  double omega_max(const Vec& q) const override {
    return std::sqrt(1 + 2 * std::hypot(q[0], q[1]));
  }

  static double value(double q1, double q2) {
    return 0.5 * (q1 * q1 + q2 * q2) + q1 * q1 * q2 - q2 * q2 * q2 / 3;
  }

 private:
  State initial_;
};

}  // namespace

std::unique_ptr<Problem> make_henon_heiles(Params& params) {
  const double energy =
      params.real("energy", 1.0 / 12, "total energy H (orbits with H < 1/6 stay bounded)");
  const double q1 = params.real("q1", 0.0, "initial q1");
  const double q2 = params.real("q2", 0.1, "initial q2");
  const double p1 = params.real("p1", 0.1, "initial p1 (p2 >= 0 follows from the energy)");
  // p₂ = +√(2(H − V(q)) − p₁²) must be real.
  const double p2_squared = 2 * (energy - HenonHeiles::value(q1, q2)) - p1 * p1;
  if (!(p2_squared >= 0)) {
    throw InputError(fmt::format(
        "problem 'henon_heiles': parameter energy={} is below V(q1, q2) + p1^2/2 = {} for "
        "q1={}, q2={}, p1={}",
        format_number(energy), format_number(HenonHeiles::value(q1, q2) + 0.5 * p1 * p1),
        format_number(q1), format_number(q2), format_number(p1)));
  }
  State initial{0.0, Vec(2), Vec(2)};
  initial.q << q1, q2;
  initial.p << p1, std::sqrt(p2_squared);
  return std::make_unique<HenonHeiles>(initial);
}

}  // namespace geomint
