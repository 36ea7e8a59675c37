// Checks of the stiff FPU chain (GNI §I.5.1) beyond the registry suite: the Hamiltonian against
// GNI's form in the transformed coordinates, the initial values and oscillatory energies there,
// and the stiff frequency.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "problems/problem.hpp"

namespace geomint {
namespace fpu_stiff_test {
namespace {

// GNI (5.2)–(5.3): x₀,ᵢ = (q_{2i} + q_{2i−1})/√2, x₁,ᵢ = (q_{2i} − q_{2i−1})/√2, y likewise.
struct Transformed {
  Vec x0, x1, y0, y1;
};
Transformed transform(const Vec& q, const Vec& p) {
  const int m = static_cast<int>(q.size() / 2);
  Transformed out{Vec(m), Vec(m), Vec(m), Vec(m)};
  for (int i = 0; i < m; ++i) {
    out.x0[i] = (q[2 * i + 1] + q[2 * i]) / std::numbers::sqrt2;
    out.x1[i] = (q[2 * i + 1] - q[2 * i]) / std::numbers::sqrt2;
    out.y0[i] = (p[2 * i + 1] + p[2 * i]) / std::numbers::sqrt2;
    out.y1[i] = (p[2 * i + 1] - p[2 * i]) / std::numbers::sqrt2;
  }
  return out;
}

// GNI (5.4): H = ½Σ(y₀² + y₁²) + ω²/2 Σ x₁² + ¼[(x₀,₁ − x₁,₁)⁴
//   + Σ_{i<m} (x₀,ᵢ₊₁ − x₁,ᵢ₊₁ − x₀,ᵢ − x₁,ᵢ)⁴ + (x₀,ₘ + x₁,ₘ)⁴].
double gni_hamiltonian(const Transformed& x, double omega) {
  const long m = x.x0.size();
  double h =
      0.5 * (x.y0.squaredNorm() + x.y1.squaredNorm()) + 0.5 * omega * omega * x.x1.squaredNorm();
  double quartic = std::pow(x.x0[0] - x.x1[0], 4) + std::pow(x.x0[m - 1] + x.x1[m - 1], 4);
  for (long i = 0; i + 1 < m; ++i)
    quartic += std::pow(x.x0[i + 1] - x.x1[i + 1] - x.x0[i] - x.x1[i], 4);
  return h + 0.25 * quartic;
}

TEST(FpuStiff, HamiltonianMatchesGniTransformedForm) {
  std::mt19937 generator(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const auto& [spec, omega] :
       std::vector<std::pair<std::string, double>>{{"fpu_stiff", 50.0},
                                                   {"fpu_stiff:m=5,omega=7", 7.0},
                                                   {"fpu_stiff:m=1,omega=300", 300.0}}) {
    const auto problem = make_problem(spec);
    for (int trial = 0; trial < 5; ++trial) {
      Vec q(problem->dof()), p(problem->dof());
      for (int i = 0; i < q.size(); ++i) q[i] = uniform(generator), p[i] = uniform(generator);
      const double expected = gni_hamiltonian(transform(q, p), omega);
      EXPECT_NEAR(problem->energy(q, p), expected, 1e-13 * std::abs(expected)) << spec;
    }
  }
}

TEST(FpuStiff, InitialValuesAndOscillatoryEnergiesAtTimeZero) {
  // GNI Fig. 5.1: x₀,₁ = 1, y₀,₁ = 1, x₁,₁ = ω⁻¹, y₁,₁ = 1, zero otherwise, so I₁ = 1.
  const double omega = 50;
  const auto problem = make_problem("fpu_stiff");
  const State start = problem->initial_state();
  const Transformed x = transform(start.q, start.p);
  EXPECT_NEAR(x.x0[0], 1.0, 2 * DBL_EPSILON);
  EXPECT_NEAR(x.y0[0], 1.0, 2 * DBL_EPSILON);
  EXPECT_NEAR(x.x1[0], 1 / omega, 2 * DBL_EPSILON);
  EXPECT_NEAR(x.y1[0], 1.0, 2 * DBL_EPSILON);
  for (int i = 1; i < 3; ++i) {
    EXPECT_EQ(x.x0[i], 0.0);
    EXPECT_EQ(x.x1[i], 0.0);
    EXPECT_EQ(x.y0[i], 0.0);
    EXPECT_EQ(x.y1[i], 0.0);
  }
  EXPECT_EQ(problem->series_names(), (std::vector<std::string>{"I1", "I2", "I3", "I"}));
  std::vector<double> values;
  problem->series_values(start.q, start.p, values);
  ASSERT_EQ(values.size(), 4u);
  EXPECT_NEAR(values[0], 1.0, 4 * DBL_EPSILON);
  EXPECT_EQ(values[1], 0.0);
  EXPECT_EQ(values[2], 0.0);
  EXPECT_NEAR(values[3], 1.0, 4 * DBL_EPSILON);
  // H(0) = ½(1 + 1) + ½ + ¼[(1 − 1/ω)⁴ + (1 + 1/ω)⁴] (the two soft springs next to spring 1).
  const double expected = 1.5 + 0.25 * (std::pow(1 - 1 / omega, 4) + std::pow(1 + 1 / omega, 4));
  EXPECT_NEAR(problem->energy(start.q, start.p), expected, 8 * DBL_EPSILON);
}

TEST(FpuStiff, OscillatoryEnergyOfAStateInOneStiffSpring) {
  // I_j = ½(y₁,ⱼ² + ω²x₁,ⱼ²) at an arbitrary state, spring 2 of m = 4, ω = 30.
  const auto problem = make_problem("fpu_stiff:m=4,omega=30");
  Vec q = Vec::Zero(8), p = Vec::Zero(8);
  q[2] = 0.1, q[3] = 0.25, p[2] = -0.4, p[3] = 0.6;  // nodes of stiff spring 2
  std::vector<double> values;
  problem->series_values(q, p, values);
  const double x1 = (0.25 - 0.1) / std::numbers::sqrt2, y1 = (0.6 + 0.4) / std::numbers::sqrt2;
  EXPECT_NEAR(values[1], 0.5 * (y1 * y1 + 900 * x1 * x1), 1e-14);
  EXPECT_EQ(values[0], 0.0);
  EXPECT_NEAR(values[4], values[1], 1e-15);
}

TEST(FpuStiff, OmegaMaxIsTheStiffFrequencyAtRest) {
  for (double omega : {50.0, 5000.0}) {
    const auto problem = make_problem("fpu_stiff:omega=" + format_number(omega));
    // At q = 0 the soft springs contribute nothing: the stiff spring's ω exactly.
    EXPECT_NEAR(problem->omega_max(Vec::Zero(6)), omega, 1e-12 * omega);
    EXPECT_NEAR(problem->default_dt() * omega, 0.5, 1e-15);
  }
  EXPECT_THROW(make_problem("fpu_stiff:omega=0.5"), InputError);
  EXPECT_THROW(make_problem("fpu_stiff:m=0"), InputError);
}

}  // namespace
}  // namespace fpu_stiff_test
}  // namespace geomint
