// Checks of the elastic bar (docs/METHOD.md §6) beyond the registry suite: P and dP/dF of both
// materials against finite differences (deformed, compressed, inverted), frame invariance, the
// strain-rate damping, the SPD projection, lumped masses, linear-regime frequencies against beam
// theory.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <cfloat>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "problems/force.hpp"
#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace elastic_bar_test {
namespace {

using Vec3 = Eigen::Vector3d;
using Dense = Eigen::MatrixXd;

constexpr double kPi = std::numbers::pi;

using test::random_vector;

Eigen::Matrix3d random_rotation(unsigned seed) {
  const Vec r = random_vector(4, seed);
  return Eigen::Quaterniond(r[0], r[1], r[2], r[3]).normalized().toRotationMatrix();
}

// Applies x ↦ A x + t to every node of q (q holds node positions, 3 per node).
Vec map_nodes(const Vec& q, const Eigen::Matrix3d& A, const Vec3& t) {
  Vec out(q.size());
  for (int i = 0; i < q.size(); i += 3) out.segment<3>(i) = A * q.segment<3>(i) + t;
  return out;
}

Vec3 net(const Vec& f) {
  Vec3 total = Vec3::Zero();
  for (int i = 0; i < f.size(); i += 3) total += f.segment<3>(i);
  return total;
}
Vec3 torque(const Vec& q, const Vec& f) {
  Vec3 total = Vec3::Zero();
  for (int i = 0; i < f.size(); i += 3) total += Vec3(q.segment<3>(i)).cross(Vec3(f.segment<3>(i)));
  return total;
}
// Σ|x_i||f_i|: the size of the terms a torque sum cancels.
double torque_scale(const Vec& q, const Vec& f) {
  double sum = 0;
  for (int i = 0; i < f.size(); i += 3) sum += q.segment<3>(i).norm() * f.segment<3>(i).norm();
  return sum;
}

double inf_norm(const Vec& v) { return v.lpNorm<Eigen::Infinity>(); }

// Richardson-extrapolated central difference (4 D(h) − D(2h))/3: truncation O(h⁴). Plain central
// differences leave an O(h²) error that, for an elastic energy near rest (a large third
// derivative, a small gradient), is bigger than the gradient itself.
template <class Fn>
auto richardson(const Fn& f, const Vec& q, int j, double h) {
  Vec plus = q, minus = q, plus2 = q, minus2 = q;
  plus[j] += h;
  minus[j] -= h;
  plus2[j] += 2 * h;
  minus2[j] -= 2 * h;
  using Value = decltype(f(q));
  const Value near = f(plus) - f(minus);
  const Value far = f(plus2) - f(minus2);
  return Value((8 * near - far) / (12 * h));
}

std::string small_bar(const std::string& material, const std::string& clamp) {
  return "elastic_bar:nx=2,ny=1,nz=1,init=rest,material=" + material + ",clamp=" + clamp;
}

// Test configurations of the small bar (cells 0.5 × 0.2 × 0.2).
enum class Shape { kDeformed, kCompressed, kInverted };

Vec shaped(const Problem& problem, Shape shape, unsigned seed) {
  const Vec rest = problem.initial_state().q;
  const Vec noise = random_vector(problem.dof(), seed);
  switch (shape) {
    case Shape::kDeformed:  // strains of ~10%, plus a rotation so that F is far from symmetric
      return map_nodes(rest + 0.03 * noise, random_rotation(seed + 1), Vec3(0.2, -0.1, 0.3));
    case Shape::kCompressed:  // J = 0.6 · 0.7 · 0.7 ≈ 0.29
      return map_nodes(rest, Vec3(0.6, 0.7, 0.7).asDiagonal(), Vec3::Zero()) + 0.003 * noise;
    case Shape::kInverted:  // mirror image: J < 0 in every element
      return map_nodes(rest, Vec3(1, 1, -1).asDiagonal(), Vec3::Zero()) + 0.01 * noise;
  }
  return rest;
}

TEST(ElasticBar, GradientAndHessianMatchFiniteDifferences) {
  struct Case {
    std::string material;
    Shape shape;
  };
  const std::vector<Case> cases = {
      {"neohookean", Shape::kDeformed}, {"neohookean", Shape::kCompressed},
      {"stvk", Shape::kDeformed},       {"stvk", Shape::kCompressed},
      {"stvk", Shape::kInverted},
  };
  for (const auto& [material, shape] : cases) {
    // Free (no gravity) and clamped with gravity, which take different paths through the code.
    for (const std::string clamp : {"none", "left"}) {
      const auto problem = make_problem(small_bar(material, clamp));
      const Vec q = shaped(*problem, shape, 3);
      const std::string label =
          material + " shape " + std::to_string(static_cast<int>(shape)) + " clamp=" + clamp;
      const double V = problem->potential(q);
      ASSERT_TRUE(std::isfinite(V)) << label;
      Vec g;
      problem->gradient(q, g);
      SparseMatrix H;
      problem->hessian(q, H);
      const Dense dense(H);
      // Bitwise symmetric: element blocks are symmetrised and assembled in the same order.
      EXPECT_EQ((dense - dense.transpose()).cwiseAbs().maxCoeff(), 0.0) << label;
      // h = 1e-4 of a 0.2 cell: Richardson truncation ~h⁴ ≈ 1e-16 relative; the rounding of V
      // (≈ ε|V|/h ≈ 1e-12|V|) and of g (≈ ε|g|/h) set the allowances.
      const double h = 1e-4;
      const double g_tol = 1e-8 * inf_norm(g) + 1e3 * DBL_EPSILON * std::abs(V) / h;
      const double H_tol = 1e-8 * dense.cwiseAbs().maxCoeff() + 1e3 * DBL_EPSILON * inf_norm(g) / h;
      const auto potential = [&](const Vec& x) { return problem->potential(x); };
      const auto gradient = [&](const Vec& x) {
        Vec y;
        problem->gradient(x, y);
        return y;
      };
      for (int j = 0; j < problem->dof(); ++j) {
        EXPECT_NEAR(g[j], richardson(potential, q, j, h), g_tol) << label << " component " << j;
        const Vec column = richardson(gradient, q, j, h);
        EXPECT_LE(inf_norm(dense.col(j) - column), H_tol) << label << " column " << j;
      }
    }
  }
}

// The exact Hessian at a strongly compressed state is indefinite for both materials (the StVK
// stress is compressive; the neo-Hookean (μ − λ ln J) Q_il Q_kj term has negative eigenvalues).
TEST(ElasticBar, CompressedHessianIsIndefinite) {
  for (const std::string material : {"neohookean", "stvk"}) {
    const auto problem = make_problem("elastic_bar:nx=4,ny=1,nz=1,material=" + material);
    const Vec q = map_nodes(problem->initial_state().q, Vec3(0.5, 1, 1).asDiagonal(), Vec3::Zero());
    SparseMatrix H;
    problem->hessian(q, H);
    const Vec eigenvalues = Eigen::SelfAdjointEigenSolver<Dense>(Dense(H)).eigenvalues();
    EXPECT_LT(eigenvalues.minCoeff(), -1e-3 * eigenvalues.maxCoeff()) << material;
  }
}

TEST(ElasticBar, NeoHookeanInvertedIsInfiniteAndFlagged) {
  const auto problem = make_problem(small_bar("neohookean", "none"));
  const Vec q = shaped(*problem, Shape::kInverted, 5);
  EXPECT_EQ(problem->potential(q), std::numeric_limits<double>::infinity());
  Vec g;
  problem->gradient(q, g);
  EXPECT_TRUE(g.hasNaN());
  SparseMatrix H;
  problem->hessian(q, H);
  EXPECT_TRUE(Dense(H).hasNaN());
  EXPECT_EQ(problem->omega_max(q), std::numeric_limits<double>::infinity());
  // StVK is defined there and invariant under reflection (it depends on FᵀF only).
  const auto stvk = make_problem(small_bar("stvk", "none"));
  const Vec rest = stvk->initial_state().q;
  const Vec mirrored = map_nodes(rest + 0.02 * random_vector(stvk->dof(), 6),
                                 Vec3(1, 1, -1).asDiagonal(), Vec3::Zero());
  EXPECT_NEAR(stvk->potential(mirrored),
              stvk->potential(map_nodes(mirrored, Vec3(1, 1, -1).asDiagonal(), Vec3::Zero())),
              1e-12 * stvk->potential(mirrored));
}

TEST(ElasticBar, EnergyIsFrameInvariantAndZeroAtRest) {
  for (const std::string material : {"neohookean", "stvk"}) {
    const auto problem =
        make_problem("elastic_bar:nx=3,ny=2,nz=2,clamp=none,init=rest,material=" + material);
    const Vec rest = problem->initial_state().q;
    // F = I + U G with U = 0: exactly zero, no rounding.
    EXPECT_EQ(problem->potential(rest), 0.0) << material;
    Vec g;
    problem->gradient(rest, g);
    EXPECT_EQ(inf_norm(g), 0.0) << material;
    // A rigid motion of the rest state is still stress-free (to rounding of F = R).
    const Vec moved_rest = map_nodes(rest, random_rotation(7), Vec3(1, 2, 3));
    const auto problem_scale = make_problem("elastic_bar:nx=3,ny=2,nz=2,clamp=none,init=rest");
    for (unsigned seed : {8u, 9u, 10u}) {
      const Vec q = rest + 0.02 * random_vector(problem->dof(), seed);
      const double before = problem->potential(q);
      ASSERT_GT(before, 0.0);
      const Vec moved = map_nodes(q, random_rotation(seed + 20), Vec3(3, -2, 5));
      // F becomes R F: E and J are unchanged up to the rounding of R and of the products.
      EXPECT_NEAR(problem->potential(moved), before, 1e-10 * before) << material << " " << seed;
      EXPECT_LE(problem->potential(moved_rest), 1e-10 * before) << material;
    }
  }
}

TEST(ElasticBar, ElasticForcesHaveZeroNetForceAndTorque) {
  for (const std::string material : {"neohookean", "stvk"}) {
    const auto problem =
        make_problem("elastic_bar:nx=3,ny=2,nz=2,clamp=none,init=rest,material=" + material);
    const Vec q = map_nodes(problem->initial_state().q + 0.03 * random_vector(problem->dof(), 11),
                            random_rotation(12), Vec3(4, -3, 2));
    Vec g;
    problem->gradient(q, g);
    ASSERT_GT(inf_norm(g), 0.0);
    // Each element's nodal forces sum to zero exactly in exact arithmetic (Σ_a G_a = 0) and have
    // zero moment because P Fᵀ is symmetric; rounding leaves a few hundred ulps of the terms.
    EXPECT_LE(net(g).lpNorm<Eigen::Infinity>(), 256 * DBL_EPSILON * g.lpNorm<1>()) << material;
    EXPECT_LE(torque(q, g).lpNorm<Eigen::Infinity>(), 256 * DBL_EPSILON * torque_scale(q, g))
        << material;
  }
}

TEST(ElasticBar, DampingIsFrameInvariantDissipativeAndLinear) {
  const auto problem =
      make_problem("elastic_bar:nx=3,ny=2,nz=2,clamp=none,init=rest,damping=0.02,material=stvk");
  ASSERT_TRUE(problem->has(kForce));
  ASSERT_TRUE(problem->has(kForceJacobian));
  const int n = problem->dof();
  const Vec q = map_nodes(problem->initial_state().q + 0.03 * random_vector(n, 13),
                          random_rotation(14), Vec3(1, 1, -2));
  SparseMatrix C;
  force_of(*problem).force_jacobian_v(q, Vec::Zero(n), 0.0, C);
  const Dense dense(C);
  EXPECT_EQ((dense - dense.transpose()).cwiseAbs().maxCoeff(), 0.0);
  const Vec eigenvalues = Eigen::SelfAdjointEigenSolver<Dense>(dense).eigenvalues();
  // PSD with exactly six zero modes (the rigid velocities); 1e-12 relative is rounding.
  EXPECT_GE(eigenvalues.minCoeff(), -1e-12 * eigenvalues.maxCoeff());
  EXPECT_LE(std::abs(eigenvalues[5]), 1e-12 * eigenvalues.maxCoeff());
  EXPECT_GT(eigenvalues[6], 1e-6 * eigenvalues.maxCoeff());

  for (unsigned seed : {15u, 16u, 17u}) {
    const Vec v = random_vector(n, seed);
    Vec f;
    force_of(*problem).force(q, v, 0.0, f);
    // Dissipation vᵀf = −2D < 0, zero net force and torque (Ė depends on relative motion).
    EXPECT_LT(v.dot(f), -1e-3 * v.norm() * f.norm());
    EXPECT_LE(net(f).lpNorm<Eigen::Infinity>(), 256 * DBL_EPSILON * f.lpNorm<1>());
    EXPECT_LE(torque(q, f).lpNorm<Eigen::Infinity>(), 256 * DBL_EPSILON * torque_scale(q, f));
    // f is linear in v, f = −C v.
    EXPECT_LE(inf_norm(f + C * v), 1e-12 * inf_norm(f));
    // C against central differences of −f in v, exact up to rounding because f is linear.
    const auto minus_force = [&](const Vec& w) {
      Vec y;
      force_of(*problem).force(q, w, 0.0, y);
      return Vec(-y);
    };
    for (int j = 0; j < n; j += 7) {
      EXPECT_LE(inf_norm(dense.col(j) - richardson(minus_force, v, j, 1e-3)),
                1e-9 * dense.cwiseAbs().maxCoeff())
          << "column " << j;
    }
  }

  // A rigid velocity field v = ω × x + c has Ė = 0: no damping force, to rounding.
  Vec rigid(n);
  const Vec3 omega(0.3, -1.1, 0.7), drift(0.5, 0.2, -0.4);
  for (int i = 0; i < n; i += 3) rigid.segment<3>(i) = omega.cross(Vec3(q.segment<3>(i))) + drift;
  const Vec generic = random_vector(n, 18);
  Vec f_rigid, f_generic;
  force_of(*problem).force(q, rigid, 0.0, f_rigid);
  force_of(*problem).force(q, generic, 0.0, f_generic);
  EXPECT_LE(inf_norm(f_rigid), 1e-12 * inf_norm(f_generic) / inf_norm(generic) * inf_norm(rigid));
}

// In the linear limit the strain-rate damping is stiffness-proportional, C = ν K (docs/METHOD.md
// §6): at rest both materials' Hessians are the linear-elastic stiffness, and so is C/ν.
TEST(ElasticBar, DampingAtRestIsStiffnessProportional) {
  for (const std::string material : {"neohookean", "stvk"}) {
    const auto problem = make_problem("elastic_bar:nx=3,damping=0.01,material=" + material);
    const Vec rest = problem->initial_state().q;
    SparseMatrix C, K;
    force_of(*problem).force_jacobian_v(rest, Vec::Zero(problem->dof()), 0.0, C);
    problem->hessian(rest, K);
    const Dense difference = Dense(C) - 0.01 * Dense(K);
    EXPECT_LE(difference.cwiseAbs().maxCoeff(), 1e-13 * Dense(C).cwiseAbs().maxCoeff()) << material;
  }
}

TEST(ElasticBar, ProjectedHessianIsPositiveDefinite) {
  for (const std::string material : {"neohookean", "stvk"}) {
    const std::string spec = "elastic_bar:nx=4,ny=1,nz=1,material=" + material;
    const auto exact = make_problem(spec);
    const auto projected = make_problem(spec + ",proj_spd=true");
    const Vec rest = exact->initial_state().q;
    const Vec q = map_nodes(rest, Vec3(0.5, 1, 1).asDiagonal(), Vec3::Zero());
    SparseMatrix H_exact, H;
    exact->hessian(q, H_exact);
    projected->hessian(q, H);
    EXPECT_LT(Eigen::SelfAdjointEigenSolver<Dense>(Dense(H_exact)).eigenvalues().minCoeff(), 0.0);
    Eigen::SimplicialLDLT<SparseMatrix> ldlt(H);
    ASSERT_EQ(ldlt.info(), Eigen::Success) << material;
    EXPECT_GT(ldlt.vectorD().minCoeff(), 0.0) << material;
    // At rest the element Hessians are PSD already, so the projection only moves the zero
    // (rigid) eigenvalues by rounding.
    SparseMatrix K_exact, K;
    exact->hessian(rest, K_exact);
    projected->hessian(rest, K);
    EXPECT_LE((Dense(K) - Dense(K_exact)).cwiseAbs().maxCoeff(),
              1e-10 * Dense(K_exact).cwiseAbs().maxCoeff())
        << material;
  }
}

TEST(ElasticBar, LumpedMassesSumToTotalMass) {
  const auto free = make_problem(
      "elastic_bar:nx=5,ny=3,nz=2,length=2,width=0.3,height=0.1,density=700,clamp=none");
  const double total = 700 * 2 * 0.3 * 0.1;
  EXPECT_NEAR(free->mass().sum() / 3, total, 1e-12 * total);
  for (int i = 0; i < free->dof(); i += 3) {
    EXPECT_EQ(free->mass()[i], free->mass()[i + 1]);
    EXPECT_EQ(free->mass()[i], free->mass()[i + 2]);
  }
  // Clamping drops the 4 × 3 nodes of the face x = 0, with their share of the mass.
  const auto clamped =
      make_problem("elastic_bar:nx=5,ny=3,nz=2,length=2,width=0.3,height=0.1,density=700");
  EXPECT_EQ(clamped->dof(), free->dof() - 3 * 4 * 3);
  // The lumped share of the face x = 0 is half the first layer of cells (corner weights 1/4 for
  // the two ends of the Kuhn diagonal, 1/12 for the other six): 1/(2 nx) of the total.
  EXPECT_NEAR(clamped->mass().sum() / 3, 0.9 * total, 1e-12 * total);
}

// Lowest eigenpairs of M⁻¹K (K positive definite: clamped bar) by subspace iteration with a
// sparse LDLT of M^(−½) K M^(−½); returns ω and the fraction of each mode's motion along x.
struct Modes {
  Vec omega;
  Vec axial_fraction;
};
Modes lowest_modes(const Problem& problem, int count) {
  SparseMatrix K;
  problem.hessian(problem.initial_state().q, K);
  const Vec scale = problem.inverse_mass().cwiseSqrt();
  const SparseMatrix A = scale.asDiagonal() * K * scale.asDiagonal();
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(A);
  const int n = problem.dof();
  const int block = count + 8;  // extra vectors speed up convergence of the wanted ones
  Dense X = Dense::Random(n, block);
  Vec lambda;
  Dense vectors;
  for (int iteration = 0; iteration < 80; ++iteration) {
    const Dense Y = ldlt.solve(X);
    const Dense Q = Eigen::HouseholderQR<Dense>(Y).householderQ() * Dense::Identity(n, block);
    Eigen::SelfAdjointEigenSolver<Dense> ritz(Q.transpose() * (A * Q));
    lambda = ritz.eigenvalues();
    X = vectors = Q * ritz.eigenvectors();
  }
  Modes modes{Vec(count), Vec(count)};
  for (int k = 0; k < count; ++k) {
    const Vec u = scale.asDiagonal() * vectors.col(k);
    double axial = 0;
    for (int i = 0; i < n; i += 3) axial += u[i] * u[i];
    modes.omega[k] = std::sqrt(lambda[k]);
    modes.axial_fraction[k] = axial / u.squaredNorm();
  }
  return modes;
}

// Clamped-free bar, L = 1, square section h = 0.1 (slender, L/h = 10), E = 1e5, ρ = 1000:
// first longitudinal mode (π/2L)√(E/ρ) = 15.708, first bending mode (Euler–Bernoulli)
// 1.8751²/L² √(EI/(ρA)), I = h⁴/12, = 1.0150. Measured (nx × n × n cells):
//   mesh      bending (two directions)   longitudinal
//   20×2×2    1.310, 1.554 (+29%, +53%)  15.82 (+0.7%)
//   40×4×4    1.098, 1.178 ( +8%, +16%)  15.78 (+0.5%)
//   80×8×8    1.035, 1.057 ( +2%,  +4%)  15.76 (+0.4%)
// Linear tetrahedra lock in bending (a linear element cannot represent the linear-in-thickness
// axial strain without spurious shear), so bending converges from above and needs ≥ 4 elements
// across the section; the two bending frequencies split because the Kuhn split singles out the
// (1, 1, 1) diagonal. The longitudinal mode is nearly exact; its remaining +0.4% is 3D (the clamp
// stops the lateral Poisson contraction), not discretisation.
TEST(ElasticBar, LinearFrequenciesMatchBeamTheory) {
  const double E = 1e5, rho = 1000, L = 1, h = 0.1;
  const double longitudinal = kPi / (2 * L) * std::sqrt(E / rho);
  const double bending = 1.875104 * 1.875104 / (L * L) * std::sqrt(E * h * h / (12 * rho));
  const std::string base = "elastic_bar:gravity=0,width=0.1,height=0.1,";

  // Coarse mesh: the dense generalized eigenproblem K u = ω² M u, also a check of lowest_modes.
  const auto coarse = make_problem(base + "nx=20,ny=2,nz=2");
  SparseMatrix K;
  coarse->hessian(coarse->initial_state().q, K);
  const Dense M = coarse->mass().asDiagonal();
  const Vec dense_omega =
      Eigen::GeneralizedSelfAdjointEigenSolver<Dense>(Dense(K), M, Eigen::EigenvaluesOnly)
          .eigenvalues()
          .cwiseSqrt();
  const Modes coarse_modes = lowest_modes(*coarse, 8);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(coarse_modes.omega[k], dense_omega[k], 1e-8);

  const Modes fine_modes = lowest_modes(*make_problem(base + "nx=40,ny=4,nz=4"), 8);
  double previous_error = std::numeric_limits<double>::infinity();
  for (const Modes* modes : {&coarse_modes, &fine_modes}) {
    // The two lowest modes are the bending pair (little axial motion); the longitudinal mode is
    // the first that is almost purely axial.
    EXPECT_LT(modes->axial_fraction[0], 0.05);
    EXPECT_LT(modes->axial_fraction[1], 0.05);
    int axial = 0;
    while (axial < 8 && modes->axial_fraction[axial] < 0.9) ++axial;
    ASSERT_LT(axial, 8) << "no longitudinal mode among the lowest 8";
    EXPECT_NEAR(modes->omega[axial], longitudinal, 0.02 * longitudinal);
    const double error = 0.5 * (modes->omega[0] + modes->omega[1]) / bending - 1;
    EXPECT_GT(error, 0.0) << "linear tetrahedra are too stiff in bending, never too soft";
    EXPECT_LT(error, previous_error) << "refinement must reduce the bending error";
    previous_error = error;
  }
  // 40×4×4: both bending frequencies within 20% (locking; see the table above).
  EXPECT_NEAR(fine_modes.omega[0], bending, 0.2 * bending);
  EXPECT_NEAR(fine_modes.omega[1], bending, 0.2 * bending);
}

// omega_max bounds the highest frequency of the exact Hessian at q (the registry check skips
// problems with more than 200 dof). At the defaults (8×2×2 cells, 216 dof) it is 450.5 against a
// true 344.0, so the explicit (Störmer–Verlet) limit 2/omega_max ≈ 4.4e-3 > default dt 1e-3.
TEST(ElasticBar, OmegaMaxBoundsHighestFrequency) {
  for (const std::string spec :
       {"elastic_bar", "elastic_bar:material=stvk,clamp=none,nx=3", "elastic_bar:init=twist"}) {
    const auto problem = make_problem(spec);
    const Vec rest = problem->initial_state().q;
    for (const Vec& q : {rest, Vec(rest + 0.01 * random_vector(problem->dof(), 19))}) {
      SparseMatrix H;
      problem->hessian(q, H);
      const Vec scale = problem->inverse_mass().cwiseSqrt();
      const Dense scaled = scale.asDiagonal() * Dense(H) * scale.asDiagonal();
      const double top = std::sqrt(
          std::max(Eigen::SelfAdjointEigenSolver<Dense>(scaled).eigenvalues().maxCoeff(), 0.0));
      const double omega = problem->omega_max(q);
      EXPECT_GE(omega, top) << spec;
      // The element-by-element bound is not wildly pessimistic either.
      EXPECT_LE(omega, 2 * top) << spec;
    }
  }
}

TEST(ElasticBar, InitialConditions) {
  // Twist: the end face is rotated by `twist` about the axis (y, z) = (0.1, 0.1).
  const auto twisted = make_problem("elastic_bar:init=twist,twist=0.8");
  const auto rest = make_problem("elastic_bar");
  const Vec q = twisted->initial_state().q;
  const Vec x = rest->initial_state().q;
  for (int i = 0; i < q.size(); i += 3) {
    if (x[i] != 1.0) continue;
    const double angle =
        std::atan2(q[i + 2] - 0.1, q[i + 1] - 0.1) - std::atan2(x[i + 2] - 0.1, x[i + 1] - 0.1);
    if (Vec3(x.segment<3>(i)) == Vec3(1, 0.1, 0.1)) continue;  // on the axis
    EXPECT_NEAR(std::remainder(angle, 2 * kPi), 0.8, 1e-12);
  }
  // Bend: tip_z is the mean end-face deflection, bend·(x/L)² = bend there; zero at rest.
  std::vector<double> values;
  const auto bent = make_problem("elastic_bar:init=bend,bend=0.07");
  bent->series_values(bent->initial_state().q, bent->initial_state().p, values);
  ASSERT_EQ(bent->series_names(), std::vector<std::string>{"tip_z"});
  EXPECT_NEAR(values.at(0), 0.07, 1e-15);
  rest->series_values(x, rest->initial_state().p, values);
  EXPECT_EQ(values.at(0), 0.0);
  // Velocity (the free bar's default): spin about the centre of mass adds no linear momentum, the
  // shake adds Σ m shake (x/L)² along z; both momenta are non-zero.
  const auto moving = make_problem("elastic_bar:clamp=none");
  EXPECT_EQ(Spec::parse(moving->spec()).values.at("init"), "velocity");
  EXPECT_TRUE(moving->has(kLinearMomentum) && moving->has(kAngularMomentum));
  const State start = moving->initial_state();
  double expected_z = 0;
  for (int i = 0; i < start.q.size(); i += 3) {
    expected_z += moving->mass()[i] * 0.5 * start.q[i] * start.q[i];
  }
  const Vec momentum = moving->linear_momentum(start.q, start.p);
  EXPECT_NEAR(momentum[0], 0.0, 1e-12);
  EXPECT_NEAR(momentum[1], 0.0, 1e-12);
  EXPECT_NEAR(momentum[2], expected_z, 1e-12 * expected_z);
  EXPECT_GT(moving->angular_momentum(start.q, start.p).norm(), 1.0);
}

// Symplectic Euler on the free bar with damping: the elastic and damping forces are torque-free
// at q_k, so p_{k+1} = p_k + h f(q_k, v_k) keeps Σ p and, with q_{k+1} = q_k + h M⁻¹p_{k+1},
// Σ q × p, to rounding, while the energy decays.
TEST(ElasticBar, DampedFreeBarConservesMomenta) {
  const auto problem = make_problem("elastic_bar:clamp=none,nx=4,damping=0.005,spin=2,shake=1");
  State state = problem->initial_state();
  const Vec momentum0 = problem->linear_momentum(state.q, state.p);
  const Vec angular0 = problem->angular_momentum(state.q, state.p);
  const double energy0 = problem->energy(state.q, state.p);
  const double h = 1e-3;
  for (int step = 0; step < 300; ++step) {
    Vec g, f;
    const Vec v = problem->inverse_mass().cwiseProduct(state.p);
    problem->gradient(state.q, g);
    force_of(*problem).force(state.q, v, state.t, f);
    state.p += h * (f - g);
    state.q += h * problem->inverse_mass().cwiseProduct(state.p);
    state.t += h;
  }
  const double p_scale = state.p.lpNorm<1>();
  EXPECT_LE(inf_norm(problem->linear_momentum(state.q, state.p) - momentum0), 1e-12 * p_scale);
  EXPECT_LE(inf_norm(problem->angular_momentum(state.q, state.p) - angular0),
            1e-12 * p_scale * inf_norm(state.q));
  EXPECT_LT(problem->energy(state.q, state.p), energy0);
}

TEST(ElasticBar, BadParametersNameTheKey) {
  const test::InputErrorCases cases = {
      {"elastic_bar:nx=0", "nx"},
      {"elastic_bar:poisson=0.5", "poisson"},
      {"elastic_bar:poisson=-0.1", "poisson"},
      {"elastic_bar:material=foo", "material"},
      {"elastic_bar:clamp=right", "clamp"},
      {"elastic_bar:clamp=none,gravity=9.81", "gravity"},
      {"elastic_bar:nx=1000,ny=100,nz=100", "nx"},
      {"elastic_bar:young=0", "young"},
      {"elastic_bar:damping=-1", "damping"},
      {"elastic_bar:init=spin", "init"},
  };
  EXPECT_TRUE(test::input_errors_name(make_problem, cases));
  // The free bar's gravity defaults to 0, so clamp=none alone is valid.
  EXPECT_EQ(Spec::parse(make_problem("elastic_bar:clamp=none")->spec()).values.at("gravity"), "0");
}

// 66 × 16 × 16 cells = 101 376 tetrahedra, 57 222 dof: build, gradient and Hessian (speed is
// measured in bench/bench_elastic_bar.cpp, not asserted here).
TEST(ElasticBar, HundredThousandTetrahedra) {
  const auto problem = make_problem("elastic_bar:nx=66,ny=16,nz=16");
  ASSERT_EQ(problem->dof(), 3 * 66 * 17 * 17);
  const Vec q = problem->initial_state().q + 1e-3 * random_vector(problem->dof(), 21);
  EXPECT_TRUE(std::isfinite(problem->potential(q)));
  Vec g;
  problem->gradient(q, g);
  EXPECT_TRUE(g.allFinite());
  SparseMatrix H;
  problem->hessian(q, H);
  EXPECT_EQ(H.rows(), problem->dof());
  // At most 15 neighbours (itself included) per node in the Kuhn mesh: ≤ 45 entries per row.
  EXPECT_LE(H.nonZeros(), 45L * problem->dof());
  EXPECT_TRUE(Eigen::Map<const Vec>(H.valuePtr(), H.nonZeros()).allFinite());
}

}  // namespace
}  // namespace elastic_bar_test
}  // namespace geomint
