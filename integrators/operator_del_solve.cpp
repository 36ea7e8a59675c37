// Matrix-free solve of del's and hp's velocity equation (operator_del_solve.hpp): quasi-Newton on
// the O(n) preconditioner P = M + h²α(1−α)K₊, or Newton–Krylov (GMRES) preconditioned by it.
#include "integrators/operator_del_solve.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "problems/lagrangian.hpp"
#include "problems/mass_operator.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace {

// The inexact Newton forcing term of Newton–Krylov: ‖J d − R‖₂ ≤ this·‖R‖₂.
constexpr double kKrylovTolerance = 1e-3;
// Halvings of a Newton–Krylov update before the solve fails ("line_search_failed").
constexpr int kMaxBacktracks = 10;

double infinity_norm(const Vec& x) { return x.size() == 0 ? 0.0 : x.cwiseAbs().maxCoeff(); }

// One solve's state: the counted residual and preconditioner, and the result being built.
class MatrixFreeRun {
 public:
  MatrixFreeRun(const NewtonSystem& system, const VelocityPreconditioner& precondition,
                NewtonResult& result)
      : system_(system), precondition_(precondition), result_(result) {}

  // ‖R(x)‖₂ into `residual`, +inf when an entry is not finite.
  double evaluate(const Vec& x, Vec& residual) {
    system_.residual(x, residual);
    ++result_.residual_evals;
    return residual.allFinite() ? robust_norm(residual) : std::numeric_limits<double>::infinity();
  }

  void apply_preconditioner(const Vec& v, const Vec& r, Vec& x) {
    precondition_(v, r, x);
    ++result_.linear_solves;
  }

  // The quasi-Newton correction d = P(v)⁻¹R (the next iterate is v − d).
  void quasi_newton_correction(const Vec& v, const Vec& residual, Vec& correction) {
    apply_preconditioner(v, residual, correction);
  }

  // The Newton correction d ≈ J⁻¹R by GMRES on J P⁻¹ y = R (right preconditioning, so the
  // Krylov residual is the true linear residual), J z ≈ (R(v + δz) − R(v))/δ; stops at
  // ‖J d − R‖₂ ≤ kKrylovTolerance·‖R‖₂, kMaxKrylovVectors products, or an invariant subspace.
  void newton_krylov_correction(const Vec& v, const Vec& residual, Vec& correction) {
    const double beta = residual.norm();
    std::vector<Vec> basis{residual / beta};
    std::vector<Vec> preconditioned;
    Eigen::MatrixXd hessenberg = Eigen::MatrixXd::Zero(kMaxKrylovVectors + 1, kMaxKrylovVectors);
    Vec rhs = Vec::Zero(kMaxKrylovVectors + 1);
    rhs[0] = beta;
    std::vector<double> cosines, sines;
    Vec shifted_residual, z;
    int size = 0;
    for (int j = 0; j < kMaxKrylovVectors; ++j) {
      apply_preconditioner(v, basis[j], z);
      preconditioned.push_back(z);
      const double delta = std::sqrt(std::numeric_limits<double>::epsilon()) *
                           (1 + infinity_norm(v)) /
                           std::max(infinity_norm(z), std::numeric_limits<double>::min());
      evaluate(v + delta * z, shifted_residual);
      Vec w = (shifted_residual - residual) / delta;
      for (int i = 0; i <= j; ++i) {  // modified Gram–Schmidt
        hessenberg(i, j) = basis[i].dot(w);
        w -= hessenberg(i, j) * basis[i];
      }
      const double next = w.norm();
      hessenberg(j + 1, j) = next;
      for (int i = 0; i < j; ++i) {  // the earlier Givens rotations
        const double a = hessenberg(i, j), b = hessenberg(i + 1, j);
        hessenberg(i, j) = cosines[i] * a + sines[i] * b;
        hessenberg(i + 1, j) = -sines[i] * a + cosines[i] * b;
      }
      const double r = std::hypot(hessenberg(j, j), hessenberg(j + 1, j));
      cosines.push_back(r > 0 ? hessenberg(j, j) / r : 1);
      sines.push_back(r > 0 ? hessenberg(j + 1, j) / r : 0);
      hessenberg(j, j) = r;
      hessenberg(j + 1, j) = 0;
      rhs[j + 1] = -sines[j] * rhs[j];
      rhs[j] *= cosines[j];
      size = j + 1;
      if (std::abs(rhs[j + 1]) <= kKrylovTolerance * beta || !(next > 0)) break;
      basis.push_back(w / next);
    }
    const Vec y =
        hessenberg.topLeftCorner(size, size).triangularView<Eigen::Upper>().solve(rhs.head(size));
    correction = Vec::Zero(v.size());
    for (int i = 0; i < size; ++i) correction += y[i] * preconditioned[i];
  }

 private:
  const NewtonSystem& system_;
  const VelocityPreconditioner& precondition_;
  NewtonResult& result_;
};

}  // namespace

