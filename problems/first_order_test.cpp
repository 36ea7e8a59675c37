// The first-order-only problems (FirstOrderSystem, capability kFirstOrderOnly, docs/DESIGN.md §2):
// sizes, the Test Set's initial values and end references, and rhs_jacobian against central
// differences of rhs, for every registered problem that offers the interface.
#include "problems/first_order.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <vector>

#include "problems/problem.hpp"

namespace geomint {
namespace first_order_test {
namespace {

std::vector<std::string> first_order_specs() {
  std::vector<std::string> specs;
  for (const auto& spec : problem_test_specs()) {
    if (make_problem(spec)->has(kFirstOrderOnly)) specs.push_back(spec);
  }
  return specs;
}

TEST(FirstOrderProblems, TheRegistryHasThem) {
  const auto specs = first_order_specs();
  EXPECT_GE(specs.size(), 3u);  // van_der_pol, its variant, robertson
}

TEST(FirstOrderProblems, StateIsYAloneAndThereIsNoEnergy) {
  for (const auto& spec : first_order_specs()) {
    const auto problem = make_problem(spec);
    const State start = problem->initial_state();
    EXPECT_EQ(start.q.size(), problem->dof()) << spec;
    EXPECT_EQ(start.p.size(), 0) << spec;
    EXPECT_EQ(problem->first_order_size(), problem->dof()) << spec;
    EXPECT_TRUE(std::isnan(problem->energy(start.q, start.p))) << spec;
    Vec g;
    EXPECT_THROW(problem->gradient(start.q, g), std::logic_error) << spec;
    Vec y(problem->first_order_size());
    problem->pack_first_order(start, y.data());
    State back;
    problem->unpack_first_order(y.data(), back);
    EXPECT_EQ(back.q, start.q) << spec;
    EXPECT_EQ(back.p.size(), 0) << spec;
  }
}

// Columns of ∂f/∂y by Richardson-extrapolated central differences of rhs at y0 and at a few
// points along the way (y0 moved by a fraction of f(y0)), relative to the Jacobian's size.
TEST(FirstOrderProblems, RhsJacobianMatchesFiniteDifferences) {
  for (const auto& spec : first_order_specs()) {
    const auto problem = make_problem(spec);
    const FirstOrderSystem& system = first_order_system_of(*problem);
    const Vec y0 = problem->initial_state().q;
    Vec f0;
    problem->first_order_rhs(0.0, y0, f0);
    const double scale = std::max(y0.lpNorm<Eigen::Infinity>(), 1e-3);
    std::vector<Vec> points = {y0, y0 + Vec::Constant(y0.size(), 1e-3 * scale),
                               y0 - 0.1 * scale * f0 / std::max(f0.norm(), 1e-300) +
                                   Vec::LinSpaced(y0.size(), 0.01, 0.03) * scale};
    for (const Vec& y : points) {
      SparseMatrix J;
      problem->first_order_jacobian(0.0, y, J);
      ASSERT_EQ(J.rows(), y.size()) << spec;
      ASSERT_EQ(J.cols(), y.size()) << spec;
      const Eigen::MatrixXd dense(J);
      const double size = dense.cwiseAbs().maxCoeff();
      const double h = 1e-5 * scale;
      for (int j = 0; j < y.size(); ++j) {
        Vec plus = y, minus = y, plus2 = y, minus2 = y;
        plus[j] += h, minus[j] -= h, plus2[j] += 2 * h, minus2[j] -= 2 * h;
        Vec fp, fm, fp2, fm2;
        system.rhs(0.0, plus, fp);
        system.rhs(0.0, minus, fm);
        system.rhs(0.0, plus2, fp2);
        system.rhs(0.0, minus2, fm2);
        const Vec column = (8 * (fp - fm) - (fp2 - fm2)) / (12 * h);
        for (int i = 0; i < y.size(); ++i) {
          EXPECT_NEAR(dense(i, j), column[i], 1e-7 * size)
              << spec << " entry (" << i << ", " << j << ") at y = " << y.transpose();
        }
      }
    }
  }
}

TEST(FirstOrderProblems, TestSetInitialValuesAndReferences) {
  const auto vdpol = make_problem("van_der_pol");
  EXPECT_EQ(vdpol->spec(), "van_der_pol:mu=1000");
  EXPECT_EQ(vdpol->initial_state().q, (Vec(2) << 2.0, 0.0).finished());
  EXPECT_EQ(vdpol->default_t_end(), 2.0);
  ASSERT_TRUE(vdpol->has(kEndReference));
  EXPECT_EQ(vdpol->end_reference_time(), 2.0);
  EXPECT_EQ(vdpol->end_reference().q[1], -0.8928097010247975);
  // ε = 1/μ² = 1e-6: y2' = ((1 − y1²) y2 − y1)/ε at (2, 0) is −2e6.
  Vec f;
  vdpol->first_order_rhs(0.0, vdpol->initial_state().q, f);
  EXPECT_EQ(f[1], -2.0 / 1.0e-6);
  EXPECT_FALSE(make_problem("van_der_pol:mu=10")->has(kEndReference));
  // μ = 10⁶: ε = 1e-12, with a computed reference at t = 2.
  const auto stiffest = make_problem("van_der_pol:mu=1e6");
  EXPECT_TRUE(stiffest->has(kEndReference));
  stiffest->first_order_rhs(0.0, stiffest->initial_state().q, f);
  EXPECT_EQ(f[1], -2.0 / 1.0e-12);

  const auto rober = make_problem("robertson");
  EXPECT_EQ(rober->initial_state().q, (Vec(3) << 1.0, 0.0, 0.0).finished());
  EXPECT_EQ(rober->default_t_end(), 1e11);
  EXPECT_EQ(rober->end_reference_time(), 1e11);
  EXPECT_EQ(rober->end_reference().q[1], 0.8333360770334713e-13);
  // Mass conservation: Σ y' = 0.
  rober->first_order_rhs(0.0, (Vec(3) << 0.5, 1e-5, 0.3).finished(), f);
  EXPECT_NEAR(f.sum(), 0.0, 1e-12);
}

// Exponential decay y' = −k y with k = 250 and y0 = 3e-4 (non-unit scales), built without the
// registry and without FirstOrderProblem: its kind comes from the interface alone. `offer` makes
// as_first_order() return it, `claim` is passed to set_capabilities (a problem that tries to
// declare the bit itself).
class Decay final : public Problem, public FirstOrderSystem {
 public:
  Decay(bool offer, unsigned claim) : offer_(offer) {
    set_mass(Vec::Ones(1));
    set_capabilities(kExact | claim);
  }
  const FirstOrderSystem* as_first_order() const override { return offer_ ? this : nullptr; }
  State initial_state() const override { return {0.0, Vec::Constant(1, 3e-4), Vec()}; }
  double potential(const Vec&) const override { return 0.0; }
  void gradient(const Vec& q, Vec& g) const override { g = Vec::Zero(q.size()); }
  void rhs(double, const Vec& y, Vec& ydot) const override { ydot = -250.0 * y; }
  void rhs_jacobian(double, const Vec&, SparseMatrix& J) const override {
    J.resize(1, 1);
    J.insert(0, 0) = -250.0;
    J.makeCompressed();
  }

