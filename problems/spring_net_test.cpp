// Checks of the spring network beyond the registry suite: the symmetries behind momentum
// conservation (rigid-motion invariance, zero net force and torque, frame-invariant damping),
// the damping matrix, the 3D variant, a 10⁴-dof net, and parameter validation.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cfloat>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "problems/force.hpp"
#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace spring_net_test {
namespace {

int dimension_of(const Problem& problem) {
  return static_cast<int>(
      problem.linear_momentum(problem.initial_state().q, problem.initial_state().p).size());
}

// A configuration away from the lattice and away from the origin, so torques about the origin
// have long lever arms and every spring is stretched or compressed by a different amount.
Vec deformed(const Problem& problem, unsigned seed, double amplitude = 0.2, double shift = 30) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Vec q = problem.initial_state().q;
  for (int k = 0; k < q.size(); ++k) q[k] += amplitude * uniform(generator) + shift;
  return q;
}

using test::random_vector;

// Random proper rotation: a normalised random quaternion in 3D, a random angle in 2D.
Eigen::MatrixXd random_rotation(int dim, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  if (dim == 2) {
    const double angle = 3 * uniform(generator);
    return Eigen::Rotation2Dd(angle).toRotationMatrix();
  }
  Eigen::Quaterniond rotation(uniform(generator), uniform(generator), uniform(generator),
                              uniform(generator));
  return rotation.normalized().toRotationMatrix();
}

Vec apply_rigid_motion(const Vec& q, const Eigen::MatrixXd& rotation, const Vec& translation) {
  const int dim = static_cast<int>(rotation.rows());
  Vec moved(q.size());
  for (int node = 0; node < q.size() / dim; ++node) {
    moved.segment(dim * node, dim) = rotation * q.segment(dim * node, dim) + translation;
  }
  return moved;
}

// Σ_i x_i × y_i per node pair, with 1 component in 2D and 3 in 3D.
Vec total_torque(const Vec& q, const Vec& f, int dim) {
  if (dim == 2) {
    double total = 0;
    for (int node = 0; node < q.size() / 2; ++node) {
      total += q[2 * node] * f[2 * node + 1] - q[2 * node + 1] * f[2 * node];
    }
    return Vec::Constant(1, total);
  }
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (int node = 0; node < q.size() / 3; ++node) {
    total += Eigen::Vector3d(q.segment<3>(3 * node)).cross(Eigen::Vector3d(f.segment<3>(3 * node)));
  }
  return total;
}

Vec total_force(const Vec& f, int dim) {
  Vec total = Vec::Zero(dim);
  for (int node = 0; node < f.size() / dim; ++node) total += f.segment(dim * node, dim);
  return total;
}

// Σ_i |q_i| |f_i|: the size of the terms a torque sum cancels.
double torque_scale(const Vec& q, const Vec& f, int dim) {
  double sum = 0;
  for (int node = 0; node < q.size() / dim; ++node) {
    sum += q.segment(dim * node, dim).norm() * f.segment(dim * node, dim).norm();
  }
  return sum;
}

const std::vector<std::string>& variants() {
  static const std::vector<std::string> specs = {
      "spring_net",
      "spring_net:nx=5,ny=4,model=nonlinear,stiffness=30,mass=0.5,damping=2",
      "spring_net:dim=3,nx=3,ny=3,nz=3",
      "spring_net:dim=3,nx=4,ny=3,nz=2,model=nonlinear,quartic=50,diagonals=false,damping=0.5",
  };
  return specs;
}

TEST(SpringNet, PotentialInvariantUnderRigidMotion) {
  for (const auto& spec : variants()) {
    const auto problem = make_problem(spec);
    const int dim = dimension_of(*problem);
    for (unsigned seed : {1u, 2u, 3u}) {
      const Vec q = deformed(*problem, seed);
      const Vec translation = 50 * random_vector(dim, seed + 10);
      const Vec moved = apply_rigid_motion(q, random_rotation(dim, seed + 20), translation);
      const double before = problem->potential(q);
      // Each spring's stretch r − L loses ~ε r/|r − L| of relative accuracy to cancellation.
      EXPECT_NEAR(problem->potential(moved), before, 1e-12 * before) << spec << " seed " << seed;
    }
  }
}

TEST(SpringNet, GradientHasZeroNetForceAndTorque) {
  for (const auto& spec : variants()) {
    const auto problem = make_problem(spec);
    const int dim = dimension_of(*problem);
    for (unsigned seed : {4u, 5u}) {
      const Vec q = deformed(*problem, seed);
      Vec g;
      problem->gradient(q, g);
      ASSERT_GT(g.norm(), 0.0);
      // Each spring adds ±pull exactly, so only summation rounding remains: tens of ulps of the
      // sum of |g_i| (force) or of |q_i||g_i| (torque).
      EXPECT_LE(total_force(g, dim).lpNorm<Eigen::Infinity>(), 64 * DBL_EPSILON * g.lpNorm<1>())
          << spec;
      EXPECT_LE(total_torque(q, g, dim).lpNorm<Eigen::Infinity>(),
                64 * DBL_EPSILON * torque_scale(q, g, dim))
          << spec;
    }
  }
}

