// The Toda lattice's Lax matrix (Flaschka 1974), a structure interface (problems/structure.hpp)
// offered by the toda problem and read by the toda_invariants_err_max metric.
#pragma once

#include <Eigen/Core>

#include "problems/structure.hpp"

namespace geomint {

// L(q, p): symmetric, diagonal b_i = −p_i/2, off-diagonal a_i = ½√α e^{(q_i − q_{i+1})/2} (and
// the corner a_n of the periodic lattice). L̇ = [B, L] along the flow, so its spectrum and the
// traces tr Lᵏ (Flaschka's invariants; tr L² = H/2) are conserved.
class TodaStructure {
 public:
  static constexpr StructureKey kStructureKey{"toda", "Toda lattices",
                                              "toda, which offers its Lax matrix"};
  virtual ~TodaStructure() = default;
  virtual Eigen::MatrixXd lax_matrix(const Eigen::VectorXd& q, const Eigen::VectorXd& p) const = 0;
};

// tr Lᵏ for k = 1 … n (n = L.rows()), by repeated multiplication.
Eigen::VectorXd flaschka_invariants(const Eigen::MatrixXd& lax);

}  // namespace geomint
