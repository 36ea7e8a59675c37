// Holonomic constraints g(q) = 0 and g(q, t) = 0 as an interface of their own (PAPER.md §3,
// docs/METHOD.md §3, docs/DESIGN.md §2): what a constrained problem implements and returns from
// Problem::as_constrained().
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <optional>
#include <string>
#include <vector>

namespace geomint {

// The same aliases as problems/problem.hpp (which includes this header).
using Vec = Eigen::VectorXd;
using SparseMatrix = Eigen::SparseMatrix<double>;

// The motion is M q̈ = −∇V(q) + F − G(q)ᵀλ, G = ∂g/∂q, with m = constraint_count() multipliers
// λ. A problem with constraints derives from this interface as well as from Problem and returns
// `this` from Problem::as_constrained() (nullptr when an instance has none, e.g. elastic_bar
// without clamp=constraint|pin); the capabilities kConstraints and kTimeDependentConstraints are
// derived from that query and time_dependent(), never declared (Problem::capabilities()).
// Problems whose initial state comes from user parameters get it checked by make_problem (an
// inconsistent state is an InputError naming the residual, Problem::check_consistent).
class HolonomicConstraints {
 public:
  virtual ~HolonomicConstraints() = default;

  // m, the number of constraints and multipliers.
  virtual int constraint_count() const = 0;
  // g = g(q) ∈ Rᵐ; g is resized by the callee.
  virtual void constraint(const Vec& q, Vec& g) const = 0;
  // G = ∂g/∂q, m × n, compressed.
  virtual void constraint_jacobian(const Vec& q, SparseMatrix& G) const = 0;
  // c = (∂G/∂q · v) v ∈ Rᵐ, so that d²g/dt² = G(q) q̈ + c(q, v): the term index reduction needs.
  virtual void constraint_curvature(const Vec& q, const Vec& v, Vec& c) const = 0;
  // K = Σᵢ λᵢ ∇²gᵢ(q), n × n, symmetric, compressed: the constraint part of the Hessian of the
  // Lagrangian V + λᵀg that Newton/KKT solves of constrained steps need.
  virtual void constraint_hessian(const Vec& q, const Vec& lambda, SparseMatrix& K) const = 0;
  // Names of the multipliers for series columns ("tension"); default lambda1 … lambdam.
  virtual std::vector<std::string> multiplier_names() const;

  // Rheonomic constraints g(q, t) = 0 (time_dependent(), e.g. a driven joint; the capability
  // kTimeDependentConstraints): g and G at time t, and the explicit time terms g_t = ∂g/∂t and
  // a_t = 2(∂G/∂t)v + ∂²g/∂t², so that dg/dt = G v + g_t and d²g/dt² = G q̈ + c(q, v) + a_t (c and
  // K above carry no explicit t). Defaults: the time-free functions and zero terms. Only methods
  // that declare kRheonomic see such problems (applicable()); the time-free functions of a
  // rheonomic problem give g and G at t = 0.
  virtual bool time_dependent() const { return false; }
  virtual void constraint_at(double t, const Vec& q, Vec& g) const;
  virtual void constraint_jacobian_at(double t, const Vec& q, SparseMatrix& G) const;
  virtual void constraint_time_terms(double t, const Vec& q, const Vec& v, Vec& g_t,
                                     Vec& a_t) const;

  // The exact motion's multipliers λ(t) (same sign and units as Problem::multipliers()), from the
  // problem's own closed form; nullopt when it has none (the default). The order study fits the
  // methods' discrete multipliers against it (harness/order.cpp, docs/METHOD.md §3).
  virtual std::optional<Vec> exact_multipliers(double t) const;
};

}  // namespace geomint