TEST(SpringNet, DampingHasZeroForceAndTorqueAndDissipates) {
  for (const auto& spec : variants()) {
    const auto problem = make_problem(spec);
    if (!problem->has(kForce)) continue;
    const int dim = dimension_of(*problem);
    const Vec q = deformed(*problem, 6);
    for (unsigned seed : {7u, 8u, 9u}) {
      const Vec v = random_vector(problem->dof(), seed);
      Vec f;
      force_of(*problem).force(q, v, 0.0, f);
      ASSERT_GT(f.norm(), 0.0);
      EXPECT_LE(total_force(f, dim).lpNorm<Eigen::Infinity>(), 64 * DBL_EPSILON * f.lpNorm<1>())
          << spec;
      EXPECT_LE(total_torque(q, f, dim).lpNorm<Eigen::Infinity>(),
                64 * DBL_EPSILON * torque_scale(q, f, dim))
          << spec;
      // Power −Σ c ṙ²: strictly negative for generic relative velocities.
      EXPECT_LT(v.dot(f), -1e-3 * v.norm() * f.norm()) << spec;
    }
    // A rigid velocity field v_i = a + ω × q_i does not stretch any spring, so a frame-invariant
    // damping produces no force; the bound is rounding of n·(v_j − v_i) relative to a generic
    // field's force per unit velocity.
    const Vec drift = random_vector(dim, 14);
    Vec rigid(q.size());
    for (int node = 0; node < q.size() / dim; ++node) {
      if (dim == 2) {
        rigid.segment(2 * node, 2) << -q[2 * node + 1], q[2 * node];
      } else {
        rigid.segment<3>(3 * node) =
            Eigen::Vector3d(0.3, -1.1, 0.7).cross(Eigen::Vector3d(q.segment<3>(3 * node)));
      }
      rigid.segment(dim * node, dim) += drift;
    }
    const Vec v_generic = random_vector(problem->dof(), 13);
    Vec f_generic, f_rigid;
    force_of(*problem).force(q, v_generic, 0.0, f_generic);
    force_of(*problem).force(q, rigid, 0.0, f_rigid);
    const double force_per_velocity =
        f_generic.lpNorm<Eigen::Infinity>() / v_generic.lpNorm<Eigen::Infinity>();
    EXPECT_LE(f_rigid.lpNorm<Eigen::Infinity>(),
              256 * DBL_EPSILON * force_per_velocity * rigid.lpNorm<Eigen::Infinity>())
        << spec;
  }
}

TEST(SpringNet, DampingMatrixMatchesFiniteDifferencesAndIsPsd) {
  const auto problem = make_problem("spring_net:nx=4,ny=3,damping=1.5,model=nonlinear");
  ASSERT_TRUE(problem->has(kForceJacobian));
  const int n = problem->dof();
  const Vec q = deformed(*problem, 15);
  const Vec v = random_vector(n, 16);
  SparseMatrix C;
  force_of(*problem).force_jacobian_v(q, v, 0.0, C);
  const Eigen::MatrixXd dense(C);
  // F is linear in v, so the central difference is exact up to rounding of F / h.
  const double h = 1e-3;
  Vec f_plus, f_minus;
  for (int j = 0; j < n; ++j) {
    Vec plus = v, minus = v;
    plus[j] += h;
    minus[j] -= h;
    force_of(*problem).force(q, plus, 0.0, f_plus);
    force_of(*problem).force(q, minus, 0.0, f_minus);
    const Vec column = -(f_plus - f_minus) / (2 * h);
    EXPECT_LE((dense.col(j) - column).lpNorm<Eigen::Infinity>(), 1e-11) << "column " << j;
  }
  EXPECT_LE((dense - dense.transpose()).cwiseAbs().maxCoeff(), 0.0);
  const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues()[0];
  EXPECT_GE(smallest, -1e-13);
}

