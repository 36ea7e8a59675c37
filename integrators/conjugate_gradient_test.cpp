// Conjugate gradients of the Newton systems (integrators/conjugate_gradient.hpp): the Jacobi
// preconditioner has Eigen's bits; below kBlockedCgFrom unknowns jacobi_cg is the serial loop bit
// for bit, from it the blocked loop reaches the target on the true residual, agrees with the
// serial loop, gives the same bits at 1–4 threads at scales 1e-150, 1 and 1e+150, and reports
// negative curvature.
#include "integrators/conjugate_gradient.hpp"

#include <gtest/gtest.h>

#include <Eigen/IterativeLinearSolvers>
#include <cmath>
#include <cstring>
#include <vector>

#include "problems/parallel.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace conjugate_gradient_test {
namespace {

// A sparse SPD matrix of n unknowns, stored in full: diagonal 4.5 + sin(i) (unequal, so the
// preconditioner matters), −1 to the neighbours at distance 1 and 97 (strictly diagonally
// dominant), all times `scale`.
SparseMatrix spd_matrix(Eigen::Index n, double scale) {
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index i = 0; i < n; ++i) {
    entries.emplace_back(i, i, scale * (4.5 + std::sin(static_cast<double>(i))));
    for (Eigen::Index offset : {1, 97}) {
      if (i + offset < n) {
        entries.emplace_back(i, i + offset, -scale);
        entries.emplace_back(i + offset, i, -scale);
      }
    }
  }
  SparseMatrix A(n, n);
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  return A;
}

Vec right_hand_side(Eigen::Index n, double scale) {
  Vec b(n);
  for (Eigen::Index i = 0; i < n; ++i) b[i] = scale * std::cos(0.37 * static_cast<double>(i));
  return b;
}

bool same_bits(const Vec& a, const Vec& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

struct Solve {
  CgOutcome outcome = CgOutcome::kNoConvergence;
  Vec x;
  int iterations = 0;
  double residual = 0;
};

Solve blocked_or_serial(const SparseMatrix& A, const Vec& b, double target) {
  JacobiPreconditioner jacobi;
  jacobi.compute(A);
  Solve out;
  out.outcome = jacobi_cg([&](const Vec& p, Vec& Ap) { symmetric_product(A, p, Ap); }, jacobi, b,
                          target, 10000, out.x, out.iterations, out.residual);
  return out;
}

Solve serial_with_eigens_preconditioner(const SparseMatrix& A, const Vec& b, double target) {
  Eigen::DiagonalPreconditioner<double> diagonal;
  diagonal.compute(A);
  Solve out;
  out.outcome = preconditioned_cg([&](const Vec& p, Vec& Ap) { symmetric_product(A, p, Ap); },
                                  diagonal, b, target, 10000, out.x, out.iterations, out.residual);
  return out;
}

TEST(ConjugateGradient, JacobiPreconditionerHasEigensBits) {
  // A zero and a missing diagonal entry (both give 1), and values whose inverses round.
  SparseMatrix A(4, 4);
  A.insert(0, 0) = 3.0;
  A.insert(1, 1) = 0.0;
  A.insert(2, 3) = 1.0;
  A.insert(3, 2) = 1.0;
  A.insert(3, 3) = 7e-300;
  A.makeCompressed();
  JacobiPreconditioner jacobi;
  jacobi.compute(A);
  Eigen::DiagonalPreconditioner<double> diagonal;
  diagonal.compute(A);
  const Vec r = Vec::LinSpaced(4, -1.3, 2.9);
  EXPECT_TRUE(same_bits(jacobi.solve(r), diagonal.solve(r)));
  EXPECT_EQ(jacobi.inverse_diagonal[1], 1.0);
  EXPECT_EQ(jacobi.inverse_diagonal[2], 1.0);
}

TEST(ConjugateGradient, BelowTheBlockedSizeJacobiCgIsTheSerialLoop) {
  const Eigen::Index n = kBlockedCgFrom - 1;
  const SparseMatrix A = spd_matrix(n, 1.0);
  const Vec b = right_hand_side(n, 1.0);
  const double target = 1e-10 * b.norm();
  const Solve blocked = blocked_or_serial(A, b, target);
  const Solve serial = serial_with_eigens_preconditioner(A, b, target);
  ASSERT_EQ(blocked.outcome, CgOutcome::kConverged);
  EXPECT_EQ(blocked.iterations, serial.iterations);
  EXPECT_TRUE(same_bits(blocked.x, serial.x));
  EXPECT_EQ(blocked.residual, serial.residual);
}

// n is not a multiple of kCgBlock (a short last block) and spans enough blocks for 4 threads.
TEST(ConjugateGradient, BlockedLoopSolvesWithTheSameBitsAtAnyThreadCount) {
  test::ThreadCountGuard guard;
  const Eigen::Index n = 5 * kCgBlock + 1234;
  for (double scale : {1e-150, 1.0, 1e+150}) {
    SCOPED_TRACE(scale);
    const SparseMatrix A = spd_matrix(n, scale);
    const Vec b = right_hand_side(n, scale);
    const double target = 1e-10 * robust_norm(b);
    set_thread_count(1);
    const Solve one = blocked_or_serial(A, b, target);
    ASSERT_EQ(one.outcome, CgOutcome::kConverged);
    // The target holds for the true residual too (the recursive one drifts from it only at the
    // level of round-off, far below 1e-10).
    Vec Ax;
    symmetric_product(A, one.x, Ax);
    EXPECT_LE(robust_norm(Vec(b - Ax)), 1.01 * target);
    EXPECT_LE(one.residual, target);
    // The serial loop, whose inner products Eigen sums in another order, takes the same path.
    const Solve serial = serial_with_eigens_preconditioner(A, b, target);
    ASSERT_EQ(serial.outcome, CgOutcome::kConverged);
    EXPECT_NEAR(one.iterations, serial.iterations, 1);
    EXPECT_LE(robust_norm(Vec(one.x - serial.x)), 1e-9 * robust_norm(serial.x));
    EXPECT_FALSE(same_bits(one.x, serial.x)) << "the blocked loop did not run";
    for (int threads : {2, 3, 4}) {
      set_thread_count(threads);
      const Solve other = blocked_or_serial(A, b, target);
      EXPECT_EQ(other.iterations, one.iterations) << threads;
      EXPECT_TRUE(same_bits(other.x, one.x)) << threads;
      EXPECT_EQ(other.residual, one.residual) << threads;
    }
  }
}

// pᵀAp ≤ 0 is reported, not iterated through: a negative diagonal entry that dominates the first
// direction (both loops).
TEST(ConjugateGradient, BothLoopsReportNegativeCurvature) {
  for (Eigen::Index n : {kBlockedCgFrom - 1, kBlockedCgFrom + 1}) {
    SparseMatrix A(n, n);
    A.setIdentity();
    A.coeffRef(7, 7) = -1e-3;
    A.makeCompressed();
    Vec b = Vec::Ones(n);
    b[7] = 1e3;
    EXPECT_EQ(blocked_or_serial(A, b, 1e-12).outcome, CgOutcome::kNegativeCurvature) << n;
  }
}

}  // namespace
}  // namespace conjugate_gradient_test
}  // namespace geomint
