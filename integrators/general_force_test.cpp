// A non-conservative force on an unconstrained problem of the general kind through del's and hp's
// shared step (integrators/discrete_lagrangian.cpp, hamilton_pontryagin.cpp; discrete
// Lagrange–d'Alembert, docs/METHOD.md §2): no problem of the catalogue is of that kind and forced,
// so these local damped oscillators pin the path, dense and matrix-free.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/force.hpp"
#include "problems/lagrangian.hpp"

namespace geomint {
namespace general_force_test {
namespace {

// M q̈ + C q̇ + K q = 0 on two dof at non-unit, unequal scales: the masses differ by a factor 6
// and the damping is light on one mode and heavy on the other.
struct Coefficients {
  Eigen::Matrix2d mass, stiffness, damping;
};

Coefficients coefficients(bool diagonal_mass) {
  Coefficients c;
  c.mass << 2.5, diagonal_mass ? 0.0 : 0.6, diagonal_mass ? 0.0 : 0.6, 0.4;
  c.stiffness << 30.0, -8.0, -8.0, 12.0;
  c.damping << 0.3, 0.1, 0.1, 1.7;
  return c;
}

const Vec kQ0 = (Vec(2) << 0.02, -0.035).finished();
const Vec kV0 = (Vec(2) << 0.4, 0.9).finished();

// F = −Cv, the force both kinds below take.
class LinearDamping : public NonConservativeForce {
 public:
  explicit LinearDamping(const Eigen::Matrix2d& damping) : damping_(damping) {}
  bool has_force_jacobian() const override { return true; }
  void force(const Vec&, const Vec& v, double, Vec& f) const override { f = -damping_ * v; }
  void force_jacobian_v(const Vec&, const Vec&, double, SparseMatrix& C) const override {
    C = damping_.sparseView();
  }

 private:
  Eigen::Matrix2d damping_;
};

// The general kind: L = ½vᵀMv − ½qᵀKq with M constant but given as M(q) (mass_matrix), F = −Cv.
// `recursive` declares the mass an O(n) operator, so that del and hp take their matrix-free
// solve (operator_del_solve.hpp) as on the articulated chains.
class GeneralDampedOscillator final : public Problem,
                                      public LagrangianSystem,
                                      public LinearDamping {
 public:
  GeneralDampedOscillator(const Coefficients& c, bool recursive)
      : LinearDamping(c.damping), c_(c), recursive_(recursive) {
    set_dof(2);
    set_capabilities(0);
    set_defaults(0.01, 1.0);
  }
  const LagrangianSystem* as_lagrangian() const override { return this; }
  const NonConservativeForce* as_forced() const override { return this; }
  State initial_state() const override { return {0.0, kQ0, c_.mass * kV0}; }

  void mass_matrix(const Vec&, DenseMatrix& M) const override { M = c_.mass; }
  void kinetic_gradient(const Vec&, const Vec&, Vec& T_q) const override { T_q = Vec::Zero(2); }
  void mass_velocity_jacobian(const Vec&, const Vec&, DenseMatrix& D) const override {
    D = DenseMatrix::Zero(2, 2);
  }
  void kinetic_hessian(const Vec&, const Vec&, DenseMatrix& T_qq) const override {
    T_qq = DenseMatrix::Zero(2, 2);
  }
  double potential(const Vec& q) const override { return 0.5 * q.dot(c_.stiffness * q); }
  void gradient(const Vec& q, Vec& g) const override { g = c_.stiffness * q; }
  void potential_hessian(const Vec&, DenseMatrix& K) const override { K = c_.stiffness; }
  bool mass_is_recursive() const override { return recursive_; }

 private:
  Coefficients c_;
  bool recursive_;
};

// The same system on the separable kind (constant diagonal M), the path the catalogue's damped
// problems take.
class SeparableDampedOscillator final : public Problem, public LinearDamping {
 public:
  explicit SeparableDampedOscillator(const Coefficients& c) : LinearDamping(c.damping), c_(c) {
    set_mass(c.mass.diagonal());
    set_capabilities(kHessian);
    set_defaults(0.01, 1.0);
  }
  const NonConservativeForce* as_forced() const override { return this; }
  State initial_state() const override { return {0.0, kQ0, c_.mass.diagonal().cwiseProduct(kV0)}; }
  double potential(const Vec& q) const override { return 0.5 * q.dot(c_.stiffness * q); }
  void gradient(const Vec& q, Vec& g) const override { g = c_.stiffness * q; }
  void hessian(const Vec&, SparseMatrix& H) const override { H = c_.stiffness.sparseView(); }

