// A non-conservative generalized force F(q, v, t) (damping, driving; docs/DESIGN.md §2,
// PAPER.md's forced variational integrators): the interface NonConservativeForce a problem offers
// through Problem::as_forced().
#pragma once

#include "problems/problem.hpp"

namespace geomint {

// What a forced problem implements. Offering it sets kForce, and has_force_jacobian() sets
// kForceJacobian (both derived, never declared: Problem::set_capabilities refuses them), so a
// problem cannot claim a force or a Jacobian it does not have.
class NonConservativeForce {
 public:
  virtual ~NonConservativeForce() = default;
  // f = F(q, v, t), the generalized force added to −∇V(q): ṗ = −∇V(q) + F(q, v, t) with
  // v = M⁻¹p. f is resized by the callee to q.size().
  virtual void force(const Vec& q, const Vec& v, double t, Vec& f) const = 0;
  // Whether force_jacobian_v is offered (kForceJacobian). A force without it is differenced by
  // the implicit methods that need ∂F/∂v (integrators/forcing.cpp, integrators/euler.cpp).
  virtual bool has_force_jacobian() const { return false; }
  // C = −∂F/∂v at (q, v, t), dof × dof, compressed (the damping matrix, symmetric positive
  // semidefinite for a dissipative force; its q-dependence is not part of it). Only when
  // has_force_jacobian(); the default throws std::logic_error.
  virtual void force_jacobian_v(const Vec& q, const Vec& v, double t, SparseMatrix& C) const;
};

}  // namespace geomint