TEST(SpringNet, InitialMomentaComeFromDriftAndSpin) {
  for (const std::string& spec :
       {std::string("spring_net"), std::string("spring_net:dim=3,nx=4,ny=4,nz=3")}) {
    const auto problem = make_problem(spec);
    const int dim = dimension_of(*problem);
    const State start = problem->initial_state();
    const int nodes = problem->dof() / dim;
    const double mass = problem->mass()[0];
    // Drift 0.3 along x: Σ p_x ≈ 0.3 m N; the random velocities add only ~√N.
    const Vec linear = problem->linear_momentum(start.q, start.p);
    EXPECT_GT(linear[0], 0.5 * 0.3 * mass * nodes) << spec;
    // Spin 0.5 about the centre of mass: |L| ≈ 0.5 Σ m r², every component in 3D (tilted axis).
    Vec centre = Vec::Zero(dim);
    for (int node = 0; node < nodes; ++node) centre += start.q.segment(dim * node, dim);
    centre /= nodes;
    double moment = 0;
    for (int node = 0; node < nodes; ++node) {
      moment += mass * (start.q.segment(dim * node, dim) - centre).squaredNorm();
    }
    const Vec angular = problem->angular_momentum(start.q, start.p);
    ASSERT_EQ(angular.size(), dim == 2 ? 1 : 3);
    for (int k = 0; k < angular.size(); ++k) {
      EXPECT_GT(angular[k], 0.2 * 0.5 * moment / std::sqrt(angular.size())) << spec << " " << k;
    }
    // Control: with neither drift, spin nor random velocities the net starts at rest.
    const auto still = make_problem(spec + (spec.find(':') == std::string::npos ? ":" : ",") +
                                    "drift=0,spin=0,velocity=0");
    EXPECT_EQ(still->initial_state().p.lpNorm<Eigen::Infinity>(), 0.0);
  }
}

TEST(SpringNet, SameSeedSameStartOtherSeedOtherStart) {
  const auto a = make_problem("spring_net:seed=7");
  const auto b = make_problem("spring_net:seed=7");
  const auto c = make_problem("spring_net:seed=8");
  EXPECT_EQ(a->initial_state().q, b->initial_state().q);
  EXPECT_EQ(a->initial_state().p, b->initial_state().p);
  EXPECT_NE(a->initial_state().q, c->initial_state().q);
  EXPECT_NE(a->potential(a->initial_state().q), c->potential(c->initial_state().q));
}

TEST(SpringNet, HessianSparsityAndTranslationNullSpace) {
  // Springs per offset: Π_axes (n_a − |o_a|). 8×8 2D: 2·7·8 axis + 2·7·7 diagonal = 210;
  // 3×3×3 3D: 3·18 axis + 6·12 face + 4·8 body diagonal = 158. Each node row has its own block
  // plus one per incident spring: nnz = dim² (nodes + 2 springs).
  const std::vector<std::pair<std::string, long>> expected = {
      {"spring_net", 4 * (64 + 2 * 210)},
      {"spring_net:diagonals=false", 4 * (64 + 2 * 112)},
      {"spring_net:dim=3,nx=3,ny=3,nz=3", 9 * (27 + 2 * 158)},
  };
  for (const auto& [spec, nnz] : expected) {
    const auto problem = make_problem(spec);
    const int dim = dimension_of(*problem);
    const Vec q = deformed(*problem, 17);
    SparseMatrix H;
    problem->hessian(q, H);
    EXPECT_EQ(H.nonZeros(), nnz) << spec;
    for (int axis = 0; axis < dim; ++axis) {
      Vec translation = Vec::Zero(problem->dof());
      for (int node = 0; node < problem->dof() / dim; ++node) translation[dim * node + axis] = 1;
      const double size = Eigen::MatrixXd(H).cwiseAbs().maxCoeff();
      EXPECT_LE((H * translation).lpNorm<Eigen::Infinity>(), 64 * DBL_EPSILON * size) << spec;
    }
  }
}

TEST(SpringNet, CompressedNetHasIndefiniteHessian) {
  // Shrunk to half size every spring is compressed, so its transverse stiffness φ'/r < 0: the
  // Hessian must show negative curvature (buckling) rather than be clamped to PSD.
  const auto problem = make_problem("spring_net:nx=3,ny=3");
  const Vec q = 0.5 * problem->initial_state().q;
  SparseMatrix H;
  problem->hessian(q, H);
  const Eigen::VectorXd eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Eigen::MatrixXd(H)).eigenvalues();
  EXPECT_LT(eigenvalues[0], -1.0);
}

TEST(SpringNet, ThreeDimensionalNonlinearDerivatives) {
  const auto problem = make_problem("spring_net:dim=3,nx=3,ny=2,nz=3,model=nonlinear,quartic=400");
  ASSERT_EQ(dimension_of(*problem), 3);
  ASSERT_EQ(problem->dof(), 3 * 18);
  const Vec q = deformed(*problem, 18, 0.3, 0.0);
  Vec g;
  problem->gradient(q, g);
  SparseMatrix H;
  problem->hessian(q, H);
  const Eigen::MatrixXd dense(H);
  const double h = 1e-5;
  for (int j = 0; j < problem->dof(); ++j) {
    Vec plus = q, minus = q;
    plus[j] += h;
    minus[j] -= h;
    const double slope = (problem->potential(plus) - problem->potential(minus)) / (2 * h);
    EXPECT_NEAR(g[j], slope, 1e-6 * g.lpNorm<Eigen::Infinity>()) << j;
    Vec g_plus, g_minus;
    problem->gradient(plus, g_plus);
    problem->gradient(minus, g_minus);
    const Vec column = (g_plus - g_minus) / (2 * h);
    EXPECT_LE((dense.col(j) - column).lpNorm<Eigen::Infinity>(), 1e-6 * dense.cwiseAbs().maxCoeff())
        << j;
  }
}

