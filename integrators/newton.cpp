// Damped sparse Newton solver (see newton.hpp); line search after Nocedal & Wright, "Numerical
// Optimization", 2nd ed., Algorithm 3.1 (backtracking Armijo) and §11.1 (merit ½‖R‖²).
// Layout: LinearFactorisation (the factorisations of every linear_solver kind, kept across
// solves), then NewtonRun (one solve's phases, each with its contract) and NewtonSolver::solve,
// the loop over them. The dense loop of the general-Lagrangian steps is integrators/dense_newton.
#include "integrators/newton.hpp"

#include <fmt/format.h>

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
// clang-format off
#include <iostream>  // before MetisSupport, which uses std::cerr without including it
#include <Eigen/MetisSupport>
// clang-format on
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "integrators/boomer_amg.hpp"
#include "integrators/conjugate_gradient.hpp"
#include "integrators/newton_profile.hpp"
#include "problems/parallel.hpp"
#include "problems/spec.hpp"

namespace geomint {

namespace {

using MetisLdlt = Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::MetisOrdering<int>>;

// Wall-clock seconds of a phase of the solve, added to a NewtonProfile total when it ends.
class PhaseTimer {
 public:
  explicit PhaseTimer(std::atomic<long>& nanoseconds)
      : total_(nanoseconds), start_(std::chrono::steady_clock::now()) {}
  ~PhaseTimer() {
    total_.fetch_add(std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::steady_clock::now() - start_)
                         .count(),
                     std::memory_order_relaxed);
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  std::atomic<long>& total_;
  std::chrono::steady_clock::time_point start_;
};

struct ProfileTotals {
  std::atomic<long> solves{0}, iterations{0}, cg_iterations{0}, jacobians{0}, residuals{0},
      objectives{0}, linear_solves{0};
  std::atomic<long> total_ns{0}, jacobian_ns{0}, residual_ns{0}, objective_ns{0}, setup_ns{0},
      linear_ns{0};
};

ProfileTotals& profile_totals() {
  static ProfileTotals totals;
  return totals;
}

}  // namespace

// Forcing terms of the inexact Newton iteration with CG (Eisenstat & Walker, "Choosing the
// forcing terms in an inexact Newton method", SIAM J. Sci. Comput. 17(1), 1996, choice 1):
// iteration k's CG stops at ‖J d + R_k‖ ≤ max(0.1·threshold, η_k‖R_k‖). η₀ = kFirstForcing (the
// constant forcing used before, measured on the elastic bar: docs/PERF.md "Implicit step"); then
// η_k = |‖R_k‖ − ‖R_{k−1} + J_{k−1}s_{k−1}‖| / ‖R_{k−1}‖, the miss of the last step's linear model,
// at least η_{k−1}^((1+√5)/2) when that exceeds 0.1 (their safeguard against a sudden tightening),
// at most kMaxForcing. A nearly linear step (small miss) gets a tight solve and ends in fewer
// Newton iterations; a strongly nonlinear one (large miss) a loose one, saving CG iterations that
// Newton would discard. The Newton stopping test is unchanged.
constexpr double kFirstForcing = 1e-3;
constexpr double kMaxForcing = 0.1;
constexpr double kForcingSafeguardExponent = 1.618033988749895;

// `auto` is kCg at every size from kAutoIterativeFrom on. kCgAmg was picked from 200 000 unknowns
// on the strength of loaded CPU times (11.4 s cg against 9.92 s cg_amg per step at 544 320
// unknowns); on the quiet machine (load 1.3, docs/PERF.md "Implicit step") cg took 5.06 s and
// cg_amg 5.31 s per step at that size, 463 against 482 ms at 56 355 unknowns: no size measured
// favours cg_amg, whose set-up also costs 0.4 GB more memory at 10⁶ tetrahedra. `auto` leaves
// modified Newton off: with CG it is the faster elastic-bar step (docs/PERF.md "Hessian reuse"),
// but it moves every committed `cg` trajectory within the Newton tolerance, so it stays opt-in.
LinearSolverKind resolve_linear_solver(LinearSolverKind kind, long unknowns) {
  if (kind != LinearSolverKind::kAuto) return kind;
  return unknowns < kAutoIterativeFrom ? LinearSolverKind::kLdlt : LinearSolverKind::kCg;
}

const char* linear_solver_name(LinearSolverKind kind) {
  switch (kind) {
    case LinearSolverKind::kAuto:
      return "auto";
    case LinearSolverKind::kLdlt:
      return "ldlt";
    case LinearSolverKind::kLdltMetis:
      return "ldlt_metis";
    case LinearSolverKind::kCholmod:
      return "cholmod";
    case LinearSolverKind::kCg:
      return "cg";
    case LinearSolverKind::kCgIchol:
      return "cg_ichol";
    case LinearSolverKind::kCgAmg:
      return "cg_amg";
  }
  return "auto";
}

LinearSolverOptions read_linear_solver_option(Params& params) {
  static const LinearSolverKind kinds[] = {LinearSolverKind::kAuto,      LinearSolverKind::kLdlt,
                                           LinearSolverKind::kLdltMetis, LinearSolverKind::kCholmod,
                                           LinearSolverKind::kCg,        LinearSolverKind::kCgIchol,
                                           LinearSolverKind::kCgAmg};
  std::vector<std::string> names;
  for (LinearSolverKind kind : kinds) names.push_back(linear_solver_name(kind));
  LinearSolverOptions options;
  const std::string name = params.choice(
      "linear_solver", "auto", names,
      fmt::format("solver of the symmetric Newton systems (auto: ldlt below {} unknowns, "
                  "else cg)",
                  kAutoIterativeFrom));
  for (LinearSolverKind kind : kinds) {
    if (name == linear_solver_name(kind)) options.kind = kind;
  }
  options.modified_newton = params.flag(
      "modified_newton", false,
      "keep one factorisation across Newton iterations and steps while the residual contracts "
      "fast");
  params.omit_default_from_canonical("linear_solver");
  params.omit_default_from_canonical("modified_newton");
  return options;
}

namespace {

// The linear algebra of a NewtonSolver, kept across solves (NewtonSolver::Factorisation is this;
// NewtonRun below works on it): one factorisation (or CG preconditioner) of the Newton matrix
// for each LinearSolverKind, its pattern for symbolic reuse, and the AMG refresh state.
struct LinearFactorisation {
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  MetisLdlt ldlt_metis;
  Eigen::CholmodSupernodalLLT<SparseMatrix> cholmod;
  JacobiPreconditioner jacobi;
  Eigen::IncompleteCholesky<double, Eigen::Lower> ichol;
  Eigen::SparseLU<SparseMatrix> lu;
  BoomerAmg amg;
  // CG iterations per decade of residual reduction in the first solve after the last AMG set-up
  // (−1: none yet), and whether the next factorise() must rebuild it
  // (LinearSolverOptions::amg_refresh_growth). Per decade, because the forcing terms ask the
  // solves of one Newton iteration for a few decades and of another for many.
  double amg_baseline_iterations = -1;
  bool amg_refresh = false;
  double amg_refresh_growth = 2.0;
  // Counters of the solve in progress (set by NewtonRun::start).
  int* factorizations_counter = nullptr;
  int* amg_setups_counter = nullptr;
  int* cg_iterations_counter = nullptr;
  SparseMatrix jacobian;
  LinearSolverKind kind = LinearSolverKind::kLdlt;  // resolved for the current system
  // The factorisation held is of this matrix, which factorise() was given (`jacobian`: it is
  // not changed before the next factorise()), so CG iterates on it without a copy.
  const SparseMatrix* factored = nullptr;
  // CG multiplies by the matrix in full (both triangles): `factored` itself when it stores them
  // (every Newton matrix of geomint does), else its lower triangle mirrored into full_matrix.
  const SparseMatrix* cg_matrix = nullptr;
  SparseMatrix full_matrix;
  SymmetricBlockMatrix cg_blocks;  // *cg_matrix in 3×3 blocks, when cg_blocked
  bool cg_blocked = false;
  bool pattern_in_full = true;   // the remembered pattern has both triangles
  bool has_factor = false;       // a usable factorisation of the current system's size is held
  bool direct_fallback = false;  // CG/CHOLMOD found J indefinite: this factor is an LDLT of it
  // Modified Newton: the last solve ended contracting fast, so its factorisation may start the
  // next one.
  bool keep_factor = false;
  // NewtonSystem::inner_term_scale at the iterate of the held Jacobian (modified Newton).
  double held_inner_term_scale = 0.0;
  // Set by the caller before solve(): the residual the CG iteration must reach; set by solve():
  // the residual ‖rhs − A·out‖ it reached (CG only).
  double cg_target = 0.0;
  double cg_residual = 0.0;
  // Pattern of the matrix last passed to analyzePattern, and which factorisation it was for.
  bool has_pattern = false;
  bool pattern_symmetric = false;
  LinearSolverKind pattern_kind = LinearSolverKind::kLdlt;
  Eigen::Index rows = 0;
  std::vector<SparseMatrix::StorageIndex> outer;
  std::vector<SparseMatrix::StorageIndex> inner;