 private:
  bool offer_;
};

// One source of truth for kFirstOrderOnly and the kind kFirstOrder: as_first_order() sets them,
// the first-order view goes through it, and a problem that declares the bit is refused.
TEST(FirstOrderProblems, KindFollowsTheQueryAndCannotBeClaimed) {
  const Decay decay(true, 0);
  EXPECT_TRUE(decay.has(kFirstOrderOnly));
  EXPECT_EQ(decay.kind(), ProblemKind::kFirstOrder);
  EXPECT_EQ(capability_names(decay.capabilities()),
            (std::vector<std::string>{"exact", "first_order_only"}));
  EXPECT_EQ(decay.first_order_size(), 1);
  Vec ydot;
  decay.first_order_rhs(0.0, decay.initial_state().q, ydot);
  EXPECT_EQ(ydot[0], -250.0 * 3e-4);
  SparseMatrix J;
  decay.first_order_jacobian(0.0, decay.initial_state().q, J);
  EXPECT_EQ(J.coeff(0, 0), -250.0);
  EXPECT_EQ(&first_order_system_of(decay), static_cast<const FirstOrderSystem*>(&decay));
  // Declining the interface: a separable problem with y = (q, p), whatever the class derives from.
  const Decay declined(false, 0);
  EXPECT_FALSE(declined.has(kFirstOrderOnly));
  EXPECT_EQ(declined.kind(), ProblemKind::kSeparable);
  EXPECT_EQ(declined.first_order_size(), 2);
  EXPECT_THROW(first_order_system_of(declined), std::logic_error);
  try {
    Decay claimed(false, kFirstOrderOnly);
    ADD_FAILURE() << "set_capabilities accepted kFirstOrderOnly";
  } catch (const std::logic_error& error) {
    EXPECT_NE(std::string(error.what()).find("first_order_only"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(Decay(true, kFirstOrderOnly), std::logic_error);
}

}  // namespace
}  // namespace first_order_test
}  // namespace geomint
