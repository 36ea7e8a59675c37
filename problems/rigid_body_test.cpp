// The free rigid body (problems/rigid_body.hpp, Landau–Lifshitz §37) at non-unit moments: input
// checks, the 9-coordinate form's kinetic energy and angular momenta against ½ΩᵀJΩ and QJΩ, and the
// elliptic Π(t) against a tight GSL integration of Euler's equations on both sides of the
// separatrix, its invariants and its period 4K(k)/λ.
#include "problems/rigid_body.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "problems/first_order.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace rigid_body_test {
namespace {

std::string message_of(const std::string& spec) {
  try {
    make_problem(spec);
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no error)";
}

// The 9-coordinate form needs the masses d_k = ½(I1+I2+I3) − I_k > 0: a violated triangle
// inequality is refused naming it, and a flat body (d_k = 0) naming the singular mass tensor.
TEST(RigidBody, TriangleInequalityIsAnInputErrorOfTheNineCoordinateForm) {
  const std::string message = message_of("rigid_body:I1=1,I2=1.2,I3=2.5");
  EXPECT_NE(message.find("I3 = 2.5 must be < I1 + I2 = 2.2"), std::string::npos) << message;
  EXPECT_NE(message.find("triangle inequality"), std::string::npos) << message;
  EXPECT_NE(message.find("rigid_body_euler"), std::string::npos) << message;
  const std::string flat = message_of("rigid_body:I1=3,I2=1,I3=2");
  EXPECT_NE(flat.find("I1 = 3 equals I2 + I3 (a flat body, a lamina)"), std::string::npos) << flat;
  EXPECT_NE(flat.find("mass tensor of the 9-coordinate form is singular"), std::string::npos)
      << flat;
  EXPECT_NE(message_of("heavy_top:I1=1,I2=5,I3=3").find("I2 = 5 must be < I3 + I1 = 4"),
            std::string::npos);
}

// Euler's equations need positive moments only: GNI §IV.1's body I = (2, 1, 2/3) (outside the
// triangle inequality: no mass distribution has it), a lamina I3 = I1 + I2 and I2 > I1 + I3 run,
// with the elliptic solution; a moment ≤ 0 or NaN is still refused naming the range.
TEST(RigidBodyEuler, TakesAnyPositiveMoments) {
  for (const std::string parameters :
       {"I1=2,I2=1,I3=0.6666666666666666", "I1=1,I2=2,I3=3", "I1=1,I2=5,I3=3"}) {
    SCOPED_TRACE(parameters);
    EXPECT_EQ(message_of("rigid_body_euler:" + parameters), "(no error)");
    const auto problem = make_problem("rigid_body_euler:" + parameters);
    EXPECT_TRUE(problem->has(kExact) && problem->has(kPeriod));
    EXPECT_GT(problem->period(), 0);
  }
  EXPECT_NE(message_of("rigid_body_euler:I3=0").find("I3=0 is out of range (allowed: > 0)"),
            std::string::npos);
  EXPECT_NE(message_of("rigid_body_euler:I1=-1").find("I1=-1 is out of range (allowed: > 0)"),
            std::string::npos);
  EXPECT_NE(message_of("rigid_body_euler:I2=nan").find("I2='nan' is not a finite number"),
            std::string::npos);
}

TEST(RigidBody, ZeroAttitudeAxisIsAnInputError) {
  const std::string message = message_of("rigid_body:axis1=0,axis2=0,axis3=0,angle=1");
  EXPECT_NE(message.find("attitude axis"), std::string::npos) << message;
}

// An attitude that is not a rotation (here from an `initial=` file, the one way to give Q by its
// entries) fails the constraint check of make_problem, which names the residual.
TEST(RigidBody, NonOrthogonalInitialAttitudeIsAnInputError) {
  const auto path = std::filesystem::temp_directory_path() / "geomint_rigid_body_attitude.csv";
  {
    std::ofstream out(path);
    // Q = diag(1, 1.01, 1), p = 0.
    for (int k = 0; k < 9; ++k) out << (k % 4 == 0 ? (k == 4 ? 1.01 : 1.0) : 0.0) << ",0\n";
  }
  const std::string message = message_of("rigid_body:initial=" + path.string());
  EXPECT_NE(message.find("initial state"), std::string::npos) << message;
  EXPECT_NE(message.find("constraint"), std::string::npos) << message;
  std::filesystem::remove(path);
}

// ½tr(Q̇DQ̇ᵀ) = ½ΩᵀJΩ, Σ c_k × p_k = QJΩ and Π from the state = JΩ, at an attitude other than I.
TEST(RigidBody, KineticEnergyAndMomentaAreThoseOfTheBody) {
  const auto problem = make_problem(
      "rigid_body:I1=3,I2=1.5,I3=2.2,omega1=0.2,omega2=1.1,omega3=0.4,axis1=1,axis2=-2,axis3=0.5,"
      "angle=0.9");
  const Eigen::Vector3d J(3, 1.5, 2.2), omega(0.2, 1.1, 0.4);
  const Eigen::Matrix3d Q =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const State start = problem->initial_state();
  EXPECT_NEAR(problem->energy(start.q, start.p), 0.5 * omega.dot(J.cwiseProduct(omega)), 1e-15);
  const Vec spatial = problem->angular_momentum(start.q, start.p);
  EXPECT_LE((spatial - Q * J.cwiseProduct(omega)).norm(), 1e-15);
  EXPECT_LE((rigid_body_body_momentum(start.q, start.p) - J.cwiseProduct(omega)).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(problem->mass()[0], 0.5 * (3 + 1.5 + 2.2) - 3);
  EXPECT_DOUBLE_EQ(problem->mass()[8], 0.5 * (3 + 1.5 + 2.2) - 2.2);
  EXPECT_NO_THROW(problem->check_consistent(start, "initial state", 1e-15));
}

// Π̇ = Π × J⁻¹Π by GSL's rk8pd at rtol = atol = 1e-14 relative to |Π|.
Eigen::Vector3d euler_reference(const Eigen::Vector3d& J, const Eigen::Vector3d& pi0, double t) {
  struct Data {
    Eigen::Vector3d J;
  } data{J};
  const auto rhs = [](double, const double y[], double dydt[], void* params) -> int {
    const Eigen::Vector3d& I = static_cast<Data*>(params)->J;
    const Eigen::Vector3d pi(y[0], y[1], y[2]);
    const Eigen::Vector3d rate = pi.cross(pi.cwiseQuotient(I));
    for (int i = 0; i < 3; ++i) dydt[i] = rate[i];
    return GSL_SUCCESS;
  };
  gsl_odeiv2_system system{rhs, nullptr, 3, &data};
  const double scale = pi0.norm();
  gsl_odeiv2_driver* driver =
      gsl_odeiv2_driver_alloc_y_new(&system, gsl_odeiv2_step_rk8pd, 1e-3, 1e-14 * scale, 1e-14);
  double y[3] = {pi0[0], pi0[1], pi0[2]};
  double time = 0;
  const int status = gsl_odeiv2_driver_apply(driver, &time, t, y);
  gsl_odeiv2_driver_free(driver);
  EXPECT_EQ(status, GSL_SUCCESS);
  return {y[0], y[1], y[2]};
}

struct Case {
  Eigen::Vector3d J, omega;
};

// About the largest axis, about the smallest, with the moments in another order (an odd
// relabelling reverses time), 1e-4 from the separatrix on both sides (I = (1, 2, 3), a lamina,
// Π near the intermediate axis: the tennis racket), and GNI's body outside the triangle
// inequality.
std::vector<Case> cases() {
  return {{{2, 3, 4.5}, {0.8, 0.3, -0.6}},
          {{2, 3, 4.5}, {1.5, 0.2, 0.1}},
          {{3, 1.5, 2.2}, {0.2, 1.1, 0.4}},
          {{1.5, 3, 2.2}, {-0.3, 0.2, 0.9}},
          {{1, 2, 3}, {0.01, 1, 0.0101}},
          {{1, 2, 3}, {0.0101, 1, 0.01}},
          {{4, 2.5, 3.1}, {0.05, -0.4, 0.7}},
          // GNI §IV.1's free body, Π(0) = (cos 1.1, 0, sin 1.1).
          {{2, 1, 2.0 / 3}, {std::cos(1.1) / 2, 0, 1.5 * std::sin(1.1)}}};
}

TEST(FreeBodyMotion, EllipticSolutionMatchesATightIntegrationOfEulersEquations) {
  for (const auto& [J, omega] : cases()) {
    const Eigen::Vector3d pi0 = J.cwiseProduct(omega);
    const FreeBodyMotion motion(J, pi0);
    SCOPED_TRACE(testing::Message() << "J = " << J.transpose() << ", omega = " << omega.transpose()
                                    << ", k = " << motion.modulus());
    ASSERT_TRUE(motion.exact()) << motion.why_not();
    EXPECT_LE((motion.at(0) - pi0).norm(), 1e-14 * pi0.norm());
    for (double fraction : {0.13, 0.61, 1.37, 3.1}) {
      const double t = fraction * motion.period();
      const Eigen::Vector3d reference = euler_reference(J, pi0, t);
      EXPECT_LE((motion.at(t) - reference).norm(), 1e-10 * pi0.norm())
          << "t = " << t << ": " << motion.at(t).transpose() << " vs " << reference.transpose();
    }
  }
}

// |Π|² (the Casimir) and E = ½ΠᵀJ⁻¹Π are constant, and Π returns after 4K/λ, also late.
TEST(FreeBodyMotion, InvariantsAndPeriodAlongTheExactSolution) {
  for (const auto& [J, omega] : cases()) {
    const Eigen::Vector3d pi0 = J.cwiseProduct(omega);
    const FreeBodyMotion motion(J, pi0);
    ASSERT_TRUE(motion.exact());
    const double T = motion.period();
    const double casimir = pi0.squaredNorm();
    const double energy = 0.5 * pi0.dot(pi0.cwiseQuotient(J));
    for (double t : {0.0, 0.29 * T, 0.77 * T, 2.5 * T, 1000.37 * T}) {
      const Eigen::Vector3d pi = motion.at(t);
      EXPECT_NEAR(pi.squaredNorm(), casimir, 1e-13 * casimir) << t;
      EXPECT_NEAR(0.5 * pi.dot(pi.cwiseQuotient(J)), energy, 1e-13 * energy) << t;
      EXPECT_LE((motion.at(t + T) - pi).norm(), 1e-10 * pi0.norm()) << t;
    }
    // Half a period later Π is not where it was (4K, not 2K, is the period of cn and sn).
    EXPECT_GT((motion.at(0.5 * T) - pi0).norm(), 1e-3 * pi0.norm());
  }
}

TEST(FreeBodyMotion, SeparatrixAndSymmetricBodiesHaveNoEllipticSolution) {
  // Π = (1, 0, 1) with I = (1, 2, 3)... |Π|² = 2 and 2E·I2 = (1 + 1/3)·2 ≠ 2: not it. On the
  // separatrix: Π1²(I2 − I1)/I1 = Π3²(I3 − I2)/I3, i.e. Π1² = Π3²/3.
  EXPECT_FALSE(FreeBodyMotion({1, 2, 3}, {1, 0.3, std::sqrt(3.0)}).exact());
  EXPECT_FALSE(FreeBodyMotion({1, 1, 3}, {1, 0.3, 0.2}).exact());
  // Steady rotation about a principal axis: Π constant.
  const FreeBodyMotion steady({1, 2, 3}, {0, 0, 2});
  ASSERT_TRUE(steady.exact());
  EXPECT_EQ(steady.at(7.3), Eigen::Vector3d(0, 0, 2));
}

// rigid_body_euler is Euler's equations for the same body: y = Π = JΩ, the exact solution and the
// period are FreeBodyMotion's, the Casimir is |Π|², and the period observable (Π of the axis the
// orbit does not circulate about) crosses 0 upwards once per period, for orbits about either
// extreme axis.
TEST(RigidBodyEuler, IsEulersEquationsWithTheEllipticSolution) {
  for (const std::string& parameters :
       {std::string("I1=3,I2=1.5,I3=2.2,omega1=0.2,omega2=1.1,omega3=0.4"),
        std::string("omega1=1.5,omega2=0.2,omega3=0.1")}) {
    SCOPED_TRACE(parameters);
    const auto euler = make_problem("rigid_body_euler:" + parameters);
    const auto body = make_problem("rigid_body:" + parameters);
    const State start = body->initial_state();
    const Eigen::Vector3d pi0 = rigid_body_body_momentum(start.q, start.p);
    EXPECT_LE((euler->initial_state().q - pi0).norm(), 1e-15 * pi0.norm());
    ASSERT_TRUE(euler->has(kExact) && euler->has(kPeriod) && euler->has(kCasimir));
    EXPECT_DOUBLE_EQ(body->casimir(start.q, start.p), pi0.squaredNorm());
    const double T = euler->period();
    Vec rate;
    first_order_system_of(*euler).rhs(0, euler->initial_state().q, rate);
    // J from the masses: I_k = (d1 + d2 + d3) − d_k.
    const Eigen::Vector3d d(body->mass()[0], body->mass()[3], body->mass()[6]);
    const Eigen::Vector3d J = Eigen::Vector3d::Constant(d.sum()) - d;
    EXPECT_LE((Eigen::Vector3d(rate) - pi0.cross(pi0.cwiseQuotient(J))).norm(), 1e-15);
    int upward = 0;
    double previous = euler->period_observable(euler->exact(0).q, Vec());
    for (int i = 1; i <= 4000; ++i) {
      const double now = euler->period_observable(euler->exact(3 * T * i / 4000.0).q, Vec());
      upward += previous < 0 && now >= 0;
      previous = now;
    }
    EXPECT_EQ(upward, 3);
  }
}

}  // namespace
}  // namespace rigid_body_test
}  // namespace geomint