  LinearFactorisation() {
    // METIS nested dissection only (CHOLMOD's default also tries AMD and keeps the sparser
    // factor: on a 3-D mesh METIS wins and the extra analysis is wasted); no messages on stderr —
    // a non-positive-definite matrix is an expected outcome here (the SPD safeguard).
    cholmod_common& common = cholmod.cholmod();
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_METIS;
    common.postorder = 1;
    common.print = 0;
  }

  bool same_pattern(const SparseMatrix& J, bool symmetric) const {
    if (!has_pattern || symmetric != pattern_symmetric || J.rows() != rows) return false;
    if (symmetric && kind != pattern_kind) return false;
    const auto* J_outer = J.outerIndexPtr();
    const auto* J_inner = J.innerIndexPtr();
    return std::equal(outer.begin(), outer.end(), J_outer, J_outer + J.outerSize() + 1) &&
           std::equal(inner.begin(), inner.end(), J_inner, J_inner + J.nonZeros());
  }

  void remember_pattern(const SparseMatrix& J, bool symmetric) {
    has_pattern = true;
    pattern_symmetric = symmetric;
    pattern_kind = kind;
    rows = J.rows();
    outer.assign(J.outerIndexPtr(), J.outerIndexPtr() + J.outerSize() + 1);
    inner.assign(J.innerIndexPtr(), J.innerIndexPtr() + J.nonZeros());
    long above = 0, below = 0;
    for (int k = 0; k < J.outerSize(); ++k) {
      for (SparseMatrix::InnerIterator it(J, k); it; ++it) {
        above += it.row() < it.col();
        below += it.row() > it.col();
      }
    }
    pattern_in_full = above == below;
  }

