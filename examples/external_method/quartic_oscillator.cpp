// A user's problem: the quartic oscillator H = p²/(2m) + k q⁴/4 (nonlinear, period depends on
// amplitude), with m ≠ 1 by default so a method that forgets M⁻¹ shows it.
#include <cmath>
#include <memory>

#include "problems/problem.hpp"
#include "user_extensions.hpp"

namespace user {
namespace {

using geomint::Problem;
using geomint::SparseMatrix;
using geomint::State;
using geomint::Vec;

class QuarticOscillator final : public Problem {
 public:
  QuarticOscillator(double mass, double k, double q0) : mass_(mass), k_(k), q0_(q0) {
    set_mass(Vec::Constant(1, mass));
    set_capabilities(geomint::kHessian | geomint::kOmegaMax);
    set_defaults(0.01, 20.0);
  }
  State initial_state() const override { return {0.0, Vec::Constant(1, q0_), Vec::Zero(1)}; }
  double potential(const Vec& q) const override { return 0.25 * k_ * std::pow(q[0], 4); }
  void gradient(const Vec& q, Vec& g) const override {
    g.resize(1);
    g[0] = k_ * q[0] * q[0] * q[0];
  }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    H.resize(1, 1);
    H.setZero();
    H.insert(0, 0) = 3 * k_ * q[0] * q[0];
    H.makeCompressed();
  }
  double omega_max(const Vec& q) const override { return std::sqrt(3 * k_ * q[0] * q[0] / mass_); }

 private:
  double mass_, k_, q0_;
};

std::unique_ptr<Problem> make_quartic(geomint::Params& params) {
  const auto positive = [](double x) { return x > 0; };
  const double mass = params.real("mass", 2.5, "mass m", positive, "> 0");
  const double k = params.real("k", 4.0, "quartic stiffness k", positive, "> 0");
  const double q0 = params.real("q0", 1.0, "initial position (released from rest)");
  return std::make_unique<QuarticOscillator>(mass, k, q0);
}

}  // namespace

void register_problems() {
  geomint::register_problem(
      {"user_quartic", "H = p²/2m + k q⁴/4 (user-written)", &make_quartic, {}});
}

}  // namespace user