VelocitySolve read_velocity_solve_option(Params& params) {
  const std::string solve = params.choice(
      "solve", "auto", {"auto", "dense", "matrix_free", "newton_krylov"},
      "velocity equation solver on unconstrained problems: matrix_free (quasi-Newton on the O(n) "
      "mass-plus-stiffness solve) where the mass is recursive, dense Newton elsewhere (auto); "
      "dense; matrix_free; newton_krylov (GMRES, same preconditioner)");
  params.omit_default_from_canonical("solve");
  if (solve == "dense") return VelocitySolve::kDense;
  if (solve == "matrix_free") return VelocitySolve::kMatrixFree;
  if (solve == "newton_krylov") return VelocitySolve::kNewtonKrylov;
  return VelocitySolve::kAuto;
}

VelocitySolve resolve_velocity_solve(VelocitySolve choice, const Problem& problem) {
  if (problem.has(kConstraints)) return VelocitySolve::kDense;
  if (choice != VelocitySolve::kAuto) return choice;
  const LagrangianSystem* system = problem.as_lagrangian();
  return system != nullptr && system->mass_is_recursive() ? VelocitySolve::kMatrixFree
                                                          : VelocitySolve::kDense;
}

VelocityPreconditioner velocity_equation_preconditioner(const Problem& problem, const Vec& q0,
                                                        double h, double alpha) {
  const LagrangianSystem* system = problem.as_lagrangian();
  const double stiffness_weight = h * h * alpha * (1 - alpha);
  if (system != nullptr) {
    return [system, q0, h, alpha, stiffness_weight](const Vec& v, const Vec& r, Vec& x) {
      system->solve_mass_with_stiffness(q0 + (alpha * h) * v, stiffness_weight, r, x);
    };
  }
  const MassOperator mass(problem);
  const Vec inverse_diagonal = mass.constant_inverse_diagonal();
  return [inverse_diagonal](const Vec&, const Vec& r, Vec& x) {
    x = inverse_diagonal.cwiseProduct(r);
  };
}

NewtonResult matrix_free_velocity_solve(const NewtonSystem& system,
                                        const VelocityPreconditioner& precondition, Vec& v,
                                        double residual_scale, const NewtonOptions& options,
                                        bool newton_krylov) {
  NewtonResult result;
  MatrixFreeRun run(system, precondition, result);
  Vec residual, correction, trial, trial_residual;
  double norm = run.evaluate(v, residual);
  double scale = residual_scale;
  if (system.scale_after_first_residual) scale += system.scale_after_first_residual();
  result.threshold =
      std::max(std::max(options.tolerance, kRoundoffFloor) * scale, kSubnormalResidual);
  const double floor = std::max(kRoundoffFloor * scale, kSubnormalResidual);
  const auto record = [&] {
    result.residual_norm = norm;
    if (options.record_history) result.residual_history.push_back(norm);
  };
  bool krylov = newton_krylov;
  const auto correct = [&](const Vec& at, const Vec& r, Vec& d) {
    if (krylov) {
      run.newton_krylov_correction(at, r, d);
    } else {
      run.quasi_newton_correction(at, r, d);
    }
    ++result.iterations;
  };
  record();
  while (true) {
    if (!std::isfinite(norm)) {
      result.reason = "nan";
      return result;
    }
    if (norm <= result.threshold) break;
    if (result.iterations >= options.max_iterations) {
      result.reason = "newton_max_iter";
      return result;
    }
    const bool krylov_update = krylov;
    correct(v, residual, correction);
    trial = v - correction;
    double trial_norm = run.evaluate(trial, trial_residual);
    // A Newton–Krylov direction descends ½‖R‖²: Armijo backtracking on ‖R‖ (Nocedal & Wright
    // §3.1, as NewtonSolver's line search) where the full update does not lower it enough.
    double length = 1;
    for (int halvings = 0; krylov_update && !(trial_norm <= (1 - options.armijo * length) * norm) &&
                           halvings < kMaxBacktracks;
         ++halvings) {
      length /= 2;
      correction /= 2;
      trial = v - correction;
      trial_norm = run.evaluate(trial, trial_residual);
    }
    if (krylov_update && !(trial_norm < norm)) {
      result.reason = "line_search_failed";
      return result;
    }
    // The quasi-Newton rate is ‖P⁻¹(J − P)‖, the velocity terms P leaves out: where they are
    // large (a long chain's free end whipping at h = 0.01) it nears 1 or more, and Newton–Krylov
    // on the same preconditioner takes over for the rest of the solve, from the better iterate.
    if (!krylov && !(trial_norm <= kQuasiNewtonContraction * norm)) {
      krylov = true;
      if (!(trial_norm < norm)) continue;
    }
    v.swap(trial);
    residual.swap(trial_residual);
    norm = trial_norm;
    record();
    if (std::isfinite(norm) && robust_norm(correction) <= kRoundoffFloor * robust_norm(v)) {
      result.at_roundoff = true;
      break;
    }
  }
  result.converged = true;
  // Polish towards the round-off floor, keeping each correction only while it lowers ‖R‖.
  while (options.polish && result.iterations > 0 && norm > floor &&
         result.iterations < options.max_iterations) {
    correct(v, residual, correction);
    trial = v - correction;
    const double trial_norm = run.evaluate(trial, trial_residual);
    if (!(trial_norm < norm)) break;
    v.swap(trial);
    residual.swap(trial_residual);
    norm = trial_norm;
    result.polished = true;
    record();
  }
  return result;
}

}  // namespace geomint