  template <class Solver>
  bool analyse_and_factorise(Solver& solver, const SparseMatrix& A, bool analyse) {
    if (analyse) solver.analyzePattern(A);
    solver.factorize(A);
    return solver.info() == Eigen::Success;
  }

  // Factorises `matrix` (J or a shifted J) with the solver `kind` (symmetric) or SparseLU; false
  // when it hit a zero pivot (LDLT, LU) or, for the SPD-only solvers, found the matrix not
  // positive definite — which the caller then handles (SPD shift, or an LDLT fallback).
  bool factorise(const SparseMatrix& matrix, bool symmetric, bool reuse_symbolic, int& analyses,
                 int& factorizations) {
    const PhaseTimer timer(profile_totals().setup_ns);
    has_factor = false;
    direct_fallback = false;
    const bool analyse = !reuse_symbolic || !same_pattern(matrix, symmetric);
    if (analyse) {
      ++analyses;
      remember_pattern(matrix, symmetric);
    }
    // A reused AMG set-up is no new preconditioner: setup_amg() counts the set-ups.
    if (!symmetric || kind != LinearSolverKind::kCgAmg) ++factorizations;
    bool ok = false;
    if (!symmetric) {
      ok = analyse_and_factorise(lu, matrix, analyse);
    } else {
      switch (kind) {
        case LinearSolverKind::kLdlt:
          ok = analyse_and_factorise(ldlt, matrix, analyse);
          break;
        case LinearSolverKind::kLdltMetis:
          ok = analyse_and_factorise(ldlt_metis, matrix, analyse);
          break;
        case LinearSolverKind::kCholmod:
          ok = analyse_and_factorise(cholmod, matrix, analyse);
          break;
        case LinearSolverKind::kCg:
          jacobi.compute(matrix);
          ok = true;
          break;
        case LinearSolverKind::kCgIchol:
          ok = analyse_and_factorise(ichol, matrix, analyse);
          break;
        case LinearSolverKind::kCgAmg:
          ok = (amg.ready() && amg.rows() == matrix.rows() && !amg_refresh &&
                amg_refresh_growth > 0) ||
               setup_amg(matrix);
          break;
        case LinearSolverKind::kAuto:
          break;  // resolved before
      }
      factored = &matrix;
      cg_matrix = &matrix;
      if (is_cg() && !pattern_in_full) {
        full_matrix = matrix.selfadjointView<Eigen::Lower>();
        cg_matrix = &full_matrix;
      }
      // The CG product reads the 3×3-block copy when the matrix is made of such blocks (three
      // coordinates per node): a third less memory traffic per product, same bits.
      cg_blocked = ok && is_cg() && to_symmetric_blocks(*cg_matrix, cg_blocks);
    }
    has_factor = ok;
    return ok;
  }

  // LDLT (AMD) of the last matrix for a solver that needs positive definiteness when the matrix is
  // not, and the system has no SPD safeguard: the plain Newton step, as before the choice existed.
  bool factorise_indefinite(int& factorizations) {
    ++factorizations;
    ldlt.compute(*factored);
    has_factor = ldlt.info() == Eigen::Success;
    direct_fallback = has_factor;
    return has_factor;
  }

  bool setup_amg(const SparseMatrix& matrix) {
    ++*factorizations_counter;
    ++*amg_setups_counter;
    amg_baseline_iterations = -1;
    amg_refresh = false;
    return amg.setup(matrix);
  }

  // y = A x for the CG iteration, from the block copy when there is one.
  auto cg_product() const {
    return [this](const Vec& p, Vec& Ap) {
      if (cg_blocked) {
        symmetric_product(cg_blocks, p, Ap);
      } else {
        symmetric_product(*cg_matrix, p, Ap);
      }
    };
  }

  bool is_cg() const {
    return !direct_fallback &&
           (kind == LinearSolverKind::kCg || kind == LinearSolverKind::kCgIchol ||
            kind == LinearSolverKind::kCgAmg);
  }

  // CG preconditioned by the held AMG set-up; an old set-up that fails (a matrix that moved too
  // far from it) is rebuilt from the current matrix and the solve repeated once. Tracks the
  // refresh rule of LinearSolverOptions::amg_refresh_growth, in CG iterations per decade of
  // residual reduction (at least one decade counted per solve).
  CgOutcome amg_cg(const Vec& rhs, int max_cg, Vec& out) {
    int iterations = 0;
    const bool fresh = amg_baseline_iterations < 0;
    CgOutcome outcome =
        preconditioned_cg(cg_product(), amg, rhs, cg_target, max_cg, out, iterations, cg_residual);
    *cg_iterations_counter += iterations;
    if (outcome == CgOutcome::kNoConvergence && !fresh) {
      if (!setup_amg(*factored)) return outcome;
      outcome = preconditioned_cg(cg_product(), amg, rhs, cg_target, max_cg, out, iterations,
                                  cg_residual);
      *cg_iterations_counter += iterations;
    }
    if (outcome != CgOutcome::kConverged) return outcome;
    const double decades =
        cg_residual > 0.0 ? std::max(1.0, std::log10(cg_residual_norm(rhs) / cg_residual)) : 1.0;
    if (amg_baseline_iterations < 0) {
      amg_baseline_iterations = iterations / decades;
    } else if (iterations >
               amg_refresh_growth * amg_baseline_iterations * decades + kAmgRefreshSlack) {
      amg_refresh = true;
    }
    return outcome;
  }

