// The one-degree-of-freedom oscillator pieces that harmonic and parametric_oscillator share
// (GNI §I.1): V = ½ m ω² q², its gradient and Hessian, and the start (q0, m v0).
#pragma once

#include "problems/problem.hpp"

namespace geomint {

class OscillatorBase : public Problem {
 public:
  OscillatorBase(double omega, double mass, double q0, double v0)
      : omega_(omega), mass_(mass), q0_(q0), v0_(v0) {
    set_mass(Vec::Constant(1, mass));
  }

  State initial_state() const override {
    return {0.0, Vec::Constant(1, q0_), Vec::Constant(1, mass_ * v0_)};
  }

  double potential(const Vec& q) const override { return 0.5 * stiffness() * q[0] * q[0]; }
  void gradient(const Vec& q, Vec& g) const override { HarmonicGradient{stiffness()}(q, g); }
  FixedGradient fixed_gradient() const override { return HarmonicGradient{stiffness()}; }
  bool is_linear() const override { return true; }
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(1, 1);
    H.setZero();
    H.insert(0, 0) = stiffness();
    H.makeCompressed();
  }

 protected:
  double stiffness() const { return mass_ * omega_ * omega_; }

  double omega_;
  double mass_;
  double q0_;
  double v0_;
};

}  // namespace geomint
