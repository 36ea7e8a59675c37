// Gauss–Legendre collocation, s stages, order 2s, symplectic and symmetric (Butcher 1964;
// Hairer, Lubich & Wanner, GNI §II.1.3, §VI.4 and §V.2), applied to y = (q, p); s = 1 is the
// implicit midpoint rule.
#include <fmt/format.h>

#include "integrators/high_order_coefficients.hpp"
#include "integrators/partitioned_rk.hpp"

namespace geomint {

// The collocation polynomial through the s Gauss points; as a partitioned method â = a, so the
// stage solve of partitioned_rk.cpp applies. Variational: every symplectic (P)RK method is the
// DEL map of a discrete Lagrangian (Suris 1990; Marsden & West 2001, §2.6), and Gauss keeps all
// quadratic invariants (GNI §IV.2), angular momentum among them.
std::unique_ptr<Integrator> make_gauss(Params& params) {
  const long stages = params.integer("s", 2, "Gauss-Legendre stages (order 2s)", 1, 3);
  const coefficients::PartitionedTableau& tableau = stages == 1   ? coefficients::kGauss1
                                                    : stages == 2 ? coefficients::kGauss2
                                                                  : coefficients::kGauss3;
  MethodInfo info{
      "gauss", tableau.order,
      kImplicit | kSymplectic | kSymmetric | kVariational | kNeedsHessian | kGeneralLagrangian,
      fmt::format("{}, order {}; Butcher 1964; GNI §II.1.3, §VI.4", tableau.source, tableau.order)};
  return make_partitioned_rk(tableau, std::move(info), params);
}

}  // namespace geomint