  // The held factorisation is of a positive definite matrix. LDLT: every pivot of D positive
  // (Sylvester's law of inertia); CHOLMOD LLᵀ and CG succeed only then (CG's curvature test is
  // applied in solve()).
  bool positive_definite() const {
    if (!has_factor) return false;
    if (direct_fallback) return (ldlt.vectorD().array() > 0.0).all();
    switch (kind) {
      case LinearSolverKind::kLdlt:
        return (ldlt.vectorD().array() > 0.0).all();
      case LinearSolverKind::kLdltMetis:
        return (ldlt_metis.vectorD().array() > 0.0).all();
      default:
        return true;
    }
  }

  // Solves with the held factorisation; false when CG met negative curvature or did not reach
  // cg_target (then `out` is not a usable direction).
  bool solve(bool symmetric, const Vec& rhs, Vec& out, bool& negative_curvature) {
    const PhaseTimer timer(profile_totals().linear_ns);
    profile_totals().linear_solves.fetch_add(1, std::memory_order_relaxed);
    negative_curvature = false;
    if (!symmetric) {
      out = lu.solve(rhs);
      return true;
    }
    if (direct_fallback) {
      out = ldlt.solve(rhs);
      return true;
    }
    const int max_cg = static_cast<int>(std::min<Eigen::Index>(10 * rhs.size() + 100, 100000));
    CgOutcome outcome = CgOutcome::kConverged;
    int iterations = 0;
    switch (kind) {
      case LinearSolverKind::kLdlt:
        out = ldlt.solve(rhs);
        break;
      case LinearSolverKind::kLdltMetis:
        out = ldlt_metis.solve(rhs);
        break;
      case LinearSolverKind::kCholmod:
        out = cholmod.solve(rhs);
        break;
      case LinearSolverKind::kCg:
        outcome =
            jacobi_cg(cg_product(), jacobi, rhs, cg_target, max_cg, out, iterations, cg_residual);
        *cg_iterations_counter += iterations;
        break;
      case LinearSolverKind::kCgIchol:
        outcome = preconditioned_cg(cg_product(), ichol, rhs, cg_target, max_cg, out, iterations,
                                    cg_residual);
        *cg_iterations_counter += iterations;
        break;
      case LinearSolverKind::kCgAmg:
        outcome = amg_cg(rhs, max_cg, out);
        break;
      case LinearSolverKind::kAuto:
        break;
    }
    negative_curvature = outcome == CgOutcome::kNegativeCurvature;
    return outcome == CgOutcome::kConverged;
  }
};

}  // namespace

struct NewtonSolver::Factorisation : LinearFactorisation {};

NewtonOptions read_newton_options(Params& params, const std::string& residual_scale) {
  NewtonOptions options;
  options.tolerance =
      params.real("tol", options.tolerance,
                  fmt::format("Newton relative residual tolerance (scale {})", residual_scale),
                  Range::open(0, 1));
  options.max_iterations = static_cast<int>(
      params.integer("max_iter", options.max_iterations,
                     "Newton iterations per step before the step fails", 1, 10000));
  options.linear = read_linear_solver_option(params);
  return options;
}

NewtonSolver::NewtonSolver(NewtonOptions options)
    : options_(options), factorisation_(std::make_unique<Factorisation>()) {}
NewtonSolver::~NewtonSolver() = default;
NewtonSolver::NewtonSolver(NewtonSolver&&) noexcept = default;
NewtonSolver& NewtonSolver::operator=(NewtonSolver&&) noexcept = default;

void NewtonSolver::forget_pattern() {
  factorisation_->has_pattern = false;
  factorisation_->has_factor = false;
}

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

double power_of_two_unit(double magnitude) {
  if (!(magnitude > 0.0) || !std::isfinite(magnitude)) return 1.0;
  // Clamped so that a subnormal magnitude (exponent down to −1074) still gets a finite unit.
  return std::ldexp(1.0, std::clamp(-std::ilogb(magnitude), -1000, 1000));
}

double robust_norm(const Vec& v) {
  if (v.size() == 0) return 0.0;
  const double largest = v.cwiseAbs().maxCoeff();
  if (!(largest > 0.0) || !std::isfinite(largest)) return v.norm();  // 0, or inf/NaN propagate
  const double unit = power_of_two_unit(largest);
  return (v * unit).norm() / unit;
}

double robust_norm(const Vec& a, const Vec& b) {
  const double largest = std::max(a.size() > 0 ? a.cwiseAbs().maxCoeff() : 0.0,
                                  b.size() > 0 ? b.cwiseAbs().maxCoeff() : 0.0);
  const double unit = std::isfinite(largest) ? power_of_two_unit(largest) : 1.0;
  return std::sqrt((unit * a).squaredNorm() + (unit * b).squaredNorm()) / unit;
}

double gradient_term_scale(const SparseMatrix& H, const Vec& q) {
  Vec terms = Vec::Zero(H.rows());
  for (int k = 0; k < H.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(H, k); it; ++it) {
      terms[it.row()] += std::abs(it.value()) * std::abs(q[it.col()]);
    }
  }
  return robust_norm(terms);
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

namespace {

// Adds a finished solve's totals to the NewtonProfile (declared after the result it reads, so it
// runs before the result is gone on every return path).
class SolveProfile {
 public:
  explicit SolveProfile(const NewtonResult& result)
      : result_(result), timer_(profile_totals().total_ns) {}
  ~SolveProfile() {
    ProfileTotals& totals = profile_totals();
    totals.solves.fetch_add(1, std::memory_order_relaxed);
    totals.iterations.fetch_add(result_.iterations, std::memory_order_relaxed);
    totals.cg_iterations.fetch_add(result_.cg_iterations, std::memory_order_relaxed);
    totals.residuals.fetch_add(result_.residual_evals, std::memory_order_relaxed);
  }
  SolveProfile(const SolveProfile&) = delete;
  SolveProfile& operator=(const SolveProfile&) = delete;

