// The first-order kind y' = f(t, y) (docs/DESIGN.md §2, ProblemKind::kFirstOrder): the interface
// FirstOrderSystem a problem offers through Problem::as_first_order(), and the base
// FirstOrderProblem of the catalogue's (van der Pol, Robertson, Euler's rigid body equations).
#pragma once

#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "problems/problem.hpp"

namespace geomint {

// What a first-order problem implements. The state y is State::q (n = dof() entries) and
// State::p is empty; the problem has no potential, mass or Hamiltonian, so only the methods with
// kFirstOrderCapable run it (applicable()). Offering it sets kFirstOrderOnly (derived, never
// declared: Problem::set_capabilities refuses the bit).
class FirstOrderSystem {
 public:
  virtual ~FirstOrderSystem() = default;
  // ydot = f(t, y), resized by the callee to y.size().
  virtual void rhs(double t, const Vec& y, Vec& ydot) const = 0;
  // J = ∂f/∂y at (t, y), sparse n × n, compressed (the implicit ODE solvers' Newton matrix and
  // SUNDIALS' sparse path; checked against central differences in problems/first_order_test.cpp).
  virtual void rhs_jacobian(double t, const Vec& y, SparseMatrix& J) const = 0;
};

// Base for first-order-only problems: y0 and an optional tabulated end state; V is NaN and ∇V
// throws, so a Lagrangian method or metric reached by mistake shows up.
class FirstOrderProblem : public Problem, public FirstOrderSystem {
 public:
  const FirstOrderSystem* as_first_order() const override { return this; }
  State initial_state() const override { return {0.0, y0_, Vec()}; }
  // No potential: NaN, so an energy computed by mistake shows up instead of reading as 0.
  double potential(const Vec&) const override { return std::numeric_limits<double>::quiet_NaN(); }
  void gradient(const Vec&, Vec&) const override {
    throw std::logic_error("problem '" + name() + "' is first-order only: it has no potential");
  }
  double end_reference_time() const override { return reference_.t; }
  State end_reference() const override { return reference_; }

 protected:
  // y0 fixes the dimension dof() = n (no mass: mass() throws); `capabilities` are what the
  // problem declares beyond kFirstOrderOnly, which as_first_order() sets.
  FirstOrderProblem(Vec y0, unsigned capabilities) : y0_(std::move(y0)) {
    set_dof(static_cast<int>(y0_.size()));
    set_capabilities(capabilities);
  }
  // The tabulated solution y_ref at time t (kEndReference).
  void set_end_reference(double t, Vec y) { reference_ = {t, std::move(y), Vec()}; }

 private:
  Vec y0_;
  State reference_;
};

}  // namespace geomint
