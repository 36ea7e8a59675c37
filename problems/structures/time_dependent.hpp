// A Hamiltonian with explicit time dependence, H(q, p, t) = T(p, t) + V(q, t) (separable in
// form), as a structure interface (problems/structure.hpp): what the methods that treat time
// (integrators/time_treatment.hpp) and Problem::first_order_rhs read instead of M⁻¹p and −∇V(q).
#pragma once

#include <Eigen/Core>

#include "problems/structure.hpp"

namespace geomint {

// The two halves of the vector field at time t. A problem offering it is still of the separable
// kind (its mass, potential() and gradient() are those of H at its initial time, for the
// catalogue's checks), but no method may read them for the motion: applicable() admits only the
// methods whose time treatment is not "none" (integrators/time_treatment.hpp).
class TimeDependentHamiltonian {
 public:
  static constexpr StructureKey kStructureKey{
      "time_dependent_hamiltonian", "time-dependent Hamiltonians H(q, p, t)",
      "damped_harmonic_td, which offers T(p, t), V(q, t) and its equations of motion"};
  virtual ~TimeDependentHamiltonian() = default;
  // H(q, p, t).
  virtual double hamiltonian(const Eigen::VectorXd& q, const Eigen::VectorXd& p,
                             double t) const = 0;
  // q̇ = ∂T/∂p (p, t); `qdot` is resized by the callee.
  virtual void velocity(const Eigen::VectorXd& p, double t, Eigen::VectorXd& qdot) const = 0;
  // ṗ = −∂V/∂q (q, t) for a Hamiltonian form; a form that is not Hamiltonian (is_hamiltonian()
  // false) may read p as well. `pdot` is resized by the callee.
  virtual void momentum_rate(const Eigen::VectorXd& q, const Eigen::VectorXd& p, double t,
                             Eigen::VectorXd& pdot) const = 0;
  // Whether (velocity, momentum_rate) are Hamilton's equations of hamiltonian().
  virtual bool is_hamiltonian() const { return true; }
};

}  // namespace geomint