 private:
  const NewtonResult& result_;
  PhaseTimer timer_;
};

}  // namespace

NewtonProfile newton_profile() {
  const ProfileTotals& totals = profile_totals();
  const auto count = [](const std::atomic<long>& value) {
    return value.load(std::memory_order_relaxed);
  };
  const auto seconds = [](const std::atomic<long>& nanoseconds) {
    return 1e-9 * static_cast<double>(nanoseconds.load(std::memory_order_relaxed));
  };
  NewtonProfile profile;
  profile.solves = count(totals.solves);
  profile.iterations = count(totals.iterations);
  profile.cg_iterations = count(totals.cg_iterations);
  profile.residuals = count(totals.residuals);
  profile.objectives = count(totals.objectives);
  profile.jacobians = count(totals.jacobians);
  profile.linear_solves = count(totals.linear_solves);
  profile.total_s = seconds(totals.total_ns);
  profile.residual_s = seconds(totals.residual_ns);
  profile.objective_s = seconds(totals.objective_ns);
  profile.jacobian_s = seconds(totals.jacobian_ns);
  profile.setup_s = seconds(totals.setup_ns);
  profile.linear_s = seconds(totals.linear_ns);
  return profile;
}

namespace {

// One call of NewtonSolver::solve, split into its phases. Each phase updates the shared state
// below and the NewtonResult; NewtonSolver::solve strings them together:
//   start()                              R(x₀), scale, merit, linear solver, reuse of a held factor
//   loop: converged test → polish()      (NewtonOptions::polish)
//         iteration cap   → fail()
//         iterate():  held_direction() or assemble() + newton_direction() [+ shifted_direction()]
//                     roundoff_step()    (converged when the correction is below x's rounding)
//                     descent_check()    (objective form)
//                     line_search() → accept_step()
// The order of every evaluation, comparison and counter update is that of the single loop the
// phases were cut from, so results and work counters are bit for bit those of before.
class NewtonRun {
 public:
  NewtonRun(const NewtonSystem& system, const NewtonOptions& options, LinearFactorisation& f,
            Vec& x, NewtonResult& result, double residual_scale)
      : system_(system),
        options_(options),
        f_(f),
        x_(x),
        result_(result),
        residual_scale_(residual_scale),
        relative_tolerance_(std::max(options.tolerance, kRoundoffFloor)),
        scale_(residual_scale),
        modified_(options.linear.modified_newton) {}

  // Evaluates R(x₀), fixes the stopping threshold (with NewtonSystem::scale_after_first_residual),
  // the merit's unit and value, the linear solver kind, and whether the first direction may come
  // from the factorisation a previous solve left (modified Newton). False (result failed: "nan",
  // "objective_overflow") when x₀ is already unusable; throws on a wrongly sized R or SPD shift.
  bool start() {
    result_.threshold = std::max(relative_tolerance_ * residual_scale_, kSubnormalResidual);
    f_.factorizations_counter = &result_.factorizations;
    f_.amg_setups_counter = &result_.amg_setups;
    f_.cg_iterations_counter = &result_.cg_iterations;
    f_.amg_refresh_growth = options_.linear.amg_refresh_growth;

    evaluate(x_, residual_);
    if (system_.scale_after_first_residual) {
      scale_ = residual_scale_ + system_.scale_after_first_residual();
      result_.threshold = std::max(relative_tolerance_ * scale_, kSubnormalResidual);
    }
    merit_unit_ = power_of_two_unit(scale_);
    result_.residual_norm = robust_norm(residual_);
    if (options_.record_history) result_.residual_history.push_back(result_.residual_norm);
    if (!all_finite(residual_)) return fail_with("nan");
    merit_ = merit_of(x_, residual_);
    // An objective is an energy, quadratic in the state: it overflows for a state above ~1e154
    // where the residual (linear in it) is still finite. Say so rather than "nan".
    if (system_.objective && std::isinf(merit_)) return fail_with("objective_overflow");
    if (!std::isfinite(merit_)) return fail_with("nan");

    safeguard_ = system_.symmetric && system_.objective && system_.spd_shift.size() > 0;
    if (safeguard_ &&
        (system_.spd_shift.rows() != x_.size() || system_.spd_shift.cols() != x_.size())) {
      throw std::logic_error(fmt::format("Newton SPD shift is {}x{} for {} unknowns",
                                         system_.spd_shift.rows(), system_.spd_shift.cols(),
                                         x_.size()));
    }
    f_.kind = resolve_linear_solver(options_.linear.kind, x_.size());
    // Modified Newton: the direction comes from a factorisation of an earlier Jacobian (of this
    // solve, or of the last one when it ended contracting fast).
    reuse_factor_ = modified_ && f_.keep_factor && f_.has_factor && f_.rows == x_.size() &&
                    f_.pattern_symmetric == system_.symmetric;
    // The threshold's inner-term part comes with a Jacobian evaluation; a solve that starts on
    // the held matrix takes it from the iterate that matrix was evaluated at (its Hessian is the
    // one held), so reusing a matrix does not tighten the stopping test below the round-off of R.
    if (reuse_factor_ && system_.inner_term_scale && std::isfinite(f_.held_inner_term_scale)) {
      result_.threshold =
          std::max({relative_tolerance_ * scale_,
                    kRoundoffFloor * (scale_ + f_.held_inner_term_scale), kSubnormalResidual});
    }
    return true;
  }

