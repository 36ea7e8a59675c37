// One-dimensional chain of n equal masses joined by springs φ(d) = ½k d² + ⅓α d³ + ¼β d⁴ in the
// extension d (linear, Fermi–Pasta–Ulam α and β models; GNI §I.5), with fixed, free or fixed–free
// (a wall on the left only) ends. The
// linear chain has the exact normal-mode solution q(t) = Σ_j φ_j (a_j cos ω_j t + b_j sin ω_j t).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "problems/problem.hpp"

namespace geomint {
namespace {

constexpr int kMaxExactMasses = 4096;

struct SpringChainConfig {
  int n = 8;
  bool fixed = true;        // a wall at the left end (q_wall = 0) …
  bool fixed_right = true;  // … and one at the right end; free ends have neither
  double mass = 1;
  double stiffness = 1;
  double alpha = 0;  // cubic coefficient of φ (fpu_alpha only)
  double beta = 0;   // quartic coefficient of φ (fpu_beta only)
  int mode = 1;      // the initial displacement is amplitude · mode shape …
  int node = 0;      // … or, when node ≥ 1, amplitude at that single node (1-based)
  double amplitude = 0.5;
  double velocity = 0;
};

class SpringChain final : public Problem {
 public:
  explicit SpringChain(const SpringChainConfig& config) : config_(config) {
    set_mass(Vec::Constant(config.n, config.mass));
    // The normal-mode sum costs O(n²) per evaluation (no fast sine transform here), so the exact
    // solution is offered up to kMaxExactMasses masses.
    const bool exact = config.alpha == 0 && config.beta == 0 && config.n <= kMaxExactMasses;
    unsigned capabilities = kHessian | kOmegaMax;
    if (exact) capabilities |= kExact;
    // Only the walls exert external forces, so the free chain keeps Σ p.
    if (!config.fixed && !config.fixed_right) capabilities |= kLinearMomentum;
    set_capabilities(capabilities);
    // 20 steps per period of the fastest linear mode (ω ≤ 2√(k/m)), ten periods of the slowest
    // oscillating one.
    const double omega_bound = 2 * std::sqrt(config.stiffness / config.mass);
    set_defaults(0.3 / omega_bound, 10 * 2 * std::numbers::pi / mode_frequency(1));
    if (config.node > 0) {
      initial_.q = Vec::Zero(config.n);
      initial_.q[config.node - 1] = config.amplitude;
    } else {
      initial_.q = config.amplitude * mode_shape(config.mode);
    }
    initial_.p = Vec::Constant(config.n, config.mass * config.velocity);
    if (exact) project_initial_state();
  }

  State initial_state() const override { return initial_; }

  double potential(const Vec& q) const override {
    double sum = 0;
    for (int s = 0; s < springs(); ++s) {
      const double d = extension(q, s);
      sum += d * d * (0.5 * config_.stiffness + d * (config_.alpha / 3 + 0.25 * config_.beta * d));
    }
    return sum;
  }

  // Spring s pulls its right node back by φ'(d) and its left node forward by the same amount.
  void gradient(const Vec& q, Vec& g) const override {
    g.setZero(config_.n);
    for (int s = 0; s < springs(); ++s) {
      const double tension = spring_force(extension(q, s));
      if (right(s) >= 0) g[right(s)] += tension;
      if (left(s) >= 0) g[left(s)] -= tension;
    }
  }

  bool is_linear() const override { return config_.alpha == 0 && config_.beta == 0; }
  void hessian(const Vec& q, SparseMatrix& H) const override {
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(4 * springs());
    for (int s = 0; s < springs(); ++s) {
      const double kappa = spring_stiffness(extension(q, s));
      if (right(s) >= 0) triplets.emplace_back(right(s), right(s), kappa);
      if (left(s) >= 0) triplets.emplace_back(left(s), left(s), kappa);
      if (left(s) >= 0 && right(s) >= 0) {
        triplets.emplace_back(left(s), right(s), -kappa);
        triplets.emplace_back(right(s), left(s), -kappa);
      }
    }
    H.resize(config_.n, config_.n);
    H.setFromTriplets(triplets.begin(), triplets.end());
  }

