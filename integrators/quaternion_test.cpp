// The unit-quaternion contrast (integrators/quaternion.cpp) at non-unit moments: QᵀQ = I to
// round-off with renormalisation and a drift without it, the attitude of the exact motion, the
// orders 4 (RK4) and 1 (Euler) on Π against the elliptic solution, the Casimir |Π|² not kept (it
// is not a Lie–Poisson method), and applicable() refusing every other problem with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/rigid_body.hpp"

namespace geomint {
namespace quaternion_test {
namespace {

// Away from the separatrix, non-unit and unequal moments, a general initial attitude.
const std::string kMoments = "I1=1.7,I2=2.9,I3=4.1,omega1=0.9,omega2=0.35,omega3=-0.7";
const std::string kBody = "rigid_body:angle=0.8,axis1=1,axis2=-2,axis3=0.5," + kMoments;

struct BodyRun {
  double orthogonality_err = 0;  // max ‖QᵀQ − I‖_F over the steps
  double casimir_err = 0;        // max |C/C₀ − 1|
  Eigen::Matrix3d attitude;
  Eigen::Vector3d pi;
};

BodyRun run(const std::string& method, const std::string& problem_spec, double h, int steps) {
  const auto problem = make_problem(problem_spec);
  const auto integrator = make_integrator(method);
  State state = problem->initial_state();
  const double casimir0 = problem->casimir(state.q, state.p);
  integrator->reset(*problem, state, h);
  BodyRun result;
  for (int k = 0; k < steps; ++k) {
    EXPECT_TRUE(integrator->step(*problem, state, h).ok);
    problem->as<FreeRigidBodyStructure>()->read_body(state.q, state.p, result.attitude, result.pi);
    const Eigen::Matrix3d& Q = result.attitude;
    result.orthogonality_err = std::max(result.orthogonality_err,
                                        (Q.transpose() * Q - Eigen::Matrix3d::Identity()).norm());
    result.casimir_err =
        std::max(result.casimir_err, std::abs(problem->casimir(state.q, state.p) / casimir0 - 1));
  }
  return result;
}

TEST(Quaternion, RenormalisationKeepsOrthogonalityToRoundOffAndWithoutItQDrifts) {
  // 2000 steps of 0.05 (|Ω| ≈ 0.6). Renormalised, Q = R(q/|q|) is orthogonal to a few ulps
  // (measured 2.4e-15 for RK4, 2.6e-15 for Euler). Without it |q| leaves 1 and QᵀQ − I grows with
  // |q|² − 1: RK4's amplification of the rotation q̇ = ½q⊗Ω is 1 − O((h|Ω|/2)⁶) per step
  // (measured 1.1e-7 after the run), explicit Euler's 1 + (h|Ω|/2)², and its Π spirals out
  // (measured 8.8e2).
  for (const std::string base : {"rk4", "euler"}) {
    const BodyRun on = run("quaternion:base=" + base, kBody, 0.05, 2000);
    const BodyRun off = run("quaternion:renormalize=false,base=" + base, kBody, 0.05, 2000);
    EXPECT_LT(on.orthogonality_err, 1e-14) << base;
    EXPECT_GT(off.orthogonality_err, base == "rk4" ? 1e-8 : 1.0) << base;
  }
}

// The renormalised attitude follows the exact motion: at a fine step it agrees with the
// order-4 Lie–Poisson splitting (measured 2.7e-9 in Q, 4.3e-9 in Π after T = 5); a wrong product
// order q⊗Ω ↔ Ω⊗q turns the body the wrong way.
TEST(Quaternion, AttitudeAgreesWithTheLiePoissonSplitting) {
  const BodyRun quaternion = run("quaternion", kBody, 0.01, 500);
  const BodyRun splitting = run("lie_poisson:order=4", kBody, 0.01, 500);
  EXPECT_LT((quaternion.attitude - splitting.attitude).norm(), 1e-8);
  EXPECT_LT((quaternion.pi - splitting.pi).norm(), 1e-8);
}

// It is not a Lie–Poisson method: RK4 on Euler's equations leaves the momentum sphere, on both
// problems (measured 4.8e-8 over 2·10⁴ steps of 0.05; lie_poisson keeps 6e-14 on the same run).
TEST(Quaternion, CasimirIsNotKept) {
  for (const std::string& problem :
       std::vector<std::string>{kBody, "rigid_body_euler:" + kMoments}) {
    EXPECT_GT(run("quaternion", problem, 0.05, 20000).casimir_err, 1e-8) << problem;
  }
}

// Slope of log |Π_h(T) − Π(T)| over h, h/2, h/4, h/8 against the elliptic solution.
double fitted_order(const std::string& method, const std::string& problem_spec, double h0,
                    double t_end) {
  const Eigen::Vector3d exact = make_problem("rigid_body_euler:" + kMoments)->exact(t_end).q;
  std::vector<double> log_h, log_err;
  for (int level = 0; level < 4; ++level) {
    const double h = h0 / std::pow(2.0, level);
    const int steps = static_cast<int>(std::lround(t_end / h));
    log_h.push_back(std::log(h));
    log_err.push_back(std::log((run(method, problem_spec, h, steps).pi - exact).norm()));
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

TEST(Quaternion, OrdersFourAndOneOnPiAgainstTheEllipticSolution) {
  // T = 4, h from T/20 (RK4) and T/100 (Euler); measured 4.007 and 1.006 on both problems.
  for (const std::string& problem :
       std::vector<std::string>{"rigid_body_euler:" + kMoments, kBody}) {
    EXPECT_NEAR(fitted_order("quaternion", problem, 0.2, 4.0), 4.0, 0.2) << problem;
    EXPECT_NEAR(fitted_order("quaternion:base=euler", problem, 0.04, 4.0), 1.0, 0.1) << problem;
  }
}

TEST(Quaternion, AppliesToFreeRigidBodiesOnlyAndSaysWhy) {
  const auto method = make_integrator("quaternion");
  EXPECT_TRUE(applicable(*method, *make_problem("rigid_body")).ok);
  EXPECT_TRUE(applicable(*method, *make_problem("rigid_body_euler")).ok);
  for (const char* other : {"kepler", "pendulum", "heavy_top", "spherical_pendulum"}) {
    const Applicability applies = applicable(*method, *make_problem(other));
    EXPECT_FALSE(applies.ok) << other;
    EXPECT_NE(applies.reason.find("free rigid bodies only"), std::string::npos) << other;
  }
}

}  // namespace
}  // namespace quaternion_test
}  // namespace geomint
