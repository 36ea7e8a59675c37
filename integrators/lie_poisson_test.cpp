// The Lie–Poisson splitting of the free rigid body (integrators/lie_poisson.cpp) at non-unit
// moments: the Casimir |Π|², the spatial angular momentum and QᵀQ = I to round-off, the orders 2
// and 4 on Π against the elliptic solution (problems/rigid_body.hpp), the same Π from both
// problems' views of the state, and applicable() refusing every other problem with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/rigid_body.hpp"

namespace geomint {
namespace lie_poisson_test {
namespace {

// Away from the separatrix (|Π|² > 2E I₂ here), non-unit and unequal moments.
const std::string kMoments = "I1=1.7,I2=2.9,I3=4.1,omega1=0.9,omega2=0.35,omega3=-0.7";

Eigen::Matrix3d attitude_of(const Vec& q) {
  Eigen::Matrix3d Q;
  for (int k = 0; k < 3; ++k) Q.col(k) = q.segment<3>(3 * k);
  return Q;
}

// Π after `steps` steps of h from the problem's initial state.
Eigen::Vector3d body_momentum_after(const std::string& method, const std::string& problem_spec,
                                    double h, int steps) {
  const auto problem = make_problem(problem_spec);
  const auto integrator = make_integrator(method);
  State state = problem->initial_state();
  integrator->reset(*problem, state, h);
  for (int k = 0; k < steps; ++k) EXPECT_TRUE(integrator->step(*problem, state, h).ok);
  Eigen::Matrix3d attitude;
  Eigen::Vector3d pi;
  problem->as<FreeRigidBodyStructure>()->read_body(state.q, state.p, attitude, pi);
  return pi;
}

TEST(LiePoisson, KeepsCasimirSpatialMomentumAndOrthogonalityToRoundOff) {
  // 2·10⁴ steps at a coarse h (about 20 steps per radian): every rotation keeps |Π| and the
  // columns of Q to an ulp or two, so the errors random-walk at round-off (measured 2.3e-13 for
  // the Casimir and 1.1e-13 for QᵀQ − I over the 3·10⁵ rotations of order 4): 1e-12, where RK4
  // drifts to ~1e-8 on the same run (CasimirOfRk4DriftsOnTheSameRun).
  const auto problem = make_problem("rigid_body:angle=0.8,axis1=1,axis2=-2,axis3=0.5," + kMoments);
  for (const std::string method : {"lie_poisson", "lie_poisson:order=4"}) {
    const auto integrator = make_integrator(method);
    State state = problem->initial_state();
    const double casimir0 = problem->casimir(state.q, state.p);
    const Vec spatial0 = problem->angular_momentum(state.q, state.p);
    const double h = 0.05;
    integrator->reset(*problem, state, h);
    double casimir_err = 0, spatial_err = 0, orthogonality_err = 0;
    for (int k = 0; k < 20000; ++k) {
      ASSERT_TRUE(integrator->step(*problem, state, h).ok);
      casimir_err =
          std::max(casimir_err, std::abs(problem->casimir(state.q, state.p) / casimir0 - 1));
      spatial_err =
          std::max(spatial_err, (problem->angular_momentum(state.q, state.p) - spatial0).norm() /
                                    spatial0.norm());
      const Eigen::Matrix3d Q = attitude_of(state.q);
      orthogonality_err =
          std::max(orthogonality_err, (Q.transpose() * Q - Eigen::Matrix3d::Identity()).norm());
    }
    EXPECT_LT(casimir_err, 1e-12) << method;
    EXPECT_LT(spatial_err, 1e-12) << method;
    EXPECT_LT(orthogonality_err, 1e-12) << method;
  }
}

// RK4 drifts off the momentum sphere over the same run on Euler's equations: the Casimir check
// above can fail.
TEST(LiePoisson, CasimirOfRk4DriftsOnTheSameRun) {
  const auto problem = make_problem("rigid_body_euler:" + kMoments);
  for (const std::string method : {"lie_poisson", "rk4"}) {
    const auto integrator = make_integrator(method);
    State state = problem->initial_state();
    const double casimir0 = problem->casimir(state.q, state.p);
    integrator->reset(*problem, state, 0.05);
    for (int k = 0; k < 20000; ++k) ASSERT_TRUE(integrator->step(*problem, state, 0.05).ok);
    const double err = std::abs(problem->casimir(state.q, state.p) / casimir0 - 1);
    if (method == "rk4") {
      EXPECT_GT(err, 1e-8);
    } else {
      EXPECT_LT(err, 1e-12);
    }
  }
}

// Slope of log |Π_h(T) − Π(T)| over h, h/2, h/4, h/8 against the elliptic solution.
double fitted_order(const std::string& method, const std::string& problem_spec, double h0,
                    double t_end) {
  const std::string euler_spec = "rigid_body_euler:" + kMoments;
  const auto euler = make_problem(euler_spec);
  const Eigen::Vector3d exact = euler->exact(t_end).q;
  std::vector<double> log_h, log_err;
  for (int level = 0; level < 4; ++level) {
    const double h = h0 / std::pow(2.0, level);
    const int steps = static_cast<int>(std::lround(t_end / h));
    const double err = (body_momentum_after(method, problem_spec, h, steps) - exact).norm();
    log_h.push_back(std::log(h));
    log_err.push_back(std::log(err));
  }
  double mean_x = 0, mean_y = 0;
  for (size_t i = 0; i < log_h.size(); ++i) mean_x += log_h[i], mean_y += log_err[i];
  mean_x /= log_h.size(), mean_y /= log_h.size();
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < log_h.size(); ++i) {
    sxy += (log_h[i] - mean_x) * (log_err[i] - mean_y);
    sxx += (log_h[i] - mean_x) * (log_h[i] - mean_x);
  }
  return sxy / sxx;
}

TEST(LiePoisson, OrdersTwoAndFourOnPiAgainstTheEllipticSolution) {
  // T = 4 (about a third of the period 4K/λ here), h from T/20: the order-4 errors stay far
  // above round-off (≥ 1e-9) at the finest step.
  for (const std::string& problem :
       std::vector<std::string>{"rigid_body_euler:" + kMoments, "rigid_body:" + kMoments}) {
    EXPECT_NEAR(fitted_order("lie_poisson", problem, 0.2, 4.0), 2.0, 0.1) << problem;
    EXPECT_NEAR(fitted_order("lie_poisson:order=4", problem, 0.2, 4.0), 4.0, 0.2) << problem;
  }
}

// The two views of the state (Q, p of rigid_body; Π of rigid_body_euler) give the same Π: the
// attitude never feeds back into Π, and write_body/read_body round-trip it.
TEST(LiePoisson, BothRigidBodiesGiveTheSameBodyMomentum) {
  const Eigen::Vector3d euler =
      body_momentum_after("lie_poisson:order=4", "rigid_body_euler:" + kMoments, 0.1, 200);
  const Eigen::Vector3d attitude = body_momentum_after(
      "lie_poisson:order=4", "rigid_body:angle=2,axis1=0.3,axis2=1," + kMoments, 0.1, 200);
  EXPECT_LT((euler - attitude).norm(), 1e-12 * euler.norm());
}

TEST(LiePoisson, AppliesToFreeRigidBodiesOnlyAndSaysWhy) {
  const auto method = make_integrator("lie_poisson");
  EXPECT_TRUE(applicable(*method, *make_problem("rigid_body")).ok);
  EXPECT_TRUE(applicable(*method, *make_problem("rigid_body_euler")).ok);
  for (const char* other : {"kepler", "pendulum", "van_der_pol", "spherical_pendulum"}) {
    const Applicability applies = applicable(*method, *make_problem(other));
    EXPECT_FALSE(applies.ok) << other;
    EXPECT_FALSE(applies.reason.empty()) << other;
  }
  const std::string reason = applicable(*method, *make_problem("kepler")).reason;
  EXPECT_NE(reason.find("free rigid bodies only"), std::string::npos) << reason;
}

}  // namespace
}  // namespace lie_poisson_test
}  // namespace geomint
