// Registry-driven checks of the holonomic-constraint capability (docs/METHOD.md §3):
// for every problem spec with `constraints`, G = ∂g/∂q, the curvature c(q, v) = d/dt(G(q)v) and
// the Hessian of λᵀg against finite differences, consistent initial states, and bad states named.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "problems/mass_operator.hpp"
#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace constraints_test {
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
  constraints_of(problem).constraint_jacobian(q, G);
  return Eigen::MatrixXd(G);
}

Vec residual_at(const Problem& problem, const Vec& q) {
  Vec g;
  constraints_of(problem).constraint(q, g);
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
    // v = M(q)⁻¹p whatever the kind (a constant diagonal, or M(q): andrews).
    const Vec start_velocity = MassOperator(*problem_).solve(start.q, start.p);
    const double speed = std::max(1.0, start_velocity.norm());
    points_.push_back({start.q, start_velocity});
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
  const int m = constraints_of(problem).constraint_count();
  const double delta = 1e-6 * length_scale_;
  for (const auto& [q, v] : points_) {
    const Eigen::MatrixXd G = jacobian_at(problem, q);
    ASSERT_EQ(G.rows(), m);
    ASSERT_EQ(G.cols(), problem.dof());
    ASSERT_EQ(residual_at(problem, q).size(), m);
    ASSERT_EQ(static_cast<int>(constraints_of(problem).multiplier_names().size()), m);
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
    constraints_of(problem).constraint_curvature(q, v, c);
    ASSERT_EQ(c.size(), constraints_of(problem).constraint_count());
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
  const int m = constraints_of(problem).constraint_count();
  const double delta = 1e-6 * length_scale_;
  const Vec lambda = test::random_vector(m, 7) * 2.5;
  for (const auto& [q, v] : points_) {
    SparseMatrix K_sparse;
    constraints_of(problem).constraint_hessian(q, lambda, K_sparse);
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
  EXPECT_EQ(constraints_of(problem).multiplier_names().size(),
            static_cast<size_t>(constraints_of(problem).constraint_count()));
  EXPECT_EQ(problem.multipliers(start.t, start.q, start.p).size(),
            constraints_of(problem).constraint_count());
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
  const MassOperator mass(problem);
  const double speed = std::max(1.0, mass.solve(pushed.q, pushed.p).norm());
  pushed.p += 1e-6 * speed * mass.apply(pushed.q, G.row(0).transpose());
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

// A bead on a circle of radius 3.5 with mass 0.25 (non-unit scales), built without the registry:
// its constraints come from the interface alone. `claim` is passed to set_capabilities (a
// problem that tries to declare the bits itself), `time_dependent` to the interface.
class Bead final : public Problem, public HolonomicConstraints {
 public:
  Bead(bool constrained, unsigned claim, bool time_dependent)
      : constrained_(constrained), time_dependent_(time_dependent) {
    set_mass(Vec::Constant(2, 0.25));
    set_capabilities(kHessian | claim);
  }
  State initial_state() const override { return {0.0, Vec::Unit(2, 0) * 3.5, Vec::Zero(2)}; }
  double potential(const Vec&) const override { return 0.0; }
  void gradient(const Vec& q, Vec& g) const override { g = Vec::Zero(q.size()); }
  const HolonomicConstraints* as_constrained() const override {
    return constrained_ ? this : nullptr;
  }
  bool time_dependent() const override { return time_dependent_; }
  int constraint_count() const override { return 1; }
  void constraint(const Vec& q, Vec& g) const override { g = Vec::Constant(1, q.norm() - 3.5); }
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override {
    G.resize(1, 2);
    G.insert(0, 0) = q[0] / q.norm();
    G.insert(0, 1) = q[1] / q.norm();
    G.makeCompressed();
  }
  void constraint_curvature(const Vec&, const Vec&, Vec& c) const override { c = Vec::Zero(1); }
  void constraint_hessian(const Vec& q, const Vec&, SparseMatrix& K) const override {
    K.resize(q.size(), q.size());
  }

 private:
  bool constrained_, time_dependent_;
};

// One source of truth for kConstraints and kTimeDependentConstraints: as_constrained() and
// time_dependent() set them, and a problem that declares them itself is refused at construction.
TEST(ConstrainedProblems, CapabilitiesFollowTheQueryAndCannotBeClaimed) {
  EXPECT_TRUE(Bead(true, 0, false).has(kConstraints));
  EXPECT_FALSE(Bead(true, 0, false).has(kTimeDependentConstraints));
  EXPECT_TRUE(Bead(true, 0, true).has(kTimeDependentConstraints));
  EXPECT_EQ(capability_names(Bead(true, 0, true).capabilities()),
            (std::vector<std::string>{"hessian", "constraints", "time_dependent_constraints"}));
  EXPECT_FALSE(Bead(false, 0, true).has(kConstraints));
  EXPECT_FALSE(Bead(false, 0, true).has(kTimeDependentConstraints));
  EXPECT_THROW(Bead(false, kConstraints, false), std::logic_error);
  EXPECT_THROW(Bead(true, kTimeDependentConstraints, true), std::logic_error);
  // The helpers go through the query: on a problem without constraints they refuse by name.
  const Bead free_bead(false, 0, false);
  EXPECT_THROW(free_bead.constraint_residual(free_bead.initial_state().q), std::logic_error);
  const Bead bead(true, 0, false);
  EXPECT_EQ(bead.constraint_residual(bead.initial_state().q), 0.0);
  EXPECT_EQ(&constraints_of(bead), static_cast<const HolonomicConstraints*>(&bead));
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
  EXPECT_EQ(constraints_of(*chain).multiplier_names(),
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
}  // namespace constraints_test
}  // namespace geomint
