// Checks of the spring chain beyond the registry suite: the normal-mode frequencies and shapes
// against the closed forms of the discrete Laplacian, single-mode motion, the free chain's
// momentum and centre of mass, the FPU spring laws, and parameter validation.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cfloat>
#include <cmath>
#include <numbers>
#include <string>

#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace spring_chain_test {
namespace {

// Squared frequencies of M⁻¹K from the assembled Hessian, ascending.
Vec squared_frequencies(const Problem& problem) {
  SparseMatrix H;
  problem.hessian(problem.initial_state().q, H);
  const Eigen::MatrixXd scaled = Eigen::MatrixXd(H) / problem.mass()[0];
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues();
}

TEST(SpringChain, HessianSpectrumIsTheDiscreteLaplacians) {
  // ω_j = 2√(k/m) sin(jπ/(2(n+1))), j = 1..n (fixed); 2√(k/m) sin(jπ/(2n)), j = 0..n−1 (free).
  const int n = 7;
  const double k = 3, m = 2;
  const Vec fixed = squared_frequencies(*make_problem("spring_chain:n=7,stiffness=3,mass=2"));
  const Vec free =
      squared_frequencies(*make_problem("spring_chain:n=7,stiffness=3,mass=2,ends=free"));
  for (int j = 1; j <= n; ++j) {
    const double omega = 2 * std::sqrt(k / m) * std::sin(j * std::numbers::pi / (2 * (n + 1)));
    EXPECT_NEAR(fixed[j - 1], omega * omega, 1e-13) << "fixed mode " << j;
  }
  for (int j = 0; j < n; ++j) {
    const double omega = 2 * std::sqrt(k / m) * std::sin(j * std::numbers::pi / (2 * n));
    EXPECT_NEAR(free[j], omega * omega, 1e-13) << "free mode " << j;
  }
  // A wall on the left only: 2√(k/m) sin((2j − 1)π/(2(2n + 1))), j = 1..n.
  const Vec fixed_free =
      squared_frequencies(*make_problem("spring_chain:n=7,stiffness=3,mass=2,ends=fixed_free"));
  for (int j = 1; j <= n; ++j) {
    const double omega =
        2 * std::sqrt(k / m) * std::sin((2 * j - 1) * std::numbers::pi / (2 * (2 * n + 1)));
    EXPECT_NEAR(fixed_free[j - 1], omega * omega, 1e-13) << "fixed-free mode " << j;
  }
}

TEST(SpringChain, ModeShapedStartOscillatesInThatModeOnly) {
  // q(0) = A sin(i j π/(n+1)), v(0) = 0: q(t) = q(0) cos(ω_j t) exactly.
  const int n = 6, mode = 4;
  const double k = 1.5, m = 0.7, amplitude = 0.3;
  const auto problem = make_problem("spring_chain:n=6,mode=4,amplitude=0.3,stiffness=1.5,mass=0.7");
  const double omega = 2 * std::sqrt(k / m) * std::sin(mode * std::numbers::pi / (2 * (n + 1)));
  for (double t : {0.0, 0.9, 13.7, 250.3}) {
    const State state = problem->exact(t);
    for (int i = 0; i < n; ++i) {
      const double shape = amplitude * std::sin((i + 1) * mode * std::numbers::pi / (n + 1));
      EXPECT_NEAR(state.q[i], shape * std::cos(omega * t), 1e-14) << "t = " << t << ", i = " << i;
      EXPECT_NEAR(state.p[i], -m * omega * shape * std::sin(omega * t), 1e-14) << t;
    }
  }
}

TEST(SpringChain, FreeChainCentreOfMassDriftsUniformly) {
  const auto problem = make_problem("spring_chain:ends=free,n=5,mass=1.5,velocity=0.4,mode=2");
  ASSERT_TRUE(problem->has(kLinearMomentum));
  ASSERT_TRUE(problem->has(kExact));
  EXPECT_FALSE(make_problem("spring_chain")->has(kLinearMomentum));
  const State start = problem->initial_state();
  const double centre0 = start.q.mean();
  for (double t : {0.0, 3.3, 71.0}) {
    const State state = problem->exact(t);
    EXPECT_NEAR(problem->linear_momentum(state.q, state.p)[0], 5 * 1.5 * 0.4, 1e-14) << t;
    EXPECT_NEAR(state.q.mean(), centre0 + 0.4 * t, 1e-13) << t;
  }
  // Forces between the masses only: the gradient sums to zero anywhere.
  Vec g;
  problem->gradient(Vec::LinSpaced(5, -0.3, 0.9).array().square(), g);
  EXPECT_NEAR(g.sum(), 0.0, 1e-15);
}

TEST(SpringChain, FpuSpringLawsMatchTheirPotentials) {
  // Two masses between walls: three springs with extensions q1, q2 − q1, −q2.
  Vec q(2);
  q << 0.3, -0.2;
  const double d[3] = {0.3, -0.5, 0.2};
  const double k = 2, alpha = 0.7, beta = 1.9;
  double alpha_sum = 0, beta_sum = 0;
  for (double x : d) {
    alpha_sum += k * x * x / 2 + alpha * x * x * x / 3;
    beta_sum += k * x * x / 2 + beta * x * x * x * x / 4;
  }
  const auto fpu_alpha = make_problem("spring_chain:n=2,model=fpu_alpha,alpha=0.7,stiffness=2");
  const auto fpu_beta = make_problem("spring_chain:n=2,model=fpu_beta,beta=1.9,stiffness=2");
  EXPECT_NEAR(fpu_alpha->potential(q), alpha_sum, 1e-15);
  EXPECT_NEAR(fpu_beta->potential(q), beta_sum, 1e-15);
  // Nonlinear chains have no normal-mode solution.
  EXPECT_FALSE(fpu_alpha->has(kExact));
  EXPECT_FALSE(fpu_beta->has(kExact));
  EXPECT_THROW(fpu_beta->exact(1.0), std::logic_error);
}

TEST(SpringChain, RejectsModeOutsideTheChain) {
  for (const char* spec : {"spring_chain:n=4,mode=5", "spring_chain:n=4,ends=free,mode=4"}) {
    EXPECT_TRUE(test::input_error_names(make_problem, spec, "mode="));
  }
  EXPECT_THROW(make_problem("spring_chain:model=toda"), InputError);
  EXPECT_THROW(make_problem("spring_chain:ends=periodic"), InputError);
  EXPECT_THROW(make_problem("spring_chain:n=1"), InputError);
}

}  // namespace
}  // namespace spring_chain_test
}  // namespace geomint
