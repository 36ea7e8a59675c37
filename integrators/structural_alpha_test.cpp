// HHT and generalized-α (integrators/newmark.cpp; Chung & Hulbert 1993, docs/METHOD.md §7): the
// high-frequency dissipation each declares. The spectral radius of the one-step amplification
// matrix on (q, v, a) of the harmonic oscillator at hω = 10⁶ is the requested ρ∞.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <complex>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"

namespace geomint {
namespace structural_alpha_test {
namespace {

constexpr double kHugeStep = 1e6;  // h·ω with ω = 1: the hω → ∞ limit up to O((hω)⁻²)
constexpr int kSteps = 7;

// The amplification matrix A acts on (q, v, a), but a run shows only (q, v): by Cayley–Hamilton
// every component of every orbit obeys x_{k+3} = c₂x_{k+2} + c₁x_{k+1} + c₀x_k with A's
// characteristic polynomial, so the coefficients are fitted (least squares, each row normalised)
// to the orbits of the unit states (1, 0) and (0, 1) — stepped by the integrator itself, which
// carries a between steps — and the eigenvalues are the roots, from the companion matrix. Only
// v is fitted: at hω = 10⁶ the position q₁ = q₀ + hv₀ + h²(…) is an O(1) difference of O(h²a)
// terms and keeps only ~5 digits, while v is accurate to round-off.
// `restart_every_step` resets before each step instead (the "consistent acceleration at every
// step" alternative, a two-term method).
std::vector<std::complex<double>> amplification_eigenvalues(const std::string& spec,
                                                            bool restart_every_step = false) {
  const auto problem = make_problem("harmonic:omega=1");
  std::vector<std::vector<double>> sequences;
  for (int start = 0; start < 2; ++start) {
    const auto method = make_integrator(spec);
    State state{0.0, Vec::Constant(1, start == 0 ? 1.0 : 0.0),
                Vec::Constant(1, start == 1 ? 1.0 : 0.0)};
    method->reset(*problem, state, kHugeStep);
    std::vector<double> v{state.p[0]};
    for (int k = 0; k < kSteps; ++k) {
      if (restart_every_step) method->reset(*problem, state, kHugeStep);
      EXPECT_TRUE(method->step(*problem, state, kHugeStep).ok);
      v.push_back(state.p[0]);
    }
    sequences.push_back(v);
  }
  const int order = restart_every_step ? 2 : 3;
  std::vector<Eigen::VectorXd> rows;
  std::vector<double> rhs;
  for (const auto& x : sequences) {
    for (int k = 0; k + order < static_cast<int>(x.size()); ++k) {
      Eigen::VectorXd row(order);
      for (int j = 0; j < order; ++j) row[j] = x[k + j];
      const double scale = std::max(row.cwiseAbs().maxCoeff(), std::abs(x[k + order]));
      if (scale < 1e-300) continue;  // the orbit has died out (ρ∞ = 0)
      rows.push_back(row / scale);
      rhs.push_back(x[k + order] / scale);
    }
  }
  Eigen::MatrixXd system(rows.size(), order);
  Eigen::VectorXd right(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) system.row(i) = rows[i], right[i] = rhs[i];
  const Eigen::VectorXd c = system.colPivHouseholderQr().solve(right);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(order, order);
  for (int j = 0; j < order; ++j) companion(order - 1, j) = c[j];
  for (int j = 0; j + 1 < order; ++j) companion(j, j + 1) = 1.0;
  const Eigen::VectorXcd roots = Eigen::EigenSolver<Eigen::MatrixXd>(companion).eigenvalues();
  return {roots.data(), roots.data() + roots.size()};
}

double spectral_radius(const std::vector<std::complex<double>>& eigenvalues) {
  double radius = 0;
  for (const auto& lambda : eigenvalues) radius = std::max(radius, std::abs(lambda));
  return radius;
}

TEST(GeneralizedAlpha, SpectralRadiusAtInfiniteStepIsTheRequestedRhoInf) {
  for (const double rho : {0.2, 0.5, 0.8, 0.9}) {
    const std::string spec = "generalized_alpha:rho_inf=" + std::to_string(rho);
    SCOPED_TRACE(spec);
    const auto eigenvalues = amplification_eigenvalues(spec);
    // Chung & Hulbert's choice puts all three roots at −ρ∞: a triple root, which moves by the
    // cube root of the fit's error (the orbits (a + bk + ck²)(−ρ∞)ᵏ make a nearly singular
    // least-squares system), so the roots are checked to 1e-3 and the characteristic
    // polynomial (λ + ρ∞)³ = λ³ + 3ρ∞λ² + 3ρ∞²λ + ρ∞³ (measured to ~1e-4) to 1e-3 too.
    EXPECT_NEAR(spectral_radius(eigenvalues), rho, 1e-3);
    for (const auto& lambda : eigenvalues) EXPECT_NEAR(std::abs(lambda + rho), 0.0, 3e-3);
    ASSERT_EQ(eigenvalues.size(), 3u);
    const auto& l = eigenvalues;
    EXPECT_NEAR(-(l[0] + l[1] + l[2]).real(), 3 * rho, 1e-3);
    EXPECT_NEAR((l[0] * l[1] + l[1] * l[2] + l[0] * l[2]).real(), 3 * rho * rho, 1e-3);
    EXPECT_NEAR(-(l[0] * l[1] * l[2]).real(), rho * rho * rho, 1e-3);
  }
}

// ρ∞ = 1 is the trapezoidal rule: no high-frequency damping (|λ| = 1 up to the fit).
TEST(GeneralizedAlpha, RhoInfOneDoesNotDamp) {
  const auto eigenvalues = amplification_eigenvalues("generalized_alpha:rho_inf=1");
  EXPECT_NEAR(spectral_radius(eigenvalues), 1.0, 1e-4);
}

TEST(Hht, SpectralRadiusAtInfiniteStepIsOnePlusAlphaOverOneMinusAlpha) {
  for (const double alpha : {-0.3, -0.2, -0.1, -0.05}) {
    const std::string spec = "hht:alpha=" + std::to_string(alpha);
    SCOPED_TRACE(spec);
    EXPECT_NEAR(spectral_radius(amplification_eigenvalues(spec)), (1 + alpha) / (1 - alpha), 1e-4);
  }
}

// Why the acceleration is carried between steps: recomputing the consistent a = M⁻¹f(q) at every
// step makes a different, two-term method that does not damp as requested.
TEST(GeneralizedAlpha, RestartingFromTheConsistentAccelerationLosesTheRequestedDamping) {
  const double rho = 0.5;
  const double restarted =
      spectral_radius(amplification_eigenvalues("generalized_alpha:rho_inf=0.5", true));
  RecordProperty("restarted_spectral_radius", std::to_string(restarted));
  std::printf("generalized_alpha:rho_inf=0.5 restarted every step: spectral radius %.6g\n",
              restarted);
  EXPECT_GT(std::abs(restarted - rho), 0.05);
}

}  // namespace
}  // namespace structural_alpha_test
}  // namespace geomint