TEST(SpringNet, OmegaMaxBoundsFrequenciesForUnequalScalesAnd3D) {
  for (const std::string& spec :
       {std::string("spring_net:nx=4,ny=3,mass=0.3,stiffness=7,model=nonlinear"),
        std::string("spring_net:dim=3,nx=3,ny=3,nz=2,spacing=0.2")}) {
    const auto problem = make_problem(spec);
    for (unsigned seed : {19u, 20u}) {
      const Vec q = deformed(*problem, seed, 0.05, 0.0);
      SparseMatrix H;
      problem->hessian(q, H);
      const Vec scale = problem->inverse_mass().cwiseSqrt();
      const Eigen::MatrixXd scaled = scale.asDiagonal() * Eigen::MatrixXd(H) * scale.asDiagonal();
      const double top =
          Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues().maxCoeff();
      const double omega = problem->omega_max(q);
      EXPECT_GE(omega * (1 + 1e-12), std::sqrt(top)) << spec;
      // It is exactly the Gershgorin bound of the assembled matrix (up to summation order),
      // which over-estimates, but for a lattice by less than a factor of 3 in frequency.
      const Eigen::MatrixXd rows = problem->inverse_mass().asDiagonal() * Eigen::MatrixXd(H);
      const double gershgorin = rows.cwiseAbs().rowwise().sum().maxCoeff();
      EXPECT_NEAR(omega * omega, gershgorin, 1e-13 * gershgorin) << spec;
      EXPECT_LE(omega, 3 * std::sqrt(top)) << spec;
    }
  }
}

TEST(SpringNet, NoSpringStartsCollapsed) {
  // The largest allowed jitter and rest perturbation still give finite forces (a zero-length
  // spring would make n = d/|d| a NaN).
  for (unsigned long seed = 1; seed <= 20; ++seed) {
    const auto problem = make_problem(
        "spring_net:position_jitter=0.4999,rest_perturbation=0.99,"
        "seed=" +
        std::to_string(seed));
    Vec g;
    problem->gradient(problem->initial_state().q, g);
    EXPECT_TRUE(g.allFinite()) << seed;
  }
}

TEST(SpringNet, TenThousandDofNetEvaluates) {
  const auto problem = make_problem("spring_net:nx=71,ny=71,damping=0.1");
  ASSERT_EQ(problem->dof(), 2 * 71 * 71);
  const State start = problem->initial_state();
  Vec g;
  problem->gradient(start.q, g);
  EXPECT_TRUE(g.allFinite());
  SparseMatrix H;
  problem->hessian(start.q, H);
  // 2·70·71 axis + 2·70·70 diagonal springs = 19 740.
  EXPECT_EQ(H.nonZeros(), 4L * (71 * 71 + 2 * 19'740));
  SparseMatrix C;
  force_of(*problem).force_jacobian_v(start.q, start.p, 0.0, C);
  EXPECT_EQ(C.nonZeros(), H.nonZeros());
  const double omega = problem->omega_max(start.q);
  EXPECT_TRUE(std::isfinite(omega) && omega > 0);
}

TEST(SpringNet, BadParametersNameTheKey) {
  const test::InputErrorCases cases = {
      {"spring_net:nx=1", "nx=1"},
      {"spring_net:ny=0", "ny=0"},
      {"spring_net:dim=4", "dim=4"},
      {"spring_net:stiffness=-1", "stiffness=-1"},
      {"spring_net:mass=0", "mass=0"},
      {"spring_net:spacing=-2", "spacing=-2"},
      {"spring_net:nz=3", "nz=3"},
      {"spring_net:position_jitter=0.5", "position_jitter=0.5"},
      {"spring_net:rest_perturbation=1", "rest_perturbation=1"},
      {"spring_net:damping=-0.1", "damping=-0.1"},
      {"spring_net:model=linear", "model"},
      {"spring_net:quartic=-1,model=nonlinear", "quartic=-1"},
      {"spring_net:nx=5000,ny=5000", "nx"},
      {"spring_net:bogus=1", "bogus"},
  };
  EXPECT_TRUE(test::input_errors_name(make_problem, cases));
}

}  // namespace
}  // namespace spring_net_test
}  // namespace geomint
