// Fermi–Pasta–Ulam chain with alternating stiff linear and soft nonlinear springs (Hairer, Lubich
// & Wanner, GNI §I.5.1, eq. (5.1)): H = ½Σp² + ω²/4 Σ_{i=1..m} (q_{2i} − q_{2i−1})²
// + Σ_{i=0..m} (q_{2i+1} − q_{2i})⁴ with q_0 = q_{2m+1} = 0, and the oscillatory energies I_j.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "problems/problem.hpp"

namespace geomint {
namespace {

class FpuStiff final : public Problem {
 public:
  FpuStiff(int m, double omega) : m_(m), omega_(omega) {
    set_mass(Vec::Ones(2 * m));
    set_capabilities(kHessian | kOmegaMax);
    // hω = 0.5 and GNI's horizon of Fig. 5.1 (the energy exchange between the stiff springs
    // happens on the slow time scale ω⁰, the adiabatic invariant I is kept for t ~ ω^N).
    set_defaults(0.5 / omega, 200.0);
    // GNI's initial values in the transformed coordinates x₀,ᵢ = (q_{2i} + q_{2i−1})/√2 (centre
    // of the stiff spring i), x₁,ᵢ = (q_{2i} − q_{2i−1})/√2 (its elongation), y likewise for p:
    // x₀,₁ = 1, y₀,₁ = 1, x₁,₁ = ω⁻¹, y₁,₁ = 1, all others 0, so I₁(0) = 1 and I₂(0) = I₃(0) = 0.
    // Mapped back with q_{2i−1} = (x₀ − x₁)/√2, q_{2i} = (x₀ + x₁)/√2.
    const double root2 = std::numbers::sqrt2;
    initial_.q = Vec::Zero(2 * m);
    initial_.p = Vec::Zero(2 * m);
    const double x0 = 1, x1 = 1 / omega, y0 = 1, y1 = 1;
    initial_.q[0] = (x0 - x1) / root2;
    initial_.q[1] = (x0 + x1) / root2;
    initial_.p[0] = (y0 - y1) / root2;
    initial_.p[1] = (y0 + y1) / root2;
  }

  State initial_state() const override { return initial_; }

  double potential(const Vec& q) const override {
    double sum = 0;
    for (int i = 0; i < m_; ++i) {
      const double d = stiff_elongation(q, i);
      sum += 0.25 * omega_ * omega_ * d * d;
    }
    for (int i = 0; i <= m_; ++i) sum += std::pow(soft_elongation(q, i), 4);
    return sum;
  }

  void gradient(const Vec& q, Vec& g) const override {
    g.setZero(2 * m_);
    for (int i = 0; i < m_; ++i) {
      const double tension = 0.5 * omega_ * omega_ * stiff_elongation(q, i);
      g[2 * i + 1] += tension;
      g[2 * i] -= tension;
    }
    for (int i = 0; i <= m_; ++i) {
      const double tension = 4 * std::pow(soft_elongation(q, i), 3);
      if (soft_right(i) >= 0) g[soft_right(i)] += tension;
      if (soft_left(i) >= 0) g[soft_left(i)] -= tension;
    }
  }

  void hessian(const Vec& q, SparseMatrix& H) const override {
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(8 * m_ + 4);
    const auto add_spring = [&triplets](int left, int right, double kappa) {
      if (left >= 0) triplets.emplace_back(left, left, kappa);
      if (right >= 0) triplets.emplace_back(right, right, kappa);
      if (left >= 0 && right >= 0) {
        triplets.emplace_back(left, right, -kappa);
        triplets.emplace_back(right, left, -kappa);
      }
    };
    for (int i = 0; i < m_; ++i) add_spring(2 * i, 2 * i + 1, 0.5 * omega_ * omega_);
    for (int i = 0; i <= m_; ++i) {
      const double d = soft_elongation(q, i);
      add_spring(soft_left(i), soft_right(i), 12 * d * d);
    }
    H.resize(2 * m_, 2 * m_);
    H.setFromTriplets(triplets.begin(), triplets.end());
  }

  // Gershgorin row sums of ∇²V (unit masses): the stiff spring gives ω²/2 on and off the
  // diagonal, the soft springs 12 d² each. Close to ω while the soft springs stay soft.
  double omega_max(const Vec& q) const override {
    Vec rows = Vec::Constant(2 * m_, omega_ * omega_);
    for (int i = 0; i <= m_; ++i) {
      const double kappa = 12 * std::pow(soft_elongation(q, i), 2);
      const bool between_nodes = soft_left(i) >= 0 && soft_right(i) >= 0;
      for (int node : {soft_left(i), soft_right(i)}) {
        if (node >= 0) rows[node] += between_nodes ? 2 * kappa : kappa;
      }
    }
    return std::sqrt(rows.maxCoeff());
  }

  // I_j = ½(y₁,ⱼ² + ω² x₁,ⱼ²), the energy of the j-th stiff spring, and their sum I, which GNI
  // shows to be an adiabatic invariant: I(t) = I(0) + O(ω⁻¹) over long times.
  std::vector<std::string> series_names() const override {
    std::vector<std::string> names;
    for (int j = 1; j <= m_; ++j) names.push_back("I" + std::to_string(j));
    names.push_back("I");
    return names;
  }
  void series_values(const Vec& q, const Vec& p, std::vector<double>& values) const override {
    values.assign(m_ + 1, 0.0);
    for (int j = 0; j < m_; ++j) {
      values[j] = oscillatory_energy(q, p, j);
      values[m_] += values[j];
    }
  }

 private:
  // Stiff spring i (0-based) joins nodes 2i and 2i+1; x₁ = elongation/√2.
  static double stiff_elongation(const Vec& q, int i) { return q[2 * i + 1] - q[2 * i]; }
  // Soft spring i (0..m) joins node 2i−1 and node 2i; −1 and 2m are the walls.
  int soft_left(int i) const { return 2 * i - 1; }
  int soft_right(int i) const { return i < m_ ? 2 * i : -1; }
  double soft_elongation(const Vec& q, int i) const {
    return (soft_right(i) >= 0 ? q[soft_right(i)] : 0.0) -
           (soft_left(i) >= 0 ? q[soft_left(i)] : 0.0);
  }
  double oscillatory_energy(const Vec& q, const Vec& p, int j) const {
    const double x1 = stiff_elongation(q, j) / std::numbers::sqrt2;
    const double y1 = (p[2 * j + 1] - p[2 * j]) / std::numbers::sqrt2;
    return 0.5 * (y1 * y1 + omega_ * omega_ * x1 * x1);
  }

  int m_;
  double omega_;
  State initial_;
};

}  // namespace

std::unique_ptr<Problem> make_fpu_stiff(Params& params) {
  const int m = static_cast<int>(params.integer("m", 3, "number of stiff springs", 1, 100'000));
  const double omega = params.real(
      "omega", 50.0, "stiff frequency (stiff spring constant omega^2/2)", Range::closed(1, 1e6));
  return std::make_unique<FpuStiff>(m, omega);
}

}  // namespace geomint
