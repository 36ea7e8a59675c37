// The mass operator (problems/mass_operator.hpp) on every registered problem with a mass: apply,
// solve and the kinetic energy agree with the dense M(q) they stand for, and on the separable kind
// they are bit for bit the constant-diagonal products the methods computed before the operator.
#include "problems/mass_operator.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <stdexcept>
#include <string>

namespace geomint {
namespace mass_operator_test {
namespace {

// A configuration away from the initial one and a vector with no zero entry, so that a q-dependent
// M(q) and every column of it are exercised.
Vec probe(int n, double offset) {
  Vec x(n);
  for (int i = 0; i < n; ++i) x[i] = offset + 0.37 * (i + 1) - 0.11 * i * i;
  return x;
}

TEST(MassOperator, AgreesWithTheDenseMassOnEveryProblem) {
  int separable = 0, general = 0;
  for (const std::string& spec : problem_test_specs()) {
    SCOPED_TRACE(spec);
    const auto problem = make_problem(spec);
    if (problem->kind() == ProblemKind::kFirstOrder) {
      EXPECT_THROW(MassOperator{*problem}, std::logic_error);
      continue;
    }
    const MassOperator mass(*problem);
    const State start = problem->initial_state();
    const int n = problem->dof();
    const Vec q = start.q + 1e-2 * probe(n, 0.0);
    const Vec x = probe(n, 0.5);
    Eigen::MatrixXd M;
    mass.dense(q, M);
    ASSERT_EQ(M.rows(), n);
    const double scale = M.cwiseAbs().maxCoeff();
    const Vec Mx = mass.apply(q, x);
    EXPECT_LE((Mx - M * x).lpNorm<Eigen::Infinity>(), 1e-13 * scale * x.lpNorm<Eigen::Infinity>());
    const Vec back = mass.solve(q, Mx);
    EXPECT_LE((back - x).lpNorm<Eigen::Infinity>(), 1e-10 * x.lpNorm<Eigen::Infinity>());
    EXPECT_NEAR(mass.kinetic(q, Mx), 0.5 * x.dot(Mx), 1e-12 * std::abs(x.dot(Mx)));
    EXPECT_EQ(mass.max_diagonal(q), M.diagonal().maxCoeff());
    Eigen::MatrixXd columns = Eigen::MatrixXd::Identity(n, n);
    mass.apply_columns(q, columns);
    EXPECT_LE((columns - M).cwiseAbs().maxCoeff(), 1e-13 * scale);
    mass.solve_columns(q, columns);
    EXPECT_LE((columns - Eigen::MatrixXd::Identity(n, n)).cwiseAbs().maxCoeff(), 1e-10);
    if (problem->kind() == ProblemKind::kSeparable) {
      ++separable;
      ASSERT_TRUE(mass.is_constant_diagonal());
      // The fast path: exactly the products of the stored diagonals, and H = T + V unchanged.
      EXPECT_TRUE(mass.apply(q, x) == problem->mass().cwiseProduct(x));
      EXPECT_TRUE(mass.solve(q, x) == problem->inverse_mass().cwiseProduct(x));
      EXPECT_EQ(mass.kinetic(q, x), problem->kinetic(x));
    } else {
      ++general;
      EXPECT_FALSE(mass.is_constant_diagonal());
      EXPECT_THROW(mass.constant_diagonal(), std::logic_error);
      EXPECT_THROW(mass.constant_inverse_diagonal(), std::logic_error);
      // The Legendre map through the operator: v(q, p) = M(q)⁻¹(p − a(q)).
      const LagrangianSystem& system = *problem->as_lagrangian();
      Vec a;
      system.gyroscopic(q, a);
      EXPECT_TRUE(system.velocity(q, Mx + a) == mass.solve(q, Mx + a - a));
    }
  }
  EXPECT_GT(separable, 0);
  EXPECT_GT(general, 0);
}

}  // namespace
}  // namespace mass_operator_test
}  // namespace geomint