  // Superposition of the normal modes; the zero mode of the free chain drifts (a + b t).
  State exact(double t) const override {
    if (!has(kExact)) return Problem::exact(t);  // throws: no normal modes for nonlinear springs
    State state{t, Vec::Zero(config_.n), Vec::Zero(config_.n)};
    for (const Mode& mode : modes_) {
      const Vec shape = mode_shape(mode.index);
      double position, rate;
      if (mode.omega == 0) {
        position = mode.a + mode.b * t;
        rate = mode.b;
      } else {
        const double c = std::cos(mode.omega * t);
        const double s = std::sin(mode.omega * t);
        position = mode.a * c + (mode.b / mode.omega) * s;
        rate = -mode.a * mode.omega * s + mode.b * c;
      }
      state.q += position * shape;
      state.p += (config_.mass * rate) * shape;
    }
    return state;
  }

  Vec linear_momentum(const Vec&, const Vec& p) const override { return Vec::Constant(1, p.sum()); }

  // Gershgorin bound on the largest eigenvalue of M⁻¹∇²V: each row's absolute sum, built from
  // the local spring stiffnesses φ''(d) (which the α model can make negative).
  double omega_max(const Vec& q) const override {
    Vec row_sums = Vec::Zero(config_.n);
    Vec diagonal = Vec::Zero(config_.n);
    for (int s = 0; s < springs(); ++s) {
      const double kappa = spring_stiffness(extension(q, s));
      for (int node : {left(s), right(s)}) {
        if (node < 0) continue;
        diagonal[node] += kappa;
        // The off-diagonal entry −κ exists only between two nodes.
        if (left(s) >= 0 && right(s) >= 0) row_sums[node] += std::abs(kappa);
      }
    }
    return std::sqrt((row_sums + diagonal.cwiseAbs()).maxCoeff() / config_.mass);
  }

 private:
  struct Mode {
    int index;
    double omega;
    double a, b;  // modal displacement and velocity at t = 0
  };

  // Springs: fixed ends have n + 1 (node −1 and node n are the walls), fixed–free n (the wall
  // at node −1 only), free ends n − 1.
  int springs() const {
    return config_.n - 1 + (config_.fixed ? 1 : 0) + (config_.fixed_right ? 1 : 0);
  }
  int left(int s) const { return config_.fixed ? s - 1 : s; }
  int right(int s) const {
    const int node = config_.fixed ? s : s + 1;
    return node < config_.n ? node : -1;
  }
  double extension(const Vec& q, int s) const {
    return (right(s) >= 0 ? q[right(s)] : 0.0) - (left(s) >= 0 ? q[left(s)] : 0.0);
  }
  double spring_force(double d) const {
    return d * (config_.stiffness + d * (config_.alpha + config_.beta * d));
  }
  double spring_stiffness(double d) const {
    return config_.stiffness + d * (2 * config_.alpha + 3 * config_.beta * d);
  }

  // Eigenvectors of the discrete Laplacian: sin((i + 1) j π/(n + 1)) with Dirichlet ends,
  // j = 1..n, cos((i + ½) j π/n) with Neumann (free) ends, j = 0..n−1 (j = 0: translation), and
  // sin((i + 1)(2j − 1)π/(2n + 1)), j = 1..n, with a Dirichlet left and a Neumann right end;
  // ω_j = 2√(k/m) sin(jπ/(2(n + 1))), 2√(k/m) sin(jπ/(2n)) resp. 2√(k/m) sin((2j − 1)π/(2(2n +
  // 1))).
  Vec mode_shape(int j) const {
    const int n = config_.n;
    const double pi = std::numbers::pi;
    Vec shape(n);
    for (int i = 0; i < n; ++i) {
      shape[i] = !config_.fixed        ? std::cos((i + 0.5) * j * pi / n)
                 : config_.fixed_right ? std::sin((i + 1) * j * pi / (n + 1))
                                       : std::sin((i + 1) * (2 * j - 1) * pi / (2 * n + 1));
    }
    return shape;
  }
  double mode_frequency(int j) const {
    const double scale = 2 * std::sqrt(config_.stiffness / config_.mass);
    if (config_.fixed && !config_.fixed_right) {
      return scale * std::sin((2 * j - 1) * std::numbers::pi / (2.0 * (2 * config_.n + 1)));
    }
    const int denominator = config_.fixed ? config_.n + 1 : config_.n;
    return scale * std::sin(j * std::numbers::pi / (2.0 * denominator));
  }

