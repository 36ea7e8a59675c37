// Registry-driven checks of the holonomic-constraint capability (docs/METHOD.md §3):
// for every problem spec with `constraints`, G = ∂g/∂q, the curvature c(q, v) = d/dt(G(q)v) and
// the Hessian of λᵀg against finite differences, consistent initial states, and bad states named.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace {

std::vector<std::string> constrained_specs() {
  std::vector<std::string> specs;
  for (const auto& spec : problem_test_specs()) {
    if (make_problem(spec)->has(kConstraints)) specs.push_back(spec);
  }
  return specs;
}

Vec inf_norms_of_rows(const Eigen::MatrixXd& matrix) { return matrix.cwiseAbs().rowwise().sum(); }

Eigen::MatrixXd jacobian_at(const Problem& problem, const Vec& q) {
  SparseMatrix G;
  problem.constraint_jacobian(q, G);
  return Eigen::MatrixXd(G);
}

Vec residual_at(const Problem& problem, const Vec& q) {
  Vec g;
  problem.constraint(q, g);
  return g;
}

class ConstrainedProblem : public testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    problem_ = make_problem(GetParam());
    const State start = problem_->initial_state();
    length_scale_ = std::max(1.0, start.q.lpNorm<Eigen::Infinity>());
    // The initial configuration and three configurations off the manifold by 5% of the size of
    // q (the derivatives must hold everywhere, not only where g = 0), with velocities of the
    // initial size in random directions.
    const double speed = std::max(1.0, problem_->inverse_mass().cwiseProduct(start.p).norm());
    points_.push_back({start.q, problem_->inverse_mass().cwiseProduct(start.p)});
    for (unsigned seed = 1; seed <= 3; ++seed) {
      const int n = problem_->dof();
      points_.push_back({start.q + 0.05 * length_scale_ * test::random_vector(n, seed),
                         speed * test::random_vector(n, 100 + seed)});
    }
  }
  std::unique_ptr<Problem> problem_;
  double length_scale_ = 1;
  std::vector<std::pair<Vec, Vec>> points_;  // (q, v)
};

// Central differences with δ = 1e-6 of the configuration's size: truncation ~δ²|g'''| and
// rounding ~ε|g|/δ are both ~1e-10 relative, well inside the 1e-7 allowed.
TEST_P(ConstrainedProblem, JacobianMatchesFiniteDifferences) {
  const Problem& problem = *problem_;
  const int m = problem.constraint_count();
  const double delta = 1e-6 * length_scale_;
  for (const auto& [q, v] : points_) {
    const Eigen::MatrixXd G = jacobian_at(problem, q);
    ASSERT_EQ(G.rows(), m);
    ASSERT_EQ(G.cols(), problem.dof());
    ASSERT_EQ(residual_at(problem, q).size(), m);
    ASSERT_EQ(static_cast<int>(problem.multiplier_names().size()), m);
    const double scale = inf_norms_of_rows(G).maxCoeff();
    for (int j = 0; j < problem.dof(); ++j) {
      Vec plus = q, minus = q;
      plus[j] += delta;
      minus[j] -= delta;
      const Vec column = (residual_at(problem, plus) - residual_at(problem, minus)) / (2 * delta);
      EXPECT_LE((column - G.col(j)).lpNorm<Eigen::Infinity>(), 1e-7 * scale)
          << "column " << j << ": differences " << column.transpose() << ", G "
          << G.col(j).transpose();
    }
  }
}

// c(q, v) = d/dt [G(q + tv) v] at t = 0, differenced in t.
TEST_P(ConstrainedProblem, CurvatureMatchesTheDerivativeOfGv) {
  const Problem& problem = *problem_;
  const double delta = 1e-6 * length_scale_;
  for (const auto& [q, v] : points_) {
    Vec c;
    problem.constraint_curvature(q, v, c);
    ASSERT_EQ(c.size(), problem.constraint_count());
    if (v.isZero(0)) {  // a chain released from rest: c is quadratic in v
      EXPECT_TRUE(c.isZero(0)) << c.transpose();
      continue;
    }
    const double step = delta / v.lpNorm<Eigen::Infinity>();
    const Vec differenced =
        (jacobian_at(problem, q + step * v) * v - jacobian_at(problem, q - step * v) * v) /
        (2 * step);
    // c is quadratic in v and ~|v|²/|q|: scale the tolerance by that size.
    const double scale = v.squaredNorm() / length_scale_;
    EXPECT_LE((c - differenced).lpNorm<Eigen::Infinity>(), 1e-7 * scale)
        << "curvature " << c.transpose() << ", differences " << differenced.transpose();
  }
}

// K(q, λ) = ∂(G(q)ᵀλ)/∂q, column by column, and symmetric.
TEST_P(ConstrainedProblem, HessianMatchesTheDerivativeOfGTransposeLambda) {
  const Problem& problem = *problem_;
  const int m = problem.constraint_count();
  const double delta = 1e-6 * length_scale_;
  const Vec lambda = test::random_vector(m, 7) * 2.5;
  for (const auto& [q, v] : points_) {
    SparseMatrix K_sparse;
    problem.constraint_hessian(q, lambda, K_sparse);
    const Eigen::MatrixXd K(K_sparse);
    ASSERT_EQ(K.rows(), problem.dof());
    ASSERT_EQ(K.cols(), problem.dof());
    const double scale = lambda.lpNorm<Eigen::Infinity>() / length_scale_;
    EXPECT_LE((K - K.transpose()).lpNorm<Eigen::Infinity>(), 1e-14 * scale);
    for (int j = 0; j < problem.dof(); ++j) {
      Vec plus = q, minus = q;
      plus[j] += delta;
      minus[j] -= delta;
      const Vec column = (jacobian_at(problem, plus).transpose() * lambda -
                          jacobian_at(problem, minus).transpose() * lambda) /
                         (2 * delta);
      EXPECT_LE((column - K.col(j)).lpNorm<Eigen::Infinity>(), 1e-7 * scale) << "column " << j;
    }
  }
}

