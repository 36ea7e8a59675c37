// The 1-D elastic rod (problems/elastic_rod.cpp): its discrete modes are the continuum's shapes
// at the frequencies the file states, and its exact tip motion under a step end load converges to
// d'Alembert's triangle wave between 0 and 2FL/EA with period 4L/c.
#include "problems/elastic_rod.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <string>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace elastic_rod_test {
namespace {

// K and M of a rod as dense matrices: K from its Hessian (lumped) or potential Hessian
// (consistent), M from mass() or the LagrangianSystem.
void dense_operators(const Problem& rod, Eigen::MatrixXd& K, Eigen::MatrixXd& M) {
  const Vec q = Vec::Zero(rod.dof());
  if (const auto* general = rod.as_lagrangian()) {
    general->potential_hessian(q, K);
    general->mass_matrix(q, M);
  } else {
    SparseMatrix H;
    rod.hessian(q, H);
    K = Eigen::MatrixXd(H);
    M = rod.mass().asDiagonal();
  }
}

// The generalised eigenvalues of (K, M) are the ω_j² of the closed forms (the dense solver
// against them), and they approach the continuum's ((2j − 1)πc/2L)² from below (lumped) and
// above (consistent) at O(h²).
TEST(ElasticRod, DiscreteModesAreTheClosedFormsAndBracketTheContinuum) {
  const double length = 2, young = 3, density = 1.5;
  const double c = std::sqrt(young / density);
  for (const std::string mass : {"lumped", "consistent"}) {
    double previous_error = 0;
    for (int elements : {8, 16, 32}) {
      const auto rod =
          make_problem("elastic_rod:mass=" + mass + ",elements=" + std::to_string(elements) +
                       ",length=2,young=3,area=0.5,density=1.5");
      Eigen::MatrixXd K, M;
      dense_operators(*rod, K, M);
      const Vec eigenvalues =
          Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>(K, M).eigenvalues();
      const double h = length / elements;
      const double k_over_m = young / (density * h * h);
      for (int j = 1; j <= elements; ++j) {
        const double theta = (2 * j - 1) * std::numbers::pi * h / (2 * length);
        const double closed =
            mass == "lumped" ? 4 * k_over_m * std::pow(std::sin(theta / 2), 2)
                             : 12 * k_over_m * (1 - std::cos(theta)) / (4 + 2 * std::cos(theta));
        EXPECT_NEAR(eigenvalues[j - 1], closed, 1e-11 * closed)
            << mass << " N = " << elements << " mode " << j;
      }
      const double continuum = std::pow(std::numbers::pi * c / (2 * length), 2);
      const double error = (eigenvalues[0] - continuum) / continuum;
      EXPECT_EQ(error < 0, mass == "lumped") << mass << " N = " << elements;
      if (previous_error != 0) {
        EXPECT_NEAR(previous_error / error, 4.0, 0.05) << mass;
      }
      previous_error = error;
    }
  }
}

TEST(ElasticRod, DalembertTipIsATriangleWave) {
  // L = 2, c = 3, F/EA = 0.25: peak 2FL/EA = 1 at t = 2L/c = 4/3, back to 0 at 4L/c = 8/3.
  EXPECT_DOUBLE_EQ(dalembert_tip_displacement(0, 2, 3, 1, 4), 0);
  EXPECT_DOUBLE_EQ(dalembert_tip_displacement(2.0 / 3, 2, 3, 1, 4), 0.5);
  EXPECT_DOUBLE_EQ(dalembert_tip_displacement(4.0 / 3, 2, 3, 1, 4), 1);
  EXPECT_DOUBLE_EQ(dalembert_tip_displacement(2, 2, 3, 1, 4), 0.5);
  EXPECT_NEAR(dalembert_tip_displacement(8.0 / 3, 2, 3, 1, 4), 0, 1e-15);
  EXPECT_NEAR(dalembert_tip_displacement(8.0 / 3 + 0.4, 2, 3, 1, 4),
              dalembert_tip_displacement(0.4, 2, 3, 1, 4), 1e-15);
}

// The semi-discrete exact tip under the step load (the modal sum) against d'Alembert over two
// periods: the mean error falls like 1/√N or faster with N (the Gibbs ripple at the corners
// narrows), for both masses; the peak reaches 2FL/EA within the ripple.
TEST(ElasticRod, ExactTipConvergesToTheDalembertTriangleWave) {
  const double length = 2, young = 3, area = 0.5, density = 1.5, load = 0.7;
  const double c = std::sqrt(young / density), ea = young * area;
  const double peak = 2 * load * length / ea;
  for (const std::string mass : {"lumped", "consistent"}) {
    double previous = 0;
    for (int elements : {16, 64, 256}) {
      const auto rod =
          make_problem("elastic_rod:mass=" + mass + ",elements=" + std::to_string(elements) +
                       ",length=2,young=3,area=0.5,density=1.5,load=0.7");
      const double period = 4 * length / c;
      double sum = 0;
      const int samples = 800;
      for (int k = 0; k < samples; ++k) {
        const double t = 2 * period * (k + 0.5) / samples;
        sum += std::abs(rod->exact(t).q[elements - 1] -
                        dalembert_tip_displacement(t, length, c, load, ea));
      }
      const double mean_error = sum / samples / peak;
      if (previous != 0) {
        EXPECT_LT(mean_error, previous / 1.9) << mass << " N = " << elements;
      }
      previous = mean_error;
      const double at_peak = rod->exact(period / 2).q[elements - 1];
      EXPECT_NEAR(at_peak / peak, 1.0, 0.2) << mass << " N = " << elements;
    }
    EXPECT_LT(previous, 0.01) << mass;  // N = 256
  }
}

}  // namespace
}  // namespace elastic_rod_test
}  // namespace geomint
