// The free rigid body's Lie–Poisson structure (MECHANICS.md §6), a structure interface
// (problems/structure.hpp) offered by rigid_body and rigid_body_euler and read by the Lie–Poisson
// splitting and the quaternion contrast.
#pragma once

#include <Eigen/Core>

#include "problems/structure.hpp"

namespace geomint {

// The principal moments J = diag(I1, I2, I3), and the state read as the attitude Q (the identity
// when the state holds none, as in Euler's equations) and the body angular momentum Π, and
// written back from them. The methods that need it read and write the state only through it, and
// applicable() admits them only where Problem::as<FreeRigidBodyStructure>() finds it.
class FreeRigidBodyStructure {
 public:
  static constexpr StructureKey kStructureKey{
      "free_rigid_body", "free rigid bodies",
      "rigid_body, rigid_body_euler, which offer their moments and (Q, Pi)"};
  virtual ~FreeRigidBodyStructure() = default;
  virtual Eigen::Vector3d principal_moments() const = 0;
  virtual void read_body(const Eigen::VectorXd& q, const Eigen::VectorXd& p,
                         Eigen::Matrix3d& attitude, Eigen::Vector3d& body_momentum) const = 0;
  virtual void write_body(const Eigen::Matrix3d& attitude, const Eigen::Vector3d& body_momentum,
                          Eigen::VectorXd& q, Eigen::VectorXd& p) const = 0;
};

}  // namespace geomint
