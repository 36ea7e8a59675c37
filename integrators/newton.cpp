// Damped sparse Newton solver (see newton.hpp); line search after Nocedal & Wright, "Numerical
// Optimization", 2nd ed., Algorithm 3.1 (backtracking Armijo) and §11.1 (merit ½‖R‖²).
#include "integrators/newton.hpp"

#include <fmt/format.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace geomint {

struct NewtonSolver::Factorisation {
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  Eigen::SparseLU<SparseMatrix> lu;
  SparseMatrix jacobian;
  // Pattern of the matrix last passed to analyzePattern, and which factorisation it was for.
  bool has_pattern = false;
  bool pattern_symmetric = false;
  Eigen::Index rows = 0;
  std::vector<SparseMatrix::StorageIndex> outer;
  std::vector<SparseMatrix::StorageIndex> inner;

  bool same_pattern(const SparseMatrix& J, bool symmetric) const {
    if (!has_pattern || symmetric != pattern_symmetric || J.rows() != rows) return false;
    const auto* J_outer = J.outerIndexPtr();
    const auto* J_inner = J.innerIndexPtr();
    return std::equal(outer.begin(), outer.end(), J_outer, J_outer + J.outerSize() + 1) &&
           std::equal(inner.begin(), inner.end(), J_inner, J_inner + J.nonZeros());
  }

  void remember_pattern(const SparseMatrix& J, bool symmetric) {
    has_pattern = true;
    pattern_symmetric = symmetric;
    rows = J.rows();
    outer.assign(J.outerIndexPtr(), J.outerIndexPtr() + J.outerSize() + 1);
    inner.assign(J.innerIndexPtr(), J.innerIndexPtr() + J.nonZeros());
  }

  // Factorises `jacobian`; false when the factorisation hit a zero pivot.
  bool factorise(bool symmetric, bool reuse_symbolic, int& analyses) {
    jacobian.makeCompressed();
    const bool analyse = !reuse_symbolic || !same_pattern(jacobian, symmetric);
    if (symmetric) {
      if (analyse) ldlt.analyzePattern(jacobian);
      ldlt.factorize(jacobian);
      if (analyse) {
        ++analyses;
        remember_pattern(jacobian, symmetric);
      }
      return ldlt.info() == Eigen::Success;
    }
    if (analyse) lu.analyzePattern(jacobian);
    lu.factorize(jacobian);
    if (analyse) {
      ++analyses;
      remember_pattern(jacobian, symmetric);
    }
    return lu.info() == Eigen::Success;
  }

  // Every pivot of the last LDLT factorisation is positive: the matrix is positive definite.
  bool positive_pivots() const { return (ldlt.vectorD().array() > 0.0).all(); }

  void solve(bool symmetric, const Vec& rhs, Vec& out) {
    out = symmetric ? Vec(ldlt.solve(rhs)) : Vec(lu.solve(rhs));
  }
};

NewtonOptions read_newton_options(Params& params, const std::string& residual_scale) {
  NewtonOptions options;
  options.tolerance = params.real(
      "tol", options.tolerance,
      fmt::format("Newton relative residual tolerance (scale {})", residual_scale),
      [](double x) { return x > 0.0 && x < 1.0; }, "in (0, 1)");
  options.max_iterations = static_cast<int>(
      params.integer("max_iter", options.max_iterations,
                     "Newton iterations per step before the step fails", 1, 10000));
  return options;
}

NewtonSolver::NewtonSolver(NewtonOptions options)
    : options_(options), factorisation_(std::make_unique<Factorisation>()) {}
NewtonSolver::~NewtonSolver() = default;
NewtonSolver::NewtonSolver(NewtonSolver&&) noexcept = default;
NewtonSolver& NewtonSolver::operator=(NewtonSolver&&) noexcept = default;

void NewtonSolver::forget_pattern() { factorisation_->has_pattern = false; }

namespace {

bool all_finite(const Vec& v) { return v.allFinite(); }

bool all_finite(const SparseMatrix& J) {
  const double* values = J.valuePtr();
  return std::all_of(values, values + J.nonZeros(), [](double a) { return std::isfinite(a); });
}

}  // namespace

double central_difference_step(const Vec& x, Eigen::Index j) {
  const double relative_step = std::cbrt(std::numeric_limits<double>::epsilon());
  const double size = std::max(std::abs(x[j]), x.size() ? x.cwiseAbs().maxCoeff() : 0.0);
  return relative_step * (size > 0.0 && std::isfinite(size) ? size : 1.0);
}