  // Called once ‖R‖ ≤ threshold: marks the result converged, lets a modified-Newton factor
  // outlive the solve, and with NewtonOptions::polish takes one more correction from the held
  // factorisation, kept only if it lowers ‖R‖ (never after zero iterations: no factor is of
  // this system then).
  void polish() {
    result_.converged = true;
    f_.keep_factor = reuse_factor_;
    if (!(options_.polish && result_.iterations > 0 && f_.has_factor)) return;
    if (!solve_held(-residual_, direction_)) return;
    trial_ = x_ + direction_;
    evaluate(trial_, trial_residual_);
    const double polished_norm = robust_norm(trial_residual_);
    if (all_finite(trial_residual_) && polished_norm < result_.residual_norm) {
      x_.swap(trial_);
      result_.residual_norm = polished_norm;
      result_.polished = true;
      if (options_.record_history) result_.residual_history.push_back(polished_norm);
    }
  }

  // Failure reporting: the reason, and no factor kept for the next solve. The result to return.
  NewtonResult fail(const char* reason) {
    fail_with(reason);
    return result_;
  }

  // One Newton iteration from an unconverged x below the iteration cap: a direction (held or
  // fresh), the round-off stop, the descent check and the line search. True: go on with the
  // loop (an accepted step, or a stale direction to redo with a fresh Jacobian); false: the
  // result is final (failed, or converged at round-off).
  bool iterate() {
    stale_ = false;
    if (reuse_factor_) {
      ++result_.linear_solves;
      stale_ = solve_held(-residual_, direction_);
      reuse_factor_ = stale_;
    }
    if (!stale_) {
      if (!assemble()) return fail_with("nan");
      // A nearly singular matrix factorises without a zero pivot but yields inf/NaN directions.
      if (!newton_direction()) return fail_with("linear_solve_failed");
    }
    ++result_.iterations;
    if (roundoff_step()) return false;

    // Directional derivative of the merit along the step. For ½‖R‖² it is Rᵀ J d = −‖R‖² for
    // the exact Newton step, whatever J is, so the step is always a descent direction.
    const double slope =
        system_.objective ? residual_.dot(direction_) : -(merit_unit_ * residual_).squaredNorm();
    if (system_.objective && options_.line_search && !(slope < 0.0)) {
      if (stale_) return redo_with_fresh_jacobian();
      // R·d = 0 with R and d nonzero: the product underflowed (a state below ~1e-160, whose
      // energy is below the smallest double), not a non-descent direction.
      if (slope == 0.0 && result_.residual_norm > 0.0 && robust_norm(direction_) > 0.0) {
        return fail_with("objective_underflow");
      }
      return fail_with("not_descent");
    }

    bool any_finite = false;
    const bool accepted = line_search(slope, any_finite);
    if (!accepted && stale_) return redo_with_fresh_jacobian();
    if (!accepted) return fail_with(any_finite ? "line_search_failed" : "nan");
    accept_step();
    return true;
  }

 private:
  bool fail_with(const char* reason) {
    result_.reason = reason;
    f_.keep_factor = false;
    return false;
  }

  // R at `at` into r (counted, timed; throws when R has the wrong size).
  void evaluate(const Vec& at, Vec& r) {
    ++result_.residual_evals;
    const PhaseTimer timer(profile_totals().residual_ns);
    system_.residual(at, r);
    if (r.size() != at.size()) {
      throw std::logic_error(
          fmt::format("Newton residual has size {} for {} unknowns", r.size(), at.size()));
    }
  }

  // Merit of a finite residual: the objective when the system has one, else ½‖R‖² in units of
  // the power of two nearest the residual scale (merit_unit_), so that it neither underflows for
  // a state of size 1e-300 nor overflows for 1e+150; merits and slopes are only compared with
  // each other, and scaling by 2ᵏ keeps every comparison bit for bit.
  double merit_of(const Vec& at, const Vec& r) {
    if (!system_.objective) return 0.5 * (merit_unit_ * r).squaredNorm();
    profile_totals().objectives.fetch_add(1, std::memory_order_relaxed);
    const PhaseTimer timer(profile_totals().objective_ns);
    return system_.objective(at);
  }

  // Inexact Newton: the CG iteration stops at forcing·‖R‖ (forcing terms: kFirstForcing, then
  // Eisenstat–Walker's, updated in accept_step()) and below the threshold (the last correction
  // does not leave an error the stopping test would see). The stopping test on R itself is
  // unchanged, so it alone decides convergence. Direct solvers ignore the target.
  void set_cg_target() {
    f_.cg_target = std::max(0.1 * result_.threshold, forcing_ * result_.residual_norm);
  }

  // Solves J d = −R with the held factorisation (or CG on the held matrix).
  bool solve_held(const Vec& rhs, Vec& out) {
    set_cg_target();
    bool negative_curvature = false;
    return f_.solve(system_.symmetric, rhs, out, negative_curvature) && all_finite(out);
  }

