// The Toda lattice (Toda 1967; GNI §X.1.5): n unit masses with H = ½Σp_i² + αΣ exp(q_i − q_{i+1}),
// periodic (q_{n+1} = q_1) or open (the sum to n − 1). Integrable: Flaschka's Lax matrix
// (problems/structures/toda.hpp) keeps its spectrum, which the toda_invariants_err_max metric
// reads.
#include "problems/structures/toda.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "problems/problem.hpp"

namespace geomint {

Eigen::VectorXd flaschka_invariants(const Eigen::MatrixXd& lax) {
  const int n = static_cast<int>(lax.rows());
  Eigen::VectorXd traces(n);
  Eigen::MatrixXd power = lax;
  for (int k = 0; k < n; ++k) {
    if (k > 0) power = power * lax;
    traces[k] = power.trace();
  }
  return traces;
}

namespace {

struct TodaConfig {
  int n = 8;
  bool periodic = true;
  double alpha = 1;
  double displacement = 0.5;  // q_i(0) = displacement · cos(2πi/n)
  double momentum = 0.5;      // p_i(0) = momentum · sin(2πi/n) + velocity
  double velocity = 0;
};

class Toda final : public Problem, public TodaStructure {
 public:
  explicit Toda(const TodaConfig& config) : config_(config) {
    set_mass(Vec::Ones(config.n));
    // V depends on differences only: Σp is conserved with either ends.
    set_capabilities(kHessian | kOmegaMax | kLinearMomentum);
    const double pi = std::numbers::pi;
    initial_.q.resize(config.n);
    initial_.p.resize(config.n);
    for (int i = 0; i < config.n; ++i) {
      initial_.q[i] = config.displacement * std::cos(2 * pi * i / config.n);
      initial_.p[i] = config.momentum * std::sin(2 * pi * i / config.n) + config.velocity;
    }
    // Every term of H is ≥ 0, so each bond keeps α e^{d} ≤ H₀ and the Gershgorin bound
    // 2√(max κ) of omega_max stays below 2√H₀ for the whole motion: 20 steps per such period.
    const double omega_bound = 2 * std::sqrt(std::max(energy(initial_.q, initial_.p), 1e-300));
    set_defaults(0.3 / omega_bound, 100.0);
  }

  const void* structure(const StructureKey& key) const override {
    if (auto* s = offer<TodaStructure>(key, this)) return s;
    return Problem::structure(key);
  }

  State initial_state() const override { return initial_; }

  double potential(const Vec& q) const override {
    double sum = 0;
    for (int s = 0; s < bonds(); ++s) sum += bond_energy(q, s);
    return sum;
  }

  // Bond s pushes its left particle by −α e^d and its right one by +α e^d (d = q_l − q_r).
  void gradient(const Vec& q, Vec& g) const override {
    g.setZero(config_.n);
    for (int s = 0; s < bonds(); ++s) {
      const double force = bond_energy(q, s);
      g[s] += force;
      g[right(s)] -= force;
    }
  }

  void hessian(const Vec& q, SparseMatrix& H) const override {
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(4 * bonds());
    for (int s = 0; s < bonds(); ++s) {
      const double kappa = bond_energy(q, s);
      triplets.emplace_back(s, s, kappa);
      triplets.emplace_back(right(s), right(s), kappa);
      triplets.emplace_back(s, right(s), -kappa);
      triplets.emplace_back(right(s), s, -kappa);
    }
    H.resize(config_.n, config_.n);
    H.setFromTriplets(triplets.begin(), triplets.end());
  }

  Vec linear_momentum(const Vec&, const Vec& p) const override { return Vec::Constant(1, p.sum()); }

  // Gershgorin: row i of ∇²V holds κ of its bonds on the diagonal and −κ off it.
  double omega_max(const Vec& q) const override {
    Vec row_sums = Vec::Zero(config_.n);
    for (int s = 0; s < bonds(); ++s) {
      const double kappa = bond_energy(q, s);
      row_sums[s] += 2 * kappa;
      row_sums[right(s)] += 2 * kappa;
    }
    return std::sqrt(row_sums.maxCoeff());
  }

  Eigen::MatrixXd lax_matrix(const Vec& q, const Vec& p) const override {
    const int n = config_.n;
    Eigen::MatrixXd lax = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) lax(i, i) = -0.5 * p[i];
    // a_s = ½√(α e^{d_s}); the periodic lattice's last bond fills the corners.
    for (int s = 0; s < bonds(); ++s) {
      const double a = 0.5 * std::sqrt(bond_energy(q, s));
      lax(s, right(s)) = a;
      lax(right(s), s) = a;
    }
    return lax;
  }

 private:
  int bonds() const { return config_.periodic ? config_.n : config_.n - 1; }
  int right(int s) const { return s + 1 < config_.n ? s + 1 : 0; }
  double bond_energy(const Vec& q, int s) const {
    return config_.alpha * std::exp(q[s] - q[right(s)]);
  }

  TodaConfig config_;
  State initial_;
};

}  // namespace

std::unique_ptr<Problem> make_toda(Params& params) {
  TodaConfig config;
  const std::string ends =
      params.choice("ends", "periodic", {"periodic", "open"},
                    "periodic (q_{n+1} = q_1, n >= 3) or open (n - 1 bonds, n >= 2)");
  config.periodic = ends == "periodic";
  config.n = static_cast<int>(params.integer("n", 8, "number of particles", 2, 100'000));
  if (config.periodic && config.n < 3) {
    throw InputError(fmt::format(
        "problem 'toda': parameter n={} must be in [3, 100000] for ends=periodic (with n = 2 "
        "both bonds join the same pair; use ends=open)",
        config.n));
  }
  config.alpha =
      params.real("alpha", 1.0, "bond strength: V = alpha sum exp(q_i - q_{i+1})", Range::above(0));
  // |q_i − q_{i+1}| ≤ 2|displacement| keeps e^{d} far from overflow.
  config.displacement = params.real("displacement", 0.5, "initial q_i = displacement cos(2 pi i/n)",
                                    Range::magnitude(50));
  config.momentum = params.real("momentum", 0.5, "initial p_i = momentum sin(2 pi i/n) + velocity",
                                Range::magnitude(1e6));
  config.velocity = params.real("velocity", 0.0, "uniform initial velocity added to every p_i",
                                Range::magnitude(1e6));
  return std::make_unique<Toda>(config);
}

}  // namespace geomint
