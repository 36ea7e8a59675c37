// Base for first-order-only problems y' = f(t, y) (Problem capability kFirstOrderOnly, docs/
// DESIGN.md §2): y lives in State::q, State::p is empty, and the Lagrangian pieces (V, ∇V) are
// absent, so only the ODE solvers (applicable(): kFirstOrderCapable) see them.
#pragma once

#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "problems/problem.hpp"

namespace geomint {

class FirstOrderProblem : public Problem {
 public:
  State initial_state() const override { return {0.0, y0_, Vec()}; }
  // No potential: NaN, so an energy computed by mistake shows up instead of reading as 0.
  double potential(const Vec&) const override { return std::numeric_limits<double>::quiet_NaN(); }
  void gradient(const Vec&, Vec&) const override {
    throw std::logic_error("problem '" + name() + "' is first-order only: it has no potential");
  }
  double end_reference_time() const override { return reference_.t; }
  State end_reference() const override { return reference_; }

 protected:
  // y0 fixes the dimension (the unit "mass" only sizes dof() = n); `extra` capabilities are
  // added to kFirstOrderOnly.
  FirstOrderProblem(Vec y0, unsigned extra) : y0_(std::move(y0)) {
    set_mass(Vec::Ones(y0_.size()));
    set_capabilities(kFirstOrderOnly | extra);
  }
  // The tabulated solution y_ref at time t (kEndReference).
  void set_end_reference(double t, Vec y) { reference_ = {t, std::move(y), Vec()}; }

 private:
  Vec y0_;
  State reference_;
};

}  // namespace geomint