  // Assembly: J(x) into f_.jacobian (timed; throws on a wrongly sized J), and the threshold's
  // inner-term part at this iterate (NewtonSystem::inner_term_scale). False: J is not finite.
  bool assemble() {
    {
      profile_totals().jacobians.fetch_add(1, std::memory_order_relaxed);
      const PhaseTimer timer(profile_totals().jacobian_ns);
      system_.jacobian(x_, f_.jacobian);
    }
    if (f_.jacobian.rows() != x_.size() || f_.jacobian.cols() != x_.size()) {
      throw std::logic_error(fmt::format("Newton Jacobian is {}x{} for {} unknowns",
                                         f_.jacobian.rows(), f_.jacobian.cols(), x_.size()));
    }
    if (!all_finite(f_.jacobian)) return false;
    if (system_.inner_term_scale) {
      const double inner = system_.inner_term_scale();
      f_.held_inner_term_scale = inner;
      if (std::isfinite(inner)) {
        result_.threshold = std::max(
            {relative_tolerance_ * scale_, kRoundoffFloor * (scale_ + inner), kSubnormalResidual});
      }
    }
    return true;
  }

  // Factorisation and linear solve: factorises f_.jacobian with the resolved LinearSolverKind
  // (SparseLU when not symmetric) and solves J d = −R into direction_. When the solver finds J
  // not positive definite (a non-positive LDLT pivot, CHOLMOD's NumericalIssue, CG's curvature
  // test), the SPD safeguard shifts it (shifted_direction); without the safeguard the SPD-only
  // solvers fall back to an LDLT of J, the plain Newton step. False: no finite direction.
  bool newton_direction() {
    ++result_.linear_solves;
    set_cg_target();
    bool negative_curvature = false;
    const bool factorised = f_.factorise(f_.jacobian, system_.symmetric, options_.reuse_symbolic,
                                         result_.symbolic_analyses, result_.factorizations);
    // Only the safeguard needs J positive definite; LDLT solves indefinite systems as well.
    bool solved = false;
    if (factorised && (!safeguard_ || f_.positive_definite())) {
      solved = f_.solve(system_.symmetric, -residual_, direction_, negative_curvature);
    }
    if (solved) return all_finite(direction_);
    if (safeguard_) return shifted_direction();
    if (system_.symmetric && !safeguard_ && f_.kind != LinearSolverKind::kLdlt &&
        f_.kind != LinearSolverKind::kLdltMetis &&
        f_.factorise_indefinite(result_.factorizations)) {
      solved = f_.solve(true, -residual_, direction_, negative_curvature);
      return solved && all_finite(direction_);
    }
    f_.has_factor = false;
    return false;
  }

  // The SPD safeguard (NewtonSystem::spd_shift): J is not positive definite (or singular), so
  // J + μS is factorised with μ growing geometrically until it is and its solve succeeds. J + μS
  // has the pattern of J when S's pattern is contained in it (M diagonal, J with a full
  // diagonal), so the symbolic factorisation is reused. False: no shift in the schedule worked.
  bool shifted_direction() {
    ++result_.shifted_iterations;
    const SparseMatrix unshifted = f_.jacobian;
    // Start one growth step below the last successful shift of this solve: consecutive
    // iterates usually need a similar μ, and the schedule then costs one or two factorisations.
    double mu =
        std::max(options_.spd_shift_initial, result_.last_shift / options_.spd_shift_growth);
    bool solved = false;
    bool negative_curvature = false;
    for (int attempt = 0; attempt < options_.max_spd_shifts && !solved;
         ++attempt, mu *= options_.spd_shift_growth) {
      f_.jacobian = unshifted + mu * system_.spd_shift;
      ++result_.shift_factorisations;
      if (!(f_.factorise(f_.jacobian, true, options_.reuse_symbolic, result_.symbolic_analyses,
                         result_.factorizations) &&
            f_.positive_definite())) {
        continue;
      }
      solved = f_.solve(true, -residual_, direction_, negative_curvature);
      if (solved) result_.last_shift = mu;
      if (!solved && !negative_curvature) break;  // CG did not converge: shifting won't help
    }
    if (solved) return all_finite(direction_);
    f_.has_factor = false;
    return false;
  }

  // Round-off floor in x: a correction below kRoundoffFloor·‖x‖ changes x by no more than its
  // own rounding, so the residual left is the rounding of R's terms — which can exceed
  // tolerance·residual_scale when a term's inner magnitude (h·K·q of a stiff spring whose
  // elongation is small) is far above its value. True: the correction was taken and the solve
  // converged (at_roundoff); false: go on (also when R at x + d is not finite).
  bool roundoff_step() {
    if (robust_norm(direction_) > std::max(kRoundoffFloor * robust_norm(x_), kSubnormalResidual)) {
      return false;
    }
    trial_ = x_ + direction_;
    evaluate(trial_, trial_residual_);
    if (!all_finite(trial_residual_)) return false;
    x_.swap(trial_);
    residual_.swap(trial_residual_);
    result_.residual_norm = robust_norm(residual_);
    if (options_.record_history) result_.residual_history.push_back(result_.residual_norm);
    result_.converged = true;
    result_.at_roundoff = true;
    return true;
  }

  // A direction from an old Jacobian failed (no descent, no acceptable step): this iteration
  // does not count and is redone with the current Jacobian.
  bool redo_with_fresh_jacobian() {
    --result_.iterations;
    reuse_factor_ = false;
    return true;
  }

