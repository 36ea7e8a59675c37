// Preconditioned conjugate gradients for the symmetric Newton systems (integrators/newton.cpp),
// with the curvature test of truncated CG (Nocedal & Wright, "Numerical Optimization", 2nd ed.,
// Algorithm 5.3 and §7.1), and its Jacobi-preconditioned form in threaded blocks (issue 30).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "integrators/newton.hpp"
#include "problems/parallel.hpp"

namespace geomint {

enum class CgOutcome { kConverged, kNegativeCurvature, kNoConvergence };

// ‖r‖₂ as robust_norm gives it, from one pass over r where the sum of squares is far from under-
// and overflow (a CG residual is tested every iteration; robust_norm takes two passes and a
// temporary). Squares that underflow below 1e-200 change no bit of a sum above it.
inline double norm_from_squares(double squares, const Vec& r) {
  return squares > 1e-200 && squares < 1e300 ? std::sqrt(squares) : robust_norm(r);
}
inline double cg_residual_norm(const Vec& r) { return norm_from_squares(r.squaredNorm(), r); }

// Preconditioned CG on A (stored in full, both triangles), from x = 0, until ‖b − Ax‖ ≤ target,
// written out rather than Eigen's ConjugateGradient for the curvature test: pᵀAp ≤ 0 proves A is
// not positive definite, which is what the SPD safeguard needs to know. `multiply(p, Ap)` is the
// threaded geomint::symmetric_product (problems/parallel.hpp), the same bits at any thread count;
// the vector updates and inner products here are Eigen's, serial. `final_residual` is the
// recursively updated ‖r‖ at the end.
template <class Multiply, class Preconditioner>
CgOutcome preconditioned_cg(const Multiply& multiply, const Preconditioner& preconditioner,
                            const Vec& b, double target, int max_iterations, Vec& x,
                            int& iterations, double& final_residual) {
  iterations = 0;
  x = Vec::Zero(b.size());
  Vec r = b;
  final_residual = cg_residual_norm(r);
  if (final_residual <= target) return CgOutcome::kConverged;
  Vec z = preconditioner.solve(r);
  Vec p = z, Ap;
  double rz = r.dot(z);
  for (int k = 0; k < max_iterations; ++k) {
    ++iterations;
    multiply(p, Ap);
    const double curvature = p.dot(Ap);
    if (!(curvature > 0.0)) return CgOutcome::kNegativeCurvature;
    const double alpha = rz / curvature;
    x += alpha * p;
    r -= alpha * Ap;
    final_residual = cg_residual_norm(r);
    if (final_residual <= target) return CgOutcome::kConverged;
    z = preconditioner.solve(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return CgOutcome::kNoConvergence;
}

// The Jacobi preconditioner z = D⁻¹r, D the diagonal of A (1 where it is missing or zero): the
// values and bits of Eigen::DiagonalPreconditioner, with the inverse diagonal in the open for the
// blocked loop below.
struct JacobiPreconditioner {
  Vec inverse_diagonal;
  void compute(const SparseMatrix& A);
  Vec solve(const Vec& r) const { return inverse_diagonal.cwiseProduct(r); }
};

// From this many unknowns, jacobi_cg runs its vector work in threaded blocks (below, the serial
// preconditioned_cg: smaller systems gain nothing from threads, and every committed result of the
// suite keeps its bits). 4 blocks of kCgBlock entries.
inline constexpr Eigen::Index kCgBlock = 4096;
inline constexpr Eigen::Index kBlockedCgFrom = 4 * kCgBlock;

// body(first, count, block) for the blocks [first, first + count) of kCgBlock entries of
// [0, size), on the thread pool; blocks are numbered from 0.
template <class Body>
void over_blocks(Eigen::Index size, const Body& body) {
  const auto blocks = static_cast<std::size_t>((size + kCgBlock - 1) / kCgBlock);
  for_each_chunk(chunk_count(blocks, 2), blocks, [&](int, std::size_t begin, std::size_t end) {
    for (std::size_t block = begin; block < end; ++block) {
      const Eigen::Index first = static_cast<Eigen::Index>(block) * kCgBlock;
      body(first, std::min(kCgBlock, size - first), block);
    }
  });
}

// Totals of per-block sums: body(first, count, sums) puts the sums of its entries' terms in
// sums[0..terms) (and may update those entries of vectors); each total adds the block sums in
// block order, so it has the same bits at any thread count.
template <int terms, class Body>
void sum_over_blocks(Eigen::Index size, const Body& body, double (&totals)[terms]) {
  const auto blocks = static_cast<std::size_t>((size + kCgBlock - 1) / kCgBlock);
  std::vector<double> sums(blocks * terms, 0.0);
  over_blocks(size, [&](Eigen::Index first, Eigen::Index count, std::size_t block) {
    body(first, count, sums.data() + terms * block);
  });
  for (int t = 0; t < terms; ++t) {
    double total = 0.0;
    for (std::size_t block = 0; block < blocks; ++block) total += sums[terms * block + t];
    totals[t] = total;
  }
}

// preconditioned_cg with the Jacobi preconditioner. From kBlockedCgFrom unknowns the vector work
// of an iteration is three threaded passes over blocks of kCgBlock entries instead of seven serial
// ones: pᵀAp; the updates of x and r with z = D⁻¹r, ‖r‖² and rᵀz; the update of p. The inner
// products are summed per block (sum_over_blocks), so they differ from Eigen's in the last bits
// but are the same at any thread count. docs/PERF.md "Blocked CG".
template <class Multiply>
CgOutcome jacobi_cg(const Multiply& multiply, const JacobiPreconditioner& jacobi, const Vec& b,
                    double target, int max_iterations, Vec& x, int& iterations,
                    double& final_residual) {
  const Eigen::Index n = b.size();
  if (n < kBlockedCgFrom) {
    return preconditioned_cg(multiply, jacobi, b, target, max_iterations, x, iterations,
                             final_residual);
  }
  const Vec& inverse = jacobi.inverse_diagonal;
  iterations = 0;
  x = Vec::Zero(n);
  Vec r = b, z(n), p(n), Ap(n);
  double start[2];  // ‖r‖², rᵀz
  sum_over_blocks(
      n,
      [&](Eigen::Index first, Eigen::Index count, double* sums) {
        z.segment(first, count) =
            inverse.segment(first, count).cwiseProduct(r.segment(first, count));
        p.segment(first, count) = z.segment(first, count);
        sums[0] = r.segment(first, count).squaredNorm();
        sums[1] = r.segment(first, count).dot(z.segment(first, count));
      },
      start);
  final_residual = norm_from_squares(start[0], r);
  if (final_residual <= target) return CgOutcome::kConverged;
  double rz = start[1];
  for (int k = 0; k < max_iterations; ++k) {
    ++iterations;
    multiply(p, Ap);
    double curvature[1];
    sum_over_blocks(
        n,
        [&](Eigen::Index first, Eigen::Index count, double* sums) {
          sums[0] = p.segment(first, count).dot(Ap.segment(first, count));
        },
        curvature);
    if (!(curvature[0] > 0.0)) return CgOutcome::kNegativeCurvature;
    const double alpha = rz / curvature[0];
    double next[2];  // ‖r‖², rᵀz after the update
    sum_over_blocks(
        n,
        [&](Eigen::Index first, Eigen::Index count, double* sums) {
          x.segment(first, count) += alpha * p.segment(first, count);
          r.segment(first, count) -= alpha * Ap.segment(first, count);
          z.segment(first, count) =
              inverse.segment(first, count).cwiseProduct(r.segment(first, count));
          sums[0] = r.segment(first, count).squaredNorm();
          sums[1] = r.segment(first, count).dot(z.segment(first, count));
        },
        next);
    final_residual = norm_from_squares(next[0], r);
    if (final_residual <= target) return CgOutcome::kConverged;
    const double beta = next[1] / rz;
    rz = next[1];
    over_blocks(n, [&](Eigen::Index first, Eigen::Index count, std::size_t) {
      p.segment(first, count) = z.segment(first, count) + beta * p.segment(first, count);
    });
  }
  return CgOutcome::kNoConvergence;
}

}  // namespace geomint
