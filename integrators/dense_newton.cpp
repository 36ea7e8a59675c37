// The dense Newton loop of the general-Lagrangian steps (see dense_newton.hpp): Eigen's
// PartialPivLU on the few-dof, non-symmetric step Jacobians.
#include "integrators/dense_newton.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>

namespace geomint {

double dense_inf_norm(const Vec& x) { return x.size() == 0 ? 0.0 : x.cwiseAbs().maxCoeff(); }

StepStatus dense_newton(const DenseNewtonSystem& system, Vec& x,
                        const GeneralNewtonSettings& newton, Counters& counters) {
  const std::string label =
      system.unknown.empty() ? std::string("R") : fmt::format("R({})", system.unknown);
  DenseMatrix jacobian;
  const auto factorise = [&](const Vec& at) {
    system.jacobian(at, jacobian);
    ++counters.factorizations;
    return Eigen::PartialPivLU<DenseMatrix>(jacobian);
  };
  const double floor = std::max(newton.tolerance, kDenseRoundoffFloor);
  Vec residual, polished_residual;
  for (int iteration = 0;; ++iteration) {
    system.residual(x, residual);
    if (!residual.allFinite()) {
      return StepStatus::failure("nan", system.unknown.empty()
                                            ? fmt::format("{}: non-finite residual", system.method)
                                            : fmt::format("{}: non-finite residual for {}",
                                                          system.method, system.unknown));
    }
    if (system.converged(residual, floor)) break;
    if (iteration == newton.max_iterations) {
      return StepStatus::failure(
          "newton_max_iter",
          fmt::format("{}: |{}| = {:.3g} after {} Newton iterations (tol {:.3g})", system.method,
                      label, dense_inf_norm(residual), iteration, newton.tolerance));
    }
    x -= factorise(x).solve(residual);
    ++counters.linear_solves;
    ++counters.newton_iters;
  }
  // Polishing: one more correction with a fresh LU, kept only if it lowers ‖R‖.
  const Vec polished = x - factorise(x).solve(residual);
  ++counters.linear_solves;
  system.residual(polished, polished_residual);
  if (polished_residual.allFinite() &&
      dense_inf_norm(polished_residual) < dense_inf_norm(residual)) {
    x = polished;
  } else if (system.reevaluate_after_rejected_polish) {
    system.residual(x, residual);
  }
  return StepStatus::success();
}

}  // namespace geomint
