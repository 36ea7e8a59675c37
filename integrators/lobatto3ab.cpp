// Lobatto IIIA–IIIB partitioned Runge–Kutta, s stages, order 2s − 2, symplectic for separable H
// and symmetric (Hairer, Lubich & Wanner, GNI §II.2.2, §VI.4; Jay 1996); s = 2 is Störmer–Verlet.
#include <fmt/format.h>

#include "integrators/high_order_coefficients.hpp"
#include "integrators/partitioned_rk.hpp"

namespace geomint {

// Positions by Lobatto IIIA (collocation at the Lobatto points), momenta by Lobatto IIIB; the
// stage solve is partitioned_rk.cpp's. Variational: the pair is the DEL map of the Lobatto
// quadrature discrete Lagrangian (Marsden & West 2001, §2.6), and as a symplectic PRK it keeps
// the invariants qᵀCp, angular momentum among them (GNI §IV.2).
std::unique_ptr<Integrator> make_lobatto3ab(Params& params) {
  const long stages = params.integer("s", 3, "Lobatto stages (order 2s - 2)", 2, 4);
  const coefficients::PartitionedTableau& tableau = stages == 2   ? coefficients::kLobatto2
                                                    : stages == 3 ? coefficients::kLobatto3
                                                                  : coefficients::kLobatto4;
  MethodInfo info{
      "lobatto3ab", tableau.order,
      kImplicit | kSymplectic | kSymmetric | kVariational | kNeedsHessian | kGeneralLagrangian,
      fmt::format("{}, order {}; GNI §II.2.2, §VI.4; Jay 1996", tableau.source, tableau.order)};
  return make_partitioned_rk(tableau, std::move(info), params);
}

}  // namespace geomint