SparseMatrix central_difference_jacobian(const std::function<void(const Vec& x, Vec& f)>& f,
                                         const Vec& x) {
  const Eigen::Index n = x.size();
  std::vector<Eigen::Triplet<double>> triplets;
  Vec shifted = x, plus, minus;
  Eigen::Index rows = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    const double delta = central_difference_step(x, j);
    shifted[j] = x[j] + delta;
    f(shifted, plus);
    shifted[j] = x[j] - delta;
    f(shifted, minus);
    shifted[j] = x[j];
    rows = plus.size();
    for (Eigen::Index i = 0; i < rows; ++i) {
      const double derivative = (plus[i] - minus[i]) / (2 * delta);
      if (derivative != 0.0) triplets.emplace_back(i, j, derivative);
    }
  }
  SparseMatrix out(n == 0 ? 0 : rows, n);
  out.setFromTriplets(triplets.begin(), triplets.end());
  return out;
}

double gradient_term_scale(const SparseMatrix& H, const Vec& q) {
  Vec terms = Vec::Zero(H.rows());
  for (int k = 0; k < H.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(H, k); it; ++it) {
      terms[it.row()] += std::abs(it.value()) * std::abs(q[it.col()]);
    }
  }
  return terms.norm();
}

std::string describe(const NewtonResult& result) {
  if (result.converged && result.at_roundoff) {
    return fmt::format(
        "Newton converged at round-off in {} iterations: correction below {:.2g}*|x|, residual "
        "{:.3g} (tolerance {:.3g})",
        result.iterations, kRoundoffFloor, result.residual_norm, result.threshold);
  }
  if (result.converged) {
    return fmt::format("Newton converged in {} iterations: residual {:.3g} <= {:.3g}",
                       result.iterations, result.residual_norm, result.threshold);
  }
  return fmt::format("Newton stopped after {} iterations: residual {:.3g} > {:.3g} ({})",
                     result.iterations, result.residual_norm, result.threshold, result.reason);
}