 private:
  Coefficients c_;
};

// The state after `steps` steps of h, or the failure's reason.
struct RunEnd {
  State state;
  std::string failure;
  Counters counters;
};

RunEnd run(const std::string& method, const Problem& problem, double h, int steps) {
  auto integrator = make_integrator(method);
  State state = problem.initial_state();
  integrator->reset(problem, state, h);
  for (int k = 0; k < steps; ++k) {
    const StepStatus status = integrator->step(problem, state, h);
    if (!status.ok) return {state, status.reason, integrator->counters()};
  }
  return {state, "", integrator->counters()};
}

// The exact (q, p) at t to round-off: y' = Ay for y = (q, v), A = [0 I; −M⁻¹K −M⁻¹C], by classical
// RK4 with 2¹⁶ steps (its error, ~(t/2¹⁶)⁴·|A|⁵·t ≈ 1e-13 here, is far below the errors tested),
// written out here so that the reference shares no code with the methods; p = Mv.
State exact(const Coefficients& c, double t) {
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  A.topRightCorner<2, 2>() = Eigen::Matrix2d::Identity();
  const Eigen::Matrix2d inverse_mass = c.mass.inverse();
  A.bottomLeftCorner<2, 2>() = -inverse_mass * c.stiffness;
  A.bottomRightCorner<2, 2>() = -inverse_mass * c.damping;
  Eigen::Vector4d y;
  y << kQ0, kV0;
  constexpr int kSteps = 1 << 16;
  const double h = t / kSteps;
  for (int k = 0; k < kSteps; ++k) {
    const Eigen::Vector4d k1 = A * y;
    const Eigen::Vector4d k2 = A * (y + (h / 2) * k1);
    const Eigen::Vector4d k3 = A * (y + (h / 2) * k2);
    const Eigen::Vector4d k4 = A * (y + h * k3);
    y += (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return {t, y.head<2>(), c.mass * y.tail<2>()};
}

double relative_error(const State& state, const State& reference) {
  const double difference =
      std::sqrt((state.q - reference.q).squaredNorm() + (state.p - reference.p).squaredNorm());
  return difference / std::sqrt(reference.q.squaredNorm() + reference.p.squaredNorm());
}

// The methods and the order each forced step has: the split force (the default) keeps the
// midpoint rule's 2, one slot only or α ≠ ½ gives 1.
struct ForcedMethod {
  std::string spec;
  double order;
};
const std::vector<ForcedMethod> kMethods = {{"del", 2.0},
                                            {"hp", 2.0},
                                            {"hp:solver=newton", 2.0},
                                            {"del:force_slot=minus", 1.0},
                                            {"del:force_slot=plus", 1.0},
                                            {"hp:alpha=0.3", 1.0}};

// With a diagonal M the general kind's step is the separable kind's equation written through
// L_v and L_q: the two paths agree to round-off, the matrix-free solve as well as the dense one.
TEST(GeneralKindForce, MatchesTheSeparableKindStep) {
  const Coefficients c = coefficients(/*diagonal_mass=*/true);
  const SeparableDampedOscillator separable(c);
  for (const bool recursive : {false, true}) {
    const GeneralDampedOscillator general(c, recursive);
    ASSERT_EQ(general.kind(), ProblemKind::kLagrangian);
    ASSERT_TRUE(general.has(kForce));
    for (const ForcedMethod& forced : kMethods) {
      SCOPED_TRACE(forced.spec + (recursive ? " (matrix-free)" : " (dense)"));
      const RunEnd on_general = run(forced.spec, general, 0.01, 300);
      const RunEnd on_separable = run(forced.spec, separable, 0.01, 300);
      ASSERT_EQ(on_general.failure, "");
      ASSERT_EQ(on_separable.failure, "");
      // The matrix-free solve factorises nothing; the dense one factorises its Jacobian.
      if (recursive) {
        EXPECT_EQ(on_general.counters.factorizations, 0);
      } else {
        EXPECT_GT(on_general.counters.factorizations, 0);
      }
      EXPECT_LE(relative_error(on_general.state, on_separable.state), 1e-11);
      // The damping did act: the state is far from the undamped one's scale.
      EXPECT_LT(on_general.state.q.norm() + on_general.state.p.norm(),
                0.5 * (kQ0.norm() + (c.mass * kV0).norm()));
    }
  }
}

// With a coupled M (no separable twin) the forced step converges to the exact damped motion at
// its order: halving h divides the error at t = 3 by 4 for the second-order forcings, by 2 for
// the first-order ones, and the error at h = 1/200 is small.
TEST(GeneralKindForce, ConvergesToTheExactDampedMotionWithACoupledMass) {
  const Coefficients c = coefficients(/*diagonal_mass=*/false);
  const State reference = exact(c, 3.0);
  for (const bool recursive : {false, true}) {
    const GeneralDampedOscillator general(c, recursive);
    for (const auto& [method, expected] : kMethods) {
      SCOPED_TRACE(method + (recursive ? " (matrix-free)" : " (dense)"));
      const RunEnd coarse = run(method, general, 0.01, 300);
      const RunEnd fine = run(method, general, 0.005, 600);
      ASSERT_EQ(coarse.failure, "");
      ASSERT_EQ(fine.failure, "");
      const double coarse_error = relative_error(coarse.state, reference);
      const double fine_error = relative_error(fine.state, reference);
      const double order = std::log2(coarse_error / fine_error);
      EXPECT_NEAR(order, expected, 0.05) << coarse_error << " -> " << fine_error;
      EXPECT_LT(fine_error, expected == 2.0 ? 1e-3 : 5e-2);
    }
  }
}

}  // namespace
}  // namespace general_force_test
}  // namespace geomint
