// The Toda lattice's Flaschka invariants and the Kepler orbits' eccentricity (Laplace–Runge–Lenz)
// vector: both kept by the exact flow, here a tight RK4 reference (problems/toda.cpp,
// problems/structures/).
#include "problems/structures/toda.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "problems/problem.hpp"
#include "problems/structures/kepler_orbit.hpp"

namespace geomint {
namespace toda_test {
namespace {

// RK4 on the first-order view with `steps` steps to t_end: h·ω ≈ 1e-3 makes its error ~1e-13.
State reference_state(const Problem& problem, double t_end, long steps) {
  const State start = problem.initial_state();
  const int n = problem.dof();
  Vec y(2 * n);
  problem.pack_first_order(start, y.data());
  const double h = t_end / static_cast<double>(steps);
  Vec k1, k2, k3, k4;
  for (long k = 0; k < steps; ++k) {
    const double t = static_cast<double>(k) * h;
    problem.first_order_rhs(t, y, k1);
    problem.first_order_rhs(t + h / 2, y + h / 2 * k1, k2);
    problem.first_order_rhs(t + h / 2, y + h / 2 * k2, k3);
    problem.first_order_rhs(t + h, y + h * k3, k4);
    y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  State end{t_end, Vec(n), Vec(n)};
  problem.unpack_first_order(y.data(), end);
  return end;
}

// Σ|λ_i|ᵏ of L: the scale of tr Lᵏ that stays > 0 when the trace itself is 0 (tr L with Σp = 0).
Vec invariant_scales(const Eigen::MatrixXd& lax) {
  const Vec magnitudes =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(lax).eigenvalues().cwiseAbs();
  Vec scales(lax.rows());
  for (int k = 0; k < lax.rows(); ++k) scales[k] = magnitudes.array().pow(k + 1).sum();
  return scales;
}

TEST(TodaLattice, LaxMatrixTracesAreMomentumAndEnergy) {
  for (const std::string spec : {"toda", "toda:ends=open,n=5,alpha=2,displacement=-0.3"}) {
    const auto problem = make_problem(spec);
    const auto* toda = problem->as<TodaStructure>();
    ASSERT_NE(toda, nullptr) << spec;
    const State start = problem->initial_state();
    const Vec traces = flaschka_invariants(toda->lax_matrix(start.q, start.p));
    ASSERT_EQ(traces.size(), problem->dof());
    EXPECT_NEAR(traces[0], -0.5 * start.p.sum(), 1e-14) << spec;
    EXPECT_NEAR(traces[1], 0.5 * problem->energy(start.q, start.p), 1e-14) << spec;
  }
}

// Every trace tr Lᵏ, k = 1 … n, is the same at t = 20 as at t = 0 to the reference's accuracy,
// periodic and open, while the state itself has moved far.
TEST(TodaLattice, FlaschkaInvariantsAreKeptByTheExactFlow) {
  for (const std::string spec :
       {"toda", "toda:n=3,alpha=0.5,displacement=1,momentum=-0.7",
        "toda:ends=open,n=5,alpha=2,displacement=-0.3,momentum=1.2,velocity=0.4"}) {
    const auto problem = make_problem(spec);
    const auto& toda = *problem->as<TodaStructure>();
    const State start = problem->initial_state();
    const Eigen::MatrixXd lax0 = toda.lax_matrix(start.q, start.p);
    const Vec initial = flaschka_invariants(lax0);
    const Vec scales = invariant_scales(lax0);
    const double omega = problem->omega_max(start.q);
    const State end = reference_state(*problem, 20.0, std::lround(20.0 * omega / 2e-3));
    ASSERT_GT((end.q - start.q).cwiseAbs().maxCoeff(), 0.1) << spec;
    const Vec final_traces = flaschka_invariants(toda.lax_matrix(end.q, end.p));
    for (int k = 0; k < problem->dof(); ++k) {
      EXPECT_LE(std::abs(final_traces[k] - initial[k]), 1e-11 * scales[k])
          << spec << " tr L^" << k + 1 << ": " << initial[k] << " -> " << final_traces[k];
    }
    // The eigenvalues, not only their low moments, are the conserved quantities; a tridiagonal
    // entry is not: the test would pass vacuously if L did not move.
    EXPECT_GT((toda.lax_matrix(end.q, end.p) - lax0).cwiseAbs().maxCoeff(), 1e-2) << spec;
  }
}

// The eccentricity vector of kepler:e=0.6 is (0.6, 0, 0) (perihelion on +x), on the exact solution
// at any time and in polar coordinates; nbody's two-body case keeps its own along a reference.
TEST(KeplerOrbit, EccentricityVectorIsTheOrbitsAndIsKept) {
  for (const std::string spec : {"kepler:e=0.6", "kepler:e=0.6,coordinates=polar"}) {
    const auto problem = make_problem(spec);
    const auto* orbit = problem->as<KeplerOrbitStructure>();
    ASSERT_NE(orbit, nullptr) << spec;
    for (double t : {0.0, 0.7, 2.9, 11.3}) {
      const State state = problem->exact(t);
      const Eigen::Vector3d e = orbit->eccentricity_vector(state.q, state.p);
      EXPECT_LE((e - Eigen::Vector3d(0.6, 0, 0)).norm(), 1e-14) << spec << " t = " << t;
    }
  }
  const std::string two_body =
      "nbody:preset=custom,masses=3/0.25,positions=0/0/1.5/0,velocities=0/-0.1/0/1.3,G=1.3";
  const auto problem = make_problem(two_body);
  const auto* orbit = problem->as<KeplerOrbitStructure>();
  ASSERT_NE(orbit, nullptr);
  const State start = problem->initial_state();
  const Eigen::Vector3d e0 = orbit->eccentricity_vector(start.q, start.p);
  EXPECT_GT(e0.norm(), 0.1);
  const State end = reference_state(*problem, 5.0, 50'000);
  EXPECT_LE((orbit->eccentricity_vector(end.q, end.p) - e0).norm(), 1e-11);
  EXPECT_EQ(make_problem("nbody:preset=outer_solar_system,planets=2")->as<KeplerOrbitStructure>(),
            nullptr);
}

}  // namespace
}  // namespace toda_test
}  // namespace geomint