NewtonResult NewtonSolver::solve(const NewtonSystem& system, Vec& x, double residual_scale) {
  NewtonResult result;
  const double relative_tolerance = std::max(options_.tolerance, kRoundoffFloor);
  result.threshold = relative_tolerance * residual_scale;
  double scale = residual_scale;
  Factorisation& f = *factorisation_;

  Vec residual;
  auto evaluate = [&](const Vec& at, Vec& r) {
    ++result.residual_evals;
    system.residual(at, r);
    if (r.size() != at.size()) {
      throw std::logic_error(
          fmt::format("Newton residual has size {} for {} unknowns", r.size(), at.size()));
    }
  };
  // Merit of a finite residual: the objective when the system has one, else ½‖R‖².
  auto merit_of = [&](const Vec& at, const Vec& r) {
    return system.objective ? system.objective(at) : 0.5 * r.squaredNorm();
  };
  auto fail = [&](const char* reason) {
    result.reason = reason;
    return result;
  };

  evaluate(x, residual);
  if (system.scale_after_first_residual) {
    scale = residual_scale + system.scale_after_first_residual();
    result.threshold = relative_tolerance * scale;
  }
  result.residual_norm = residual.norm();
  if (options_.record_history) result.residual_history.push_back(result.residual_norm);
  if (!all_finite(residual)) return fail("nan");
  double merit = merit_of(x, residual);
  if (!std::isfinite(merit)) return fail("nan");

  const bool safeguard = system.symmetric && system.objective && system.spd_shift.size() > 0;
  if (safeguard && (system.spd_shift.rows() != x.size() || system.spd_shift.cols() != x.size())) {
    throw std::logic_error(fmt::format("Newton SPD shift is {}x{} for {} unknowns",
                                       system.spd_shift.rows(), system.spd_shift.cols(), x.size()));
  }

  Vec direction, trial, trial_residual;
  while (true) {
    if (result.residual_norm <= result.threshold) {
      result.converged = true;
      if (options_.polish && result.iterations > 0) {
        f.solve(system.symmetric, -residual, direction);
        if (all_finite(direction)) {
          trial = x + direction;
          evaluate(trial, trial_residual);
          const double polished_norm = trial_residual.norm();
          if (all_finite(trial_residual) && polished_norm < result.residual_norm) {
            x.swap(trial);
            result.residual_norm = polished_norm;
            result.polished = true;
            if (options_.record_history) result.residual_history.push_back(polished_norm);
          }
        }
      }
      return result;
    }
    if (result.iterations >= options_.max_iterations) return fail("newton_max_iter");

    system.jacobian(x, f.jacobian);
    if (f.jacobian.rows() != x.size() || f.jacobian.cols() != x.size()) {
      throw std::logic_error(fmt::format("Newton Jacobian is {}x{} for {} unknowns",
                                         f.jacobian.rows(), f.jacobian.cols(), x.size()));
    }
    if (!all_finite(f.jacobian)) return fail("nan");
    if (system.inner_term_scale) {
      const double inner = system.inner_term_scale();
      if (std::isfinite(inner)) {
        result.threshold = std::max(relative_tolerance * scale, kRoundoffFloor * (scale + inner));
      }
    }
    ++result.linear_solves;
    const bool factorised =
        f.factorise(system.symmetric, options_.reuse_symbolic, result.symbolic_analyses);
    if (safeguard && !(factorised && f.positive_pivots())) {
      // J is not positive definite (or singular): shift it towards S until it is. J + μS has the
      // pattern of J when S's pattern is contained in it (M diagonal, J with a full diagonal), so
      // the symbolic factorisation is reused.
      ++result.shifted_iterations;
      const SparseMatrix unshifted = f.jacobian;
      // Start one growth step below the last successful shift of this solve: consecutive
      // iterates usually need a similar μ, and the schedule then costs one or two factorisations.
      double mu =
          std::max(options_.spd_shift_initial, result.last_shift / options_.spd_shift_growth);
      bool positive = false;
      for (int attempt = 0; attempt < options_.max_spd_shifts && !positive;
           ++attempt, mu *= options_.spd_shift_growth) {
        f.jacobian = unshifted + mu * system.spd_shift;
        ++result.shift_factorisations;
        positive = f.factorise(true, options_.reuse_symbolic, result.symbolic_analyses) &&
                   f.positive_pivots();
        if (positive) result.last_shift = mu;
      }
      if (!positive) return fail("linear_solve_failed");
    } else if (!factorised) {
      return fail("linear_solve_failed");
    }
    f.solve(system.symmetric, -residual, direction);
    // A nearly singular matrix factorises without a zero pivot but yields inf/NaN here.
    if (!all_finite(direction)) return fail("linear_solve_failed");
    ++result.iterations;

    // Round-off floor in x: a correction below kRoundoffFloor·‖x‖ changes x by no more than its
    // own rounding, so the residual left is the rounding of R's terms — which can exceed
    // tolerance·residual_scale when a term's inner magnitude (h·K·q of a stiff spring whose
    // elongation is small) is far above its value. Take the correction and stop.
    if (direction.norm() <= kRoundoffFloor * x.norm()) {
      trial = x + direction;
      evaluate(trial, trial_residual);
      if (all_finite(trial_residual)) {
        x.swap(trial);
        residual.swap(trial_residual);
        result.residual_norm = residual.norm();
        if (options_.record_history) result.residual_history.push_back(result.residual_norm);
        result.converged = true;
        result.at_roundoff = true;
        return result;
      }
    }

    // Directional derivative of the merit along the step. For ½‖R‖² it is Rᵀ J d = −‖R‖² for
    // the exact Newton step, whatever J is, so the step is always a descent direction.
    const double slope = system.objective ? residual.dot(direction) : -residual.squaredNorm();
    if (system.objective && options_.line_search && !(slope < 0.0)) return fail("not_descent");

    double step = 1.0;
    bool accepted = false;
    bool any_finite = false;
    double trial_merit = 0.0;
    for (int backtrack = 0; backtrack <= options_.max_backtracks; ++backtrack, step *= 0.5) {
      trial = x + step * direction;
      if (trial == x) break;  // the step is below x's resolution: no progress is possible
      evaluate(trial, trial_residual);
      if (!all_finite(trial_residual)) {
        if (!options_.line_search) break;
        continue;  // the step left the domain of R (e.g. an inverted element): shorten it
      }
      trial_merit = merit_of(trial, trial_residual);
      if (!std::isfinite(trial_merit)) {
        if (!options_.line_search) break;
        continue;
      }
      any_finite = true;
      if (!options_.line_search || trial_merit <= merit + options_.armijo * step * slope) {
        accepted = true;
        break;
      }
      // Close to the root an objective's decrease (~‖R‖²) drops below its round-off
      // (~ε|E|) long before ‖R‖ reaches the tolerance; the residual still measures progress.
      const double merit_size = std::max(std::abs(merit), system.objective_scale);
      if (system.objective && trial_residual.norm() < result.residual_norm &&
          trial_merit <= merit + 16 * std::numeric_limits<double>::epsilon() * merit_size) {
        accepted = true;
        break;
      }
    }
    if (!accepted) return fail(any_finite ? "line_search_failed" : "nan");

    x.swap(trial);
    residual.swap(trial_residual);
    merit = trial_merit;
    result.residual_norm = residual.norm();
    if (options_.record_history) result.residual_history.push_back(result.residual_norm);
  }
}

}  // namespace geomint
