// An attitude Q ∈ SO(3) held in the state (MECHANICS.md §6), a structure interface
// (problems/structure.hpp) offered by rigid_body and heavy_top and read by the
// orthogonality_err_max metric (harness/observers.cpp).
#pragma once

#include <Eigen/Core>

#include "problems/structure.hpp"

namespace geomint {

class AttitudeStructure {
 public:
  static constexpr StructureKey kStructureKey{
      "attitude", "attitude problems",
      "rigid_body, heavy_top, whose state holds Q as 9 constrained coordinates"};
  virtual ~AttitudeStructure() = default;
  // Q from the configuration (its entries, column by column).
  virtual Eigen::Matrix3d attitude(const Eigen::VectorXd& q) const = 0;
};

}  // namespace geomint
