// Andrews' squeezing mechanism against the IVP Test Set's own statement of it: its equations
// M(q)q̈ = f(q, q̇) − G(q)ᵀλ written out as in the Test Set's andrews.f, its consistent initial
// accelerations and multipliers, and the parameter checks.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>

#include "problems/force.hpp"
#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace andrews_test {
namespace {

// The Test Set's data (andrews.f).
constexpr double m2 = .00365, m4 = .00706, m6 = .00706;
constexpr double xb = -.03635, yb = .03273, xc = .014, yc = .072, c0 = 4530;
constexpr double da = 115e-4, e = 2e-2, ea = 1421e-5, rr = 7e-3, l0 = 7785e-5;
constexpr double sc = 18e-3, sd = 2e-2, u = 4e-2, zf = 2e-2, zt = 4e-2, fa = 1421e-5, mom = 33e-3;

// The Test Set's right-hand side f(q, q̇) (its ff), written out term by term from its source.
Vec test_set_f(const Vec& q, const Vec& v) {
  const double xd = sd * std::cos(q[2]) + sc * std::sin(q[2]) + xb;
  const double yd = sd * std::sin(q[2]) - sc * std::cos(q[2]) + yb;
  const double length = std::hypot(xd - xc, yd - yc);
  const double force = -c0 * (length - l0) / length;
  const double fx = force * (xd - xc), fy = force * (yd - yc);
  Vec f(7);
  f[0] = mom - m2 * da * rr * v[1] * (v[1] + 2 * v[0]) * std::sin(q[1]);
  f[1] = m2 * da * rr * v[0] * v[0] * std::sin(q[1]);
  f[2] = fx * (sc * std::cos(q[2]) - sd * std::sin(q[2])) +
         fy * (sd * std::cos(q[2]) + sc * std::sin(q[2]));
  f[3] = m4 * zt * (e - ea) * v[4] * v[4] * std::cos(q[3]);
  f[4] = -m4 * zt * (e - ea) * v[3] * (v[3] + 2 * v[4]) * std::cos(q[3]);
  f[5] = -m6 * u * (zf - fa) * v[6] * v[6] * std::cos(q[5]);
  f[6] = m6 * u * (zf - fa) * v[5] * (v[5] + 2 * v[6]) * std::cos(q[5]);
  return f;
}

// Ours: M q̈ = L_q − Ṁv + F − Gᵀλ, so f = L_q − D v + F.
Vec our_f(const Problem& problem, const Vec& q, const Vec& v) {
  const LagrangianSystem& system = *problem.as_lagrangian();
  Vec f, force;
  system.lagrangian_q(q, v, f);
  DenseMatrix D;
  system.mass_velocity_jacobian(q, v, D);
  problem.as_forced()->force(q, v, 0.0, force);
  return f - D * v + force;
}

TEST(Andrews, RightHandSideIsTheTestSets) {
  const auto problem = make_problem("andrews");
  ASSERT_EQ(problem->kind(), ProblemKind::kLagrangian);
  ASSERT_TRUE(problem->has(kConstraints) && problem->has(kForce) && problem->has(kEndReference));
  // Away from the initial state, with every rate non-zero (the reference state's rates).
  const State reference = problem->end_reference();
  const Vec v = problem->as_lagrangian()->velocity(reference.q, reference.p);
  for (const Vec& q : {reference.q, problem->initial_state().q}) {
    const Vec expected = test_set_f(q, v);
    const Vec ours = our_f(*problem, q, v);
    EXPECT_LE((ours - expected).lpNorm<Eigen::Infinity>(),
              1e-12 * expected.lpNorm<Eigen::Infinity>())
        << "ours " << ours.transpose() << "\nTest Set " << expected.transpose();
  }
}

// The Test Set's consistent initial values (andrews.f, init): at rest, q̈(0) = (14222.44…,
// −10666.83…, 0, …) and λ(0) = (98.566…, −6.1226…, 0, 0, 0, 0), our sign convention and its.
TEST(Andrews, InitialAccelerationsAndMultipliersAreTheTestSets) {
  const auto problem = make_problem("andrews");
  const State start = problem->initial_state();
  EXPECT_LE(problem->constraint_residual(0.0, start.q), 1e-16);
  const Vec lambda = problem->multipliers(0.0, start.q, start.p);
  Vec expected_lambda(6);
  expected_lambda << 98.5668703962410896057654982170, -6.12268834425566265503114393122, 0, 0, 0, 0;
  EXPECT_LE((lambda - expected_lambda).lpNorm<Eigen::Infinity>(), 1e-10 * 98.57)
      << lambda.transpose();

  const LagrangianSystem& system = *problem->as_lagrangian();
  DenseMatrix M;
  system.mass_matrix(start.q, M);
  SparseMatrix G;
  problem->as_constrained()->constraint_jacobian(start.q, G);
  const Vec zero = Vec::Zero(7);
  const Vec acceleration = M.llt().solve(our_f(*problem, start.q, zero) - G.transpose() * lambda);
  Vec expected_acceleration(7);
  expected_acceleration << 14222.4439199541138705911625887, -10666.8329399655854029433719415, 0, 0,
      0, 0, 0;
  EXPECT_LE((acceleration - expected_acceleration).lpNorm<Eigen::Infinity>(), 1e-10 * 14222.4)
      << acceleration.transpose();
}

// The reference state at t = 0.03 lies on the constraint manifold: |g| ≲ 1e-15 m on lengths of
// ~0.03 m (the 16 digits it prints), and |G v| ≈ 1e-9 against |G||v| ≈ 85 (measured 9.9e-10: its
// velocities are good to ~1e-11 relative).
TEST(Andrews, TheTestSetReferenceIsOnTheConstraints) {
  const auto problem = make_problem("andrews");
  const State reference = problem->end_reference();
  EXPECT_DOUBLE_EQ(reference.t, 0.03);
  EXPECT_LE(problem->constraint_residual(0.03, reference.q), 1e-14);
  const Vec v = problem->as_lagrangian()->velocity(reference.q, reference.p);
  EXPECT_LE(problem->constraint_velocity_residual(0.03, reference.q, reference.p),
            1e-10 * v.lpNorm<Eigen::Infinity>() * 0.03);
}

// At the reference state (t = 0.03) the accelerations and multipliers of our equations are the
// ones the Test Set lists beside its positions and velocities (andsoln, y(15 … 27)), to 7.4e-8
// and 1.0e-7 relative (measured): ours follow from its (q, v) directly, its own are the index-2
// and index-3 components of its DAE, which the error control of that run does not weigh as it
// weighs q and v.
TEST(Andrews, ReferenceAccelerationsAndMultipliersAreTheTestSets) {
  const auto problem = make_problem("andrews");
  const State reference = problem->end_reference();
  const LagrangianSystem& system = *problem->as_lagrangian();
  const Vec v = system.velocity(reference.q, reference.p);
  const Vec lambda = problem->multipliers(0.03, reference.q, reference.p);
  Vec expected_lambda(6);
  expected_lambda << 0.1991753333731910e+3, -0.2975531228015052e+2, 0.2306654119098399e+2,
      0.3145271365475927e+2, 0.2264249232082739e+2, 0.1161740700019673e+2;
  DenseMatrix M;
  system.mass_matrix(reference.q, M);
  SparseMatrix G;
  problem->as_constrained()->constraint_jacobian(reference.q, G);
  const Vec acceleration = M.llt().solve(our_f(*problem, reference.q, v) - G.transpose() * lambda);
  Vec expected_acceleration(7);
  expected_acceleration << -0.2463176316945196e+5, 0.5185037701610329e+5, 0.3241025686413781e+6,
      0.5667493645176213e+6, 0.1674362929479361e+5, -0.5667493645176222e+6, 0.9826520791458422e+4;
  const double lambda_error = (lambda - expected_lambda).lpNorm<Eigen::Infinity>() /
                              expected_lambda.lpNorm<Eigen::Infinity>();
  const double acceleration_error =
      (acceleration - expected_acceleration).lpNorm<Eigen::Infinity>() /
      expected_acceleration.lpNorm<Eigen::Infinity>();
  std::printf("andrews at t = 0.03: multipliers %.3g, accelerations %.3g (relative)\n",
              lambda_error, acceleration_error);
  EXPECT_LE(lambda_error, 1e-6);
  EXPECT_LE(acceleration_error, 1e-6);
}

TEST(Andrews, OutOfRangeParametersAreInputErrorsNamingTheRange) {
  for (const char* spec : {"andrews:c0=-1", "andrews:l0=0", "andrews:mom=1e9"}) {
    SCOPED_TRACE(spec);
    try {
      make_problem(spec);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& error) {
      const std::string message = error.what();
      const std::string key = std::string(spec).substr(8, std::string(spec).find('=') - 8);
      EXPECT_NE(message.find(key), std::string::npos) << message;
    }
  }
  // Only the Test Set's own instance has its reference.
  EXPECT_FALSE(make_problem("andrews:mom=0.05")->has(kEndReference));
}

}  // namespace
}  // namespace andrews_test
}  // namespace geomint