TEST_P(ConstrainedProblem, InitialStateIsConsistentToRoundOff) {
  const Problem& problem = *problem_;
  const State start = problem.initial_state();
  EXPECT_NO_THROW(problem.check_consistent(start, "initial state", 1e-14));
  EXPECT_EQ(problem.multiplier_names().size(), static_cast<size_t>(problem.constraint_count()));
  EXPECT_EQ(problem.multipliers(start.t, start.q, start.p).size(), problem.constraint_count());
}

// An inconsistent state (the path a user-given Cartesian state would take) is bad input whose
// message names the problem and the residual; position and velocity level separately.
TEST_P(ConstrainedProblem, InconsistentStateIsAnInputErrorNamingTheResidual) {
  const Problem& problem = *problem_;
  State moved = problem.initial_state();
  moved.q += 1e-6 * length_scale_ * test::random_vector(problem.dof(), 11);
  EXPECT_TRUE(test::input_error_names(
      [&](const std::string& what) { problem.check_consistent(moved, what); }, "initial state",
      {problem.spec(), "initial state", "constraint residual max|g(q)|"}));
  State pushed = problem.initial_state();
  // Along a constraint normal: a velocity that changes a rod's length.
  const Eigen::MatrixXd G = jacobian_at(problem, pushed.q);
  const double speed = std::max(1.0, problem.inverse_mass().cwiseProduct(pushed.p).norm());
  pushed.p += 1e-6 * speed * problem.mass().cwiseProduct(G.row(0).transpose());
  EXPECT_TRUE(test::input_error_names(
      [&](const std::string& what) { problem.check_consistent(pushed, what); }, "initial state",
      {problem.spec(), "velocity constraint residual max|G(q) v|"}));
}

std::string test_name(const testing::TestParamInfo<std::string>& info) {
  std::string name;
  for (char c : info.param) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Registry, ConstrainedProblem, testing::ValuesIn(constrained_specs()),
                         test_name);

TEST(ConstrainedProblems, TheCatalogueHasConstrainedProblems) {
  EXPECT_GE(constrained_specs().size(), 4u);
}

// The multipliers are the rods' tensions, in force units, with the sign of a pulling rod: on the
// conical spherical pendulum T = m g / cos θ (vertical balance), on a hanging chain at rest the
// tension of rod i carries the weight of the nodes below it.
TEST(ConstrainedProblems, MultipliersAreTheRodTensions) {
  const double mass = 0.4, gravity = 3, theta0 = 0.7;
  const auto spherical =
      make_problem("spherical_pendulum:length=2.5,gravity=3,mass=0.4,theta0=0.7");
  ASSERT_TRUE(spherical->has(kExact));
  const State conical = spherical->exact(1.3);
  EXPECT_NEAR(spherical->multipliers(conical.t, conical.q, conical.p)[0],
              mass * gravity / std::cos(theta0), 1e-13);
  const auto chain = make_problem("rod_chain:n=3,mass=2,mass_ratio=0.5,gravity=2.5,theta=0");
  const State hanging = chain->initial_state();
  const Vec tension = chain->multipliers(0.0, hanging.q, hanging.p);
  EXPECT_NEAR(tension[0], (2 + 1 + 0.5) * 2.5, 1e-12);
  EXPECT_NEAR(tension[1], (1 + 0.5) * 2.5, 1e-12);
  EXPECT_NEAR(tension[2], 0.5 * 2.5, 1e-12);
  EXPECT_EQ(chain->multiplier_names(),
            (std::vector<std::string>{"tension1", "tension2", "tension3"}));
}

// The conical motion's period is the time of one azimuthal revolution 2π√(L cos θ/g), and the
// state returns to its start after it.
TEST(ConstrainedProblems, ConicalPeriodIsExact) {
  const auto problem = make_problem("spherical_pendulum:length=2.5,gravity=3,theta0=0.7");
  ASSERT_TRUE(problem->has(kPeriod));
  const double period = 2 * std::numbers::pi * std::sqrt(2.5 * std::cos(0.7) / 3);
  EXPECT_NEAR(problem->period(), period, 1e-14 * period);
  EXPECT_FALSE(make_problem("spherical_pendulum:theta_dot0=0.1")->has(kExact));
  EXPECT_FALSE(make_problem("spherical_pendulum:theta0=2")->has(kExact));
}

TEST(ConstrainedProblems, BadParametersNameTheKey) {
  EXPECT_TRUE(
      test::input_errors_name(make_problem, {{"rod_chain:n=0", "n"},
                                             {"rod_chain:n=2,theta3=1", "theta3"},
                                             {"rod_chain:length=-1", "length"},
                                             {"rod_chain:n=64,mass_ratio=1e15", "mass_ratio"},
                                             {"spherical_pendulum:length=0", "length"},
                                             {"spherical_pendulum:gravity=-1", "gravity"}}));
}

}  // namespace
}  // namespace geomint
