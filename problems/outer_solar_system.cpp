// The outer solar system (Hairer, Lubich & Wanner, GNI §I.2.4, Table 2.1): the Sun (with the
// inner planets' masses added) and Jupiter to Pluto under Newtonian gravity,
// H = ½ Σ |p_i|²/m_i − G Σ_{i<j} m_i m_j/|q_i − q_j|, in AU, days and solar masses.
#include <Eigen/Dense>
#include <array>
#include <cmath>

#include "problems/problem.hpp"

namespace geomint {
namespace {

using Point = Eigen::Vector3d;

// G in AU³/(solar mass · day²).
constexpr double kGravity = 2.95912208286e-4;

struct Body {
  double mass;
  std::array<double, 3> position;  // AU, 5 September 1994, 0h00 GST
  std::array<double, 3> velocity;  // AU/day
};

// GNI Table 2.1.
constexpr std::array<Body, 6> kBodies = {{
    {1.00000597682, {0, 0, 0}, {0, 0, 0}},  // Sun, with the inner planets
    {0.000954786104043,
     {-3.5023653, -3.8169847, -1.5507963},
     {0.00565429, -0.00412490, -0.00190589}},  // Jupiter
    {0.000285583733151,
     {9.0755314, -3.0458353, -1.6483708},
     {0.00168318, 0.00483525, 0.00192462}},  // Saturn
    {0.0000437273164546,
     {8.3101420, -16.2901086, -7.2521278},
     {0.00354178, 0.00137102, 0.00055029}},  // Uranus
    {0.0000517759138449,
     {11.4707666, -25.7294829, -10.8169456},
     {0.00288930, 0.00114527, 0.00039677}},  // Neptune
    {1 / 1.3e8,
     {-15.5387357, -25.2225594, -3.1902382},
     {0.00276725, -0.00170702, -0.00136504}},  // Pluto
}};

class OuterSolarSystem final : public Problem {
 public:
  explicit OuterSolarSystem(int planets) : bodies_(planets + 1) {
    Vec mass(3 * bodies_);
    initial_.q.resize(3 * bodies_);
    initial_.p.resize(3 * bodies_);
    for (int b = 0; b < bodies_; ++b) {
      const Body& body = kBodies[b];
      masses_.push_back(body.mass);
      for (int k = 0; k < 3; ++k) {
        mass[3 * b + k] = body.mass;
        initial_.q[3 * b + k] = body.position[k];
        initial_.p[3 * b + k] = body.mass * body.velocity[k];
      }
    }
    set_mass(mass);
    // Gravity depends on differences only: total linear and angular momentum are conserved.
    set_capabilities(kHessian | kLinearMomentum | kAngularMomentum | kOmegaMax);
    // GNI's step and horizon for Fig. 2.4 ff.: h = 10 days (Jupiter's period is ~4332 days),
    // 200 000 days.
    set_defaults(10.0, 200'000.0);
  }

  State initial_state() const override { return initial_; }

  double potential(const Vec& q) const override {
    double sum = 0;
    for (int i = 0; i < bodies_; ++i) {
      for (int j = i + 1; j < bodies_; ++j) {
        sum -= kGravity * masses_[i] * masses_[j] / (body(q, i) - body(q, j)).norm();
      }
    }
    return sum;
  }

  // ∂/∂q_i of −c/|q_i − q_j| is c (q_i − q_j)/r³; body j gets the opposite.
  void gradient(const Vec& q, Vec& g) const override {
    g.setZero(3 * bodies_);
    for (int i = 0; i < bodies_; ++i) {
      for (int j = i + 1; j < bodies_; ++j) {
        const Point d = body(q, i) - body(q, j);
        const double r = d.norm();
        const Point pull = (kGravity * masses_[i] * masses_[j] / (r * r * r)) * d;
        g.segment<3>(3 * i) += pull;
        g.segment<3>(3 * j) -= pull;
      }
    }
  }

  // Pair block B = c (I/r³ − 3 d dᵀ/r⁵) on the diagonal blocks of i and j, −B off the diagonal.
  void hessian(const Vec& q, SparseMatrix& H) const override {
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(36 * bodies_ * bodies_);
    for (int i = 0; i < bodies_; ++i) {
      for (int j = i + 1; j < bodies_; ++j) {
        const Point d = body(q, i) - body(q, j);
        const double r = d.norm();
        const double c = kGravity * masses_[i] * masses_[j];
        const Eigen::Matrix3d block =
            (c / (r * r * r)) * (Eigen::Matrix3d::Identity() - (3 / (r * r)) * d * d.transpose());
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) {
            triplets.emplace_back(3 * i + a, 3 * i + b, block(a, b));
            triplets.emplace_back(3 * j + a, 3 * j + b, block(a, b));
            triplets.emplace_back(3 * i + a, 3 * j + b, -block(a, b));
            triplets.emplace_back(3 * j + a, 3 * i + b, -block(a, b));
          }
        }
      }
    }
    H.resize(3 * bodies_, 3 * bodies_);
    H.setFromTriplets(triplets.begin(), triplets.end());
  }

  Vec linear_momentum(const Vec&, const Vec& p) const override {
    Point total = Point::Zero();
    for (int b = 0; b < bodies_; ++b) total += body(p, b);
    return total;
  }

  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    Point total = Point::Zero();
    for (int b = 0; b < bodies_; ++b) total += body(q, b).cross(body(p, b));
    return total;
  }

  // Gershgorin bound on the eigenvalues of M⁻¹∇²V (similar to M^(−½)∇²V M^(−½)): the largest
  // absolute row sum divided by the row's mass. Dominated by the Sun–Jupiter pair.
  double omega_max(const Vec& q) const override {
    SparseMatrix H;
    hessian(q, H);
    const Eigen::MatrixXd dense(H);
    const Vec rows = dense.cwiseAbs().rowwise().sum();
    return std::sqrt(rows.cwiseProduct(inverse_mass()).maxCoeff());
  }

 private:
  static Point body(const Vec& x, int b) { return x.segment<3>(3 * b); }

  int bodies_;
  std::vector<double> masses_;
  State initial_;
};

}  // namespace

std::unique_ptr<Problem> make_outer_solar_system(Params& params) {
  const int planets = static_cast<int>(params.integer(
      "planets", 5, "number of planets from Jupiter outwards (5 = up to Pluto)", 1, 5));
  return std::make_unique<OuterSolarSystem>(planets);
}

}  // namespace geomint