  // Modal coordinates of the initial state: the shapes are orthogonal, so a_j = ⟨φ_j, q⟩/|φ_j|².
  // Modes the initial state does not excite are left out of the sum.
  void project_initial_state() {
    const Vec v = initial_.p / config_.mass;
    for (int j = config_.fixed ? 1 : 0; j < (config_.fixed ? config_.n + 1 : config_.n); ++j) {
      const Vec shape = mode_shape(j);
      const double norm2 = shape.squaredNorm();
      const double a = shape.dot(initial_.q) / norm2;
      const double b = shape.dot(v) / norm2;
      if (a != 0 || b != 0) modes_.push_back({j, mode_frequency(j), a, b});
    }
  }

  SpringChainConfig config_;
  std::vector<Mode> modes_;
  State initial_;
};

}  // namespace

std::unique_ptr<Problem> make_spring_chain(Params& params) {
  SpringChainConfig config;
  config.n = static_cast<int>(params.integer("n", 8, "number of masses", 2, 10'000'000));
  const std::string ends =
      params.choice("ends", "fixed", {"fixed", "free", "fixed_free"},
                    "walls at both ends, free ends, or a wall at the left end only");
  config.fixed = ends != "free";
  config.fixed_right = ends == "fixed";
  const std::string model = params.choice("model", "linear", {"linear", "fpu_alpha", "fpu_beta"},
                                          "spring law: 1/2 k d^2, plus alpha d^3/3, or beta d^4/4");
  config.mass = params.real("mass", 1.0, "mass of each node", Range::above(0));
  config.stiffness = params.real("stiffness", 1.0, "linear spring stiffness k", Range::above(0));
  const double alpha =
      params.real("alpha", 0.25, "cubic coefficient (model=fpu_alpha only)", Range::above(0));
  const double beta =
      params.real("beta", 1.0, "quartic coefficient (model=fpu_beta only)", Range::above(0));
  config.alpha = model == "fpu_alpha" ? alpha : 0.0;
  config.beta = model == "fpu_beta" ? beta : 0.0;
  const std::string init = params.choice("init", "mode", {"mode", "node"},
                                         "initial displacement: a normal mode, or a single node");
  params.omit_default_from_canonical("init");
  if (init == "node") {
    config.node =
        static_cast<int>(params.integer("node", 1, "the displaced node (1-based)", 1, 10'000'000));
    if (config.node > config.n) {
      throw InputError(
          fmt::format("problem 'spring_chain': parameter node={} must be in [1, {}] for n={}",
                      config.node, config.n, config.n));
    }
  } else {
    // Fixed chains have modes 1..n; free chains 1..n-1 (mode 0 is the translation).
    const long max_mode = config.fixed ? config.n : config.n - 1;
    config.mode = static_cast<int>(
        params.integer("mode", 1, "normal mode shaping the initial displacement", 1, 10'000'000));
    if (config.mode > max_mode) {
      throw InputError(fmt::format(
          "problem 'spring_chain': parameter mode={} must be in [1, {}] for n={}, ends={}",
          config.mode, max_mode, config.n, ends));
    }
  }
  config.amplitude =
      params.real("amplitude", 0.5, "amplitude of the initial mode or node displacement");
  config.velocity = params.real("velocity", 0.0, "uniform initial velocity of every mass");
  return std::make_unique<SpringChain>(config);
}

}  // namespace geomint