  // Line search: backtracking from the full step, halving up to max_backtracks times, on the
  // merit (Armijo, c₁ = options.armijo) with the objective form's round-off acceptances. Leaves
  // the accepted trial point in trial_, trial_residual_, trial_merit_ and its length in step_.
  // any_finite: some trial had a finite residual and merit (else the failure is "nan").
  bool line_search(double slope, bool& any_finite) {
    step_ = 1.0;
    trial_merit_ = 0.0;
    for (int backtrack = 0; backtrack <= options_.max_backtracks; ++backtrack, step_ *= 0.5) {
      trial_ = x_ + step_ * direction_;
      if (trial_ == x_) break;  // the step is below x's resolution: no progress is possible
      evaluate(trial_, trial_residual_);
      if (!all_finite(trial_residual_)) {
        if (!options_.line_search) break;
        continue;  // the step left the domain of R (e.g. an inverted element): shorten it
      }
      trial_merit_ = merit_of(trial_, trial_residual_);
      if (!std::isfinite(trial_merit_)) {
        if (!options_.line_search) break;
        continue;
      }
      any_finite = true;
      // Without a line search a full step is taken whatever it does to R; from an old Jacobian
      // only if it reduces ‖R‖ (otherwise the iteration is redone with the current one).
      if (stale_ && !options_.line_search &&
          !(robust_norm(trial_residual_) < result_.residual_norm))
        break;
      if (!options_.line_search || trial_merit_ <= merit_ + options_.armijo * step_ * slope) {
        return true;
      }
      if (accepted_at_objective_roundoff(slope)) return true;
    }
    return false;
  }

  // The objective form's two acceptances of a trial whose Armijo decrease is lost in E's
  // rounding, both only when ‖R‖ decreased.
  bool accepted_at_objective_roundoff(double slope) const {
    // Close to the root an objective's decrease (~‖R‖²) drops below its round-off
    // (~ε|E|) long before ‖R‖ reaches the tolerance; the residual still measures progress.
    const double merit_size = std::max(std::abs(merit_), system_.objective_scale);
    if (system_.objective && robust_norm(trial_residual_) < result_.residual_norm &&
        trial_merit_ <= merit_ + 16 * std::numeric_limits<double>::epsilon() * merit_size) {
      return true;
    }
    // The rounding of E can exceed 16ε·objective_scale by far when V sums terms that cancel
    // (an elastic energy density of a rotated element: μ(tr H + ½|H|²) − μ ln J with H = R − I
    // of size 1 and W ~ strain²), and then hides a decrease of E that the gradient still
    // resolves. Armijo in derivative form (the approximate Wolfe test, kApproximateArmijoSlack).
    return system_.objective && robust_norm(trial_residual_) < result_.residual_norm &&
           trial_residual_.dot(direction_) <= (1 - 2 * options_.armijo) * -slope &&
           trial_merit_ <= merit_ + kApproximateArmijoSlack * merit_size;
  }

  // Step acceptance: the line search's trial becomes x; the CG forcing term and the
  // modified-Newton reuse decision are updated from the residual it reached.
  void accept_step() {
    x_.swap(trial_);
    residual_.swap(trial_residual_);
    merit_ = trial_merit_;
    const double previous_norm = result_.residual_norm;
    result_.residual_norm = robust_norm(residual_);
    if (f_.is_cg() && previous_norm > 0.0) {
      // Eisenstat–Walker choice 1: how far the linear model R + J·s of the step taken missed the
      // new residual. For a damped step s = αd, ‖R + αJd‖ ≤ (1 − α)‖R‖ + α‖R + Jd‖.
      const double model = (1.0 - step_) * previous_norm + step_ * f_.cg_residual;
      double next = std::abs(result_.residual_norm - model) / previous_norm;
      const double safeguard = std::pow(forcing_, kForcingSafeguardExponent);
      if (safeguard > 0.1) next = std::max(next, safeguard);
      forcing_ = std::min(next, kMaxForcing);
    }
    reuse_factor_ = modified_ && f_.has_factor && step_ == 1.0 &&
                    result_.residual_norm <= kModifiedNewtonContraction * previous_norm;
    if (options_.record_history) result_.residual_history.push_back(result_.residual_norm);
  }

  const NewtonSystem& system_;
  const NewtonOptions& options_;
  LinearFactorisation& f_;
  Vec& x_;
  NewtonResult& result_;
  const double residual_scale_;
  const double relative_tolerance_;
  double scale_;  // residual_scale plus scale_after_first_residual
  double merit_unit_ = 1.0;
  double merit_ = 0.0;      // the merit at x_
  bool safeguard_ = false;  // the SPD shift applies (symmetric, objective, spd_shift given)
  const bool modified_;
  bool reuse_factor_ = false;  // the next direction comes from the held factorisation
  bool stale_ = false;         // this iteration's direction came from an old Jacobian
  double forcing_ = kFirstForcing;
  double step_ = 1.0;  // the accepted step length of the last line search
  double trial_merit_ = 0.0;
  Vec residual_, direction_, trial_, trial_residual_;
};

}  // namespace

// The phases are NewtonRun's (above); this loop is the whole algorithm.
NewtonResult NewtonSolver::solve(const NewtonSystem& system, Vec& x, double residual_scale) {
  NewtonResult result;
  const SolveProfile profile(result);
  NewtonRun run(system, options_, *factorisation_, x, result, residual_scale);
  if (!run.start()) return result;
  while (true) {
    if (result.residual_norm <= result.threshold) {
      run.polish();
      return result;
    }
    if (result.iterations >= options_.max_iterations) return run.fail("newton_max_iter");
    if (!run.iterate()) return result;
  }
}

}  // namespace geomint
