// The O(n) recursions of the planar articulated problems (problems/articulated.hpp) against their
// dense forms, an independent Cartesian kinetic energy and finite differences, at n ≤ 16; RK4
// trajectories on the recursive and dense forms; rod_chain's joint form against its old dense M(θ).
#include "problems/articulated.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace articulated_test {
namespace {

double inf_norm(const Eigen::MatrixXd& x) { return x.size() == 0 ? 0.0 : x.cwiseAbs().maxCoeff(); }

// The registry's articulated problems (defaults and variants) plus rod_chain's joint form, the
// ones small enough for the dense comparison.
std::vector<std::string> articulated_specs() {
  std::vector<std::string> specs;
  for (const auto& spec : problem_test_specs()) {
    const bool articulated =
        spec.rfind("articulated_chain", 0) == 0 || spec.rfind("rope", 0) == 0 ||
        spec.rfind("branching", 0) == 0 ||
        (spec.rfind("rod_chain", 0) == 0 && spec.find("coordinates=joint") != std::string::npos);
    if (articulated && make_problem(spec)->dof() <= 16) specs.push_back(spec);
  }
  return specs;
}

// A state away from the initial one: angles and velocities of both signs and sizes.
Vec random_vector(int n, unsigned seed, double scale) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(-scale, scale);
  Vec x(n);
  for (auto& value : x) value = uniform(generator);
  return x;
}

// Only the dense members of `system`, with the base class's dense defaults for the mass operator
// and the gyroscopic force (T_q = ½Dᵀv from the dense ∂(Mv)/∂q): the dense general-Lagrangian form
// of the same mechanics.
class DenseView final : public LagrangianSystem {
 public:
  explicit DenseView(const LagrangianSystem& system) : system_(system) {}
  void mass_matrix(const Vec& q, DenseMatrix& M) const override { system_.mass_matrix(q, M); }
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override {
    DenseMatrix D;
    system_.mass_velocity_jacobian(q, v, D);
    T_q = 0.5 * D.transpose() * v;
  }
  void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const override {
    system_.mass_velocity_jacobian(q, v, D);
  }
  void kinetic_hessian(const Vec& q, const Vec& v, DenseMatrix& T_qq) const override {
    system_.kinetic_hessian(q, v, T_qq);
  }
  double potential(const Vec& q) const override { return system_.potential(q); }
  void gradient(const Vec& q, Vec& g) const override { system_.gradient(q, g); }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    system_.potential_hessian(q, K);
  }

 private:
  const LagrangianSystem& system_;
};

// rod_chain's joint form as it was written before it ran on the recursions: point masses at the
// rod ends, M(θ)_ij = μ_ij l_i l_j cos(θ_i − θ_j) with μ_ij the mass at and below max(i, j).
class OldRodChainJoint final : public LagrangianSystem {
 public:
  OldRodChainJoint(const Vec& node_mass, const Vec& length, double gravity) {
    const int n = static_cast<int>(node_mass.size());
    Vec tail_mass(n);
    double sum = 0;
    for (int i = n - 1; i >= 0; --i) tail_mass[i] = sum += node_mass[i];
    coupling_.resize(n, n);
    for (int i = 0; i < n; ++i) {
      for (int j = i; j < n; ++j) {
        coupling_(i, j) = coupling_(j, i) = tail_mass[j] * length[i] * length[j];
      }
    }
    weight_ = gravity * tail_mass.cwiseProduct(length);
  }
  void mass_matrix(const Vec& q, DenseMatrix& M) const override {
    const int n = static_cast<int>(q.size());
    M.resize(n, n);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) M(i, j) = coupling_(i, j) * std::cos(q[i] - q[j]);
    }
  }
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override {
    const int n = static_cast<int>(q.size());
    T_q.resize(n);
    for (int a = 0; a < n; ++a) {
      double sum = 0;
      for (int j = 0; j < n; ++j) sum += coupling_(a, j) * std::sin(q[a] - q[j]) * v[j];
      T_q[a] = -v[a] * sum;
    }
  }
  void mass_velocity_jacobian(const Vec& q, const Vec&, DenseMatrix& D) const override {
    D = DenseMatrix::Zero(q.size(), q.size());  // not used by the RK4 comparison
  }
  void kinetic_hessian(const Vec& q, const Vec&, DenseMatrix& T_qq) const override {
    T_qq = DenseMatrix::Zero(q.size(), q.size());  // not used by the RK4 comparison
  }
  double potential(const Vec& q) const override { return -weight_.dot(q.array().cos().matrix()); }
  void gradient(const Vec& q, Vec& g) const override {
    g = weight_.cwiseProduct(q.array().sin().matrix());
  }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    K = weight_.cwiseProduct(q.array().cos().matrix()).asDiagonal();
  }

 private:
  DenseMatrix coupling_;
  Vec weight_;
};

// Classical RK4 on Hamilton's equations of a general L, (q̇, ṗ) = (v(q, p), L_q(q, v)): the
// same route as Problem::first_order_rhs, on any LagrangianSystem.
State rk4_steps(const LagrangianSystem& system, State state, double h, int steps) {
  const auto rhs = [&](const Vec& q, const Vec& p, Vec& dq, Vec& dp) {
    dq = system.velocity(q, p);
    system.lagrangian_q(q, dq, dp);
  };
  Vec k_q[4], k_p[4];
  for (int s = 0; s < steps; ++s) {
    rhs(state.q, state.p, k_q[0], k_p[0]);
    rhs(state.q + h / 2 * k_q[0], state.p + h / 2 * k_p[0], k_q[1], k_p[1]);
    rhs(state.q + h / 2 * k_q[1], state.p + h / 2 * k_p[1], k_q[2], k_p[2]);
    rhs(state.q + h * k_q[2], state.p + h * k_p[2], k_q[3], k_p[3]);
    state.q += h / 6 * (k_q[0] + 2 * k_q[1] + 2 * k_q[2] + k_q[3]);
    state.p += h / 6 * (k_p[0] + 2 * k_p[1] + 2 * k_p[2] + k_p[3]);
    state.t += h;
  }
  return state;
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string out;
  for (char c : info.param) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

class ArticulatedTest : public ::testing::TestWithParam<std::string> {};

// M(θ)v and M(θ)⁻¹p by the recursions equal the dense M(θ)'s product and Cholesky solve; the
// energy is ½vᵀMv + V; ∂T/∂θ is the dense ½Dᵀv; M(θ) itself is JᵀmJ + diag(I) from the links'
// Cartesian centres of mass (J by central differences), an independent derivation.
TEST_P(ArticulatedTest, RecursionsAgreeWithDenseForm) {
  const auto problem = make_problem(GetParam());
  const LagrangianSystem& system = *problem->as_lagrangian();
  const int n = problem->dof();
  const State start = problem->initial_state();
  for (const auto& [theta, velocity] :
       {std::pair{start.q, system.velocity(start.q, start.p)},
        std::pair{random_vector(n, 7, 3.0), random_vector(n, 11, 2.0)}}) {
    DenseMatrix M;
    system.mass_matrix(theta, M);
    const double scale = inf_norm(M) * std::max(1.0, inf_norm(velocity));
    Vec product, solved, T_q;
    system.apply_mass(theta, velocity, product);
    EXPECT_LE(inf_norm(product - M * velocity), 1e-13 * scale) << "apply_mass";
    system.solve_mass(theta, product, solved);
    const Vec dense_solved = M.llt().solve(product);
    EXPECT_LE(inf_norm(solved - dense_solved), 1e-11 * std::max(1.0, inf_norm(velocity)))
        << "solve_mass";
    const DenseView dense(system);
    system.kinetic_gradient(theta, velocity, T_q);
    Vec dense_T_q;
    dense.kinetic_gradient(theta, velocity, dense_T_q);
    EXPECT_LE(inf_norm(T_q - dense_T_q), 1e-13 * scale * std::max(1.0, inf_norm(velocity)))
        << "kinetic_gradient";
    const Vec p = product;
    EXPECT_NEAR(system.hamiltonian(theta, p),
                0.5 * velocity.dot(M * velocity) + system.potential(theta),
                1e-13 * (scale * inf_norm(velocity) + std::abs(system.potential(theta))))
        << "energy";
    // Cartesian check: T = ½ Σ m_i |V_i|² + ½ Σ I_i u_i² with V = J u.
    const auto* tree_system = dynamic_cast<const articulated::PlanarTreeLagrangian*>(&system);
    ASSERT_NE(tree_system, nullptr);
    const auto& tree = tree_system->dynamics().tree();
    const auto centres = [&](const Vec& angles) {
      Vec xy(2 * n);
      Eigen::Matrix2Xd joint(2, n);
      for (int a = 0; a < n; ++a) {
        const int up = tree.parent[a];
        const Eigen::Vector2d e(std::sin(angles[a]), -std::cos(angles[a]));
        joint.col(a) =
            up < 0 ? Eigen::Vector2d::Zero()
                   : Eigen::Vector2d(joint.col(up) +
                                     tree.length[up] * Eigen::Vector2d(std::sin(angles[up]),
                                                                       -std::cos(angles[up])));
        xy.segment(2 * a, 2) = joint.col(a) + tree.com[a] * e;
      }
      return xy;
    };
    DenseMatrix J(2 * n, n);
    for (int j = 0; j < n; ++j) {
      Vec plus = theta, minus = theta;
      plus[j] += 1e-6;
      minus[j] -= 1e-6;
      J.col(j) = (centres(plus) - centres(minus)) / 2e-6;
    }
    Vec point_mass(2 * n);
    for (int a = 0; a < n; ++a) point_mass.segment(2 * a, 2).setConstant(tree.mass[a]);
    DenseMatrix cartesian = J.transpose() * point_mass.asDiagonal() * J;
    cartesian.diagonal() += tree.inertia;
    EXPECT_LE(inf_norm(cartesian - M), 1e-8 * inf_norm(M)) << "M(θ) against JᵀmJ + I";
  }
}

// A few RK4 steps on the recursive form and on the dense form (dense M, Cholesky solve, dense
// ∂T/∂θ) agree to round-off.
TEST_P(ArticulatedTest, RecursiveAndDenseTrajectoriesAgree) {
  const auto problem = make_problem(GetParam());
  const LagrangianSystem& system = *problem->as_lagrangian();
  const DenseView dense(system);
  const State start = problem->initial_state();
  const double h = problem->default_dt();
  const State recursive = rk4_steps(system, start, h, 20);
  const State reference = rk4_steps(dense, start, h, 20);
  EXPECT_LE(inf_norm(recursive.q - reference.q), 1e-12 * std::max(1.0, inf_norm(reference.q)));
  EXPECT_LE(inf_norm(recursive.p - reference.p), 1e-12 * std::max(1.0, inf_norm(reference.p)));
}

INSTANTIATE_TEST_SUITE_P(Registry, ArticulatedTest, ::testing::ValuesIn(articulated_specs()),
                         test_name);

TEST(Articulated, RegistryHasTheArticulatedProblems) {
  const auto specs = articulated_specs();
  for (const std::string name : {"articulated_chain", "rope", "branching"}) {
    EXPECT_TRUE(std::any_of(specs.begin(), specs.end(), [&](const std::string& spec) {
      return spec.rfind(name, 0) == 0;
    })) << name;
  }
}

// rod_chain:coordinates=joint on the recursions: its RK4 steps agree to round-off with the dense
// M(θ)_ij = μ_ij l_i l_j cos(θ_i − θ_j) it used to assemble, for the same chain.
TEST(Articulated, RodChainJointMatchesItsDenseFormula) {
  const auto problem = make_problem(
      "rod_chain:coordinates=joint,n=5,mass=2,mass_ratio=0.7,length=0.7,length_ratio=1.3,"
      "gravity=2.5,theta1=0.3,theta2=-1.1,theta3=2.5,theta4=0.4,theta5=-2,omega=0.4");
  Vec node_mass(5), length(5);
  for (int i = 0; i < 5; ++i) {
    node_mass[i] = 2 * std::pow(0.7, i);
    length[i] = 0.7 * std::pow(1.3, i);
  }
  const OldRodChainJoint old(node_mass, length, 2.5);
  const State start = problem->initial_state();
  EXPECT_LE(inf_norm(start.p - old.momentum(start.q, Vec::Constant(5, 0.4))),
            1e-13 * inf_norm(start.p));
  const State recursive = rk4_steps(*problem->as_lagrangian(), start, 0.01, 50);
  const State reference = rk4_steps(old, start, 0.01, 50);
  EXPECT_LE(inf_norm(recursive.q - reference.q), 1e-12 * inf_norm(reference.q));
  EXPECT_LE(inf_norm(recursive.p - reference.p), 1e-12 * inf_norm(reference.p));
}

// Without gravity the angular momentum about the pivot, Σ p, is the Noether momentum of rotating
// the whole tree: the problem declares it, and ∂L/∂θ sums to zero (so ṗ sums to zero).
TEST(Articulated, AngularMomentumAboutThePivotWithoutGravity) {
  for (const std::string spec :
       {"articulated_chain:n=6,gravity=0,omega=0.5,thetas=0/0.5/1/1.5/2/2.5",
        "branching:parents=0/0/1/2,gravity=0,omega=0.7,thetas=0/3/0.5/2.5"}) {
    const auto problem = make_problem(spec);
    ASSERT_TRUE(problem->has(kAngularMomentum)) << spec;
    const LagrangianSystem& system = *problem->as_lagrangian();
    const Vec theta = random_vector(problem->dof(), 3, 3.0);
    const Vec velocity = random_vector(problem->dof(), 5, 2.0);
    Vec L_q;
    system.lagrangian_q(theta, velocity, L_q);
    EXPECT_LE(std::abs(L_q.sum()), 1e-13 * L_q.cwiseAbs().sum()) << spec;
  }
  EXPECT_FALSE(make_problem("articulated_chain")->has(kAngularMomentum));
}

// Long chains run: the recursions have no dense object, so n = 4096 is cheap.
TEST(Articulated, LongestRopeSolvesItsMass) {
  const auto problem = make_problem("rope:n=4096");
  const LagrangianSystem& system = *problem->as_lagrangian();
  const State start = problem->initial_state();
  const Vec velocity = system.velocity(start.q, start.p);
  EXPECT_LE(inf_norm(velocity), 1e-12);  // released at rest
  const Vec u = random_vector(4096, 1, 1.0);
  Vec p, back;
  system.apply_mass(start.q, u, p);
  system.solve_mass(start.q, p, back);
  EXPECT_LE(inf_norm(back - u), 1e-8);
}

// Bad input: an exit-2 InputError naming the parameter and what is allowed.
TEST(Articulated, BadInputNamesParameterAndRange) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"articulated_chain:n=0", "n"},
      {"articulated_chain:n=4097", "4096"},
      {"rope:n=5000", "4096"},
      {"articulated_chain:mass=0", "mass"},
      {"articulated_chain:length=-1", "length"},
      {"articulated_chain:inertia=0", "inertia"},
      {"articulated_chain:n=3,masses=1/2", "exactly n = 3"},
      {"articulated_chain:n=3,lengths=1/0/2", "lengths entry 2"},
      {"articulated_chain:n=2,inertias=1/-1", "inertias entry 2"},
      {"articulated_chain:n=2,thetas=1/2/3", "thetas has 3 entries"},
      {"articulated_chain:n=2,omegas=1", "omegas has 1 entries"},
      {"branching:parents=0/2", "parents entry 2"},
      {"branching:parents=0/0.5", "parents entry 2"},
      {"rod_chain:coordinates=joint,n=5000", "4096"},
  };
  for (const auto& [spec, needle] : cases) {
    try {
      make_problem(spec);
      ADD_FAILURE() << spec << " was accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(needle), std::string::npos)
          << spec << ": " << error.what();
    }
  }
}

}  // namespace
}  // namespace articulated_test
}  // namespace geomint
