// A 1-D elastic rod in longitudinal motion, fixed at x = 0 and free at x = L, discretised by N
// linear finite elements with a lumped (diagonal, kSeparable) or consistent (tridiagonal, the
// general kind with a constant M) mass; an end load F. The discrete system's exact solution is
// its normal modes, whose shapes are the continuum's sampled at the nodes.
#include "problems/elastic_rod.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {

double dalembert_tip_displacement(double t, double length, double wave_speed, double load,
                                  double axial_stiffness) {
  const double travel = 2 * length / wave_speed;  // out to the wall and back
  const double phase = std::fmod(t, 2 * travel);
  const double rising = phase <= travel ? phase : 2 * travel - phase;
  return load / axial_stiffness * wave_speed * rising;
}

namespace {

constexpr int kMaxElements = 4096;  // the exact solution sums N modes at N nodes

struct RodConfig {
  int elements = 8;
  bool consistent = false;
  double length = 1, young = 1, area = 1, density = 1;
  double load = 1;       // F at the free end, switched on at t = 0
  int mode = 1;          // the initial displacement adds amplitude · (mode shape) …
  double amplitude = 0;  // … to the rest state
};

// What both mass models share: K, the load, the modes and the exact solution.
class RodBase : public Problem {
 public:
  explicit RodBase(const RodConfig& config)
      : config_(config),
        h_(config.length / config.elements),
        stiffness_(config.young * config.area / h_),
        element_mass_(config.density * config.area * h_) {}

  State initial_state() const override { return initial_; }

  // V = ½(q − u_s)ᵀK(q − u_s) = ½qᵀKq − F q_N + F²L/(2EA): zero at the static deflection u_s,
  // so that the rod at rest under its load starts with H₀ = F²L/(2EA) > 0 (the energy errors are
  // relative to H₀).
  double potential(const Vec& q) const override {
    const Vec offset = q - static_deflection();
    double sum = 0;
    for (int e = 0; e < config_.elements; ++e) {
      const double d = offset[e] - (e > 0 ? offset[e - 1] : 0.0);
      sum += 0.5 * stiffness_ * d * d;
    }
    return sum;
  }
  void gradient(const Vec& q, Vec& g) const override {
    const int n = config_.elements;
    g.setZero(n);
    for (int e = 0; e < n; ++e) {
      const double tension = stiffness_ * (q[e] - (e > 0 ? q[e - 1] : 0.0));
      g[e] += tension;
      if (e > 0) g[e - 1] -= tension;
    }
    g[n - 1] -= config_.load;
  }
  // V is quadratic (∇V affine: the load adds a constant); the normal-mode metrics read the
  // Hessian, which only the lumped (separable) rod offers.
  bool is_linear() const override { return !config_.consistent; }

  // u(t) = u_s + Σ_j c_j φ_j cos ω_j t from rest, u_s = F x/(EA) the static deflection (exact at
  // the nodes of linear elements), c_j the M-orthogonal projection of u(0) − u_s on φ_j.
  State exact(double t) const override {
    const int n = config_.elements;
    State state{t, static_deflection(), Vec::Zero(n)};
    Vec velocity = Vec::Zero(n);
    for (const Mode& mode : modes_) {
      state.q += mode.coefficient * std::cos(mode.omega * t) * mode.shape;
      velocity -= mode.coefficient * mode.omega * std::sin(mode.omega * t) * mode.shape;
    }
    state.p = mass_times(velocity);
    return state;
  }
  double omega_max(const Vec&) const override { return mode_frequency(config_.elements); }

  std::vector<std::string> series_names() const override { return {"tip"}; }
  void series_values(const Vec& q, const Vec&, std::vector<double>& values) const override {
    values.assign(1, q[config_.elements - 1]);
  }

 protected:
  // φ_j(x_i) = sin((2j − 1)πx_i/(2L)): the continuum's shapes solve the discrete eigenproblem too
  // (with the tip's half element, the free end is a mirror), at θ = (2j − 1)πh/(2L):
  // ω² = (4k/m) sin²(θ/2) lumped, (12k/m)(1 − cos θ)/(4 + 2cos θ) consistent (k = EA/h, m = ρAh).
  double mode_frequency(int j) const {
    const double theta = (2 * j - 1) * std::numbers::pi * h_ / (2 * config_.length);
    const double ratio = stiffness_ / element_mass_;
    if (!config_.consistent) return 2 * std::sqrt(ratio) * std::sin(theta / 2);
    return std::sqrt(12 * ratio * (1 - std::cos(theta)) / (4 + 2 * std::cos(theta)));
  }
  Vec mode_shape(int j) const {
    Vec shape(config_.elements);
    for (int i = 0; i < config_.elements; ++i) {
      shape[i] = std::sin((2 * j - 1) * std::numbers::pi * (i + 1) / (2.0 * config_.elements));
    }
    return shape;
  }
  Vec static_deflection() const {
    Vec u(config_.elements);
    for (int i = 0; i < config_.elements; ++i) u[i] = config_.load * (i + 1) / stiffness_;
    return u;
  }
  // M v: lumped ρAh (ρAh/2 at the tip), consistent ρAh/6 (v_{i−1} + 4v_i + v_{i+1}) (tip:
  // ρAh/6 (v_{N−1} + 2v_N)).
  Vec mass_times(const Vec& v) const {
    const int n = config_.elements;
    Vec out(n);
    for (int i = 0; i < n; ++i) {
      if (!config_.consistent) {
        out[i] = element_mass_ * (i + 1 < n ? 1.0 : 0.5) * v[i];
      } else {
        const double left = i > 0 ? v[i - 1] : 0.0;
        out[i] = element_mass_ / 6 * (i + 1 < n ? left + 4 * v[i] + v[i + 1] : left + 2 * v[i]);
      }
    }
    return out;
  }
  void finish_setup() {
    const int n = config_.elements;
    initial_ = {0.0, config_.amplitude * mode_shape(config_.mode), Vec::Zero(n)};
    const Vec offset = initial_.q - static_deflection();
    const Vec weighted = mass_times(offset);
    for (int j = 1; j <= n; ++j) {
      Vec shape = mode_shape(j);
      const double coefficient = shape.dot(weighted) / shape.dot(mass_times(shape));
      if (coefficient != 0) modes_.push_back({mode_frequency(j), coefficient, std::move(shape)});
    }
    unsigned capabilities = kExact | kOmegaMax;
    if (!config_.consistent) capabilities |= kHessian;
    set_capabilities(capabilities);
    // 60 steps per period of the fastest mode, which the step load excites (a wave front is
    // sharp); two periods 4L/c of the tip's triangle wave.
    const double wave_speed = std::sqrt(config_.young / config_.density);
    set_defaults(0.1 / mode_frequency(n), 8 * config_.length / wave_speed);
  }

  struct Mode {
    double omega;
    double coefficient;
    Vec shape;
  };
  RodConfig config_;
  double h_, stiffness_, element_mass_;
  std::vector<Mode> modes_;
  State initial_;
};

class LumpedRod final : public RodBase {
 public:
  explicit LumpedRod(const RodConfig& config) : RodBase(config) {
    Vec mass = Vec::Constant(config.elements, element_mass_);
    mass[config.elements - 1] *= 0.5;
    set_mass(mass);
    finish_setup();
  }
  void hessian(const Vec&, SparseMatrix& H) const override { H = stiffness_matrix(); }

 private:
  SparseMatrix stiffness_matrix() const {
    const int n = config_.elements;
    std::vector<Eigen::Triplet<double>> triplets;
    for (int i = 0; i < n; ++i) {
      triplets.emplace_back(i, i, i + 1 < n ? 2 * stiffness_ : stiffness_);
      if (i + 1 < n) {
        triplets.emplace_back(i, i + 1, -stiffness_);
        triplets.emplace_back(i + 1, i, -stiffness_);
      }
    }
    SparseMatrix K(n, n);
    K.setFromTriplets(triplets.begin(), triplets.end());
    return K;
  }
};

// The consistent mass is not diagonal: the general kind, with M constant (T_q = 0).
class ConsistentRod final : public RodBase, public LagrangianSystem {
 public:
  explicit ConsistentRod(const RodConfig& config) : RodBase(config) {
    set_dof(config.elements);
    finish_setup();
  }
  const LagrangianSystem* as_lagrangian() const override { return this; }
  double potential(const Vec& q) const override { return RodBase::potential(q); }
  void gradient(const Vec& q, Vec& g) const override { RodBase::gradient(q, g); }

  void mass_matrix(const Vec&, DenseMatrix& M) const override {
    const int n = config_.elements;
    M = DenseMatrix::Zero(n, n);
    for (int i = 0; i < n; ++i) M.col(i) = mass_times(Vec::Unit(n, i));
  }
  // Mv in O(n) from the tridiagonal rows (the mass operator's product); the solve stays the
  // default dense Cholesky.
  void apply_mass(const Vec&, const Vec& v, Vec& Mv) const override { Mv = mass_times(v); }
  void kinetic_gradient(const Vec& q, const Vec&, Vec& T_q) const override {
    T_q = Vec::Zero(q.size());
  }
  void mass_velocity_jacobian(const Vec& q, const Vec&, DenseMatrix& D) const override {
    D = DenseMatrix::Zero(q.size(), q.size());
  }
  void kinetic_hessian(const Vec& q, const Vec&, DenseMatrix& T_qq) const override {
    T_qq = DenseMatrix::Zero(q.size(), q.size());
  }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    const int n = static_cast<int>(q.size());
    K = DenseMatrix::Zero(n, n);
    for (int i = 0; i < n; ++i) {
      K(i, i) = i + 1 < n ? 2 * stiffness_ : stiffness_;
      if (i + 1 < n) K(i, i + 1) = K(i + 1, i) = -stiffness_;
    }
  }
};

}  // namespace

std::unique_ptr<Problem> make_elastic_rod(Params& params) {
  RodConfig config;
  config.elements = static_cast<int>(
      params.integer("elements", 8, "number of linear elements N", 1, kMaxElements));
  config.consistent =
      params.choice("mass", "lumped", {"lumped", "consistent"},
                    "lumped (diagonal) or consistent (tridiagonal, the general kind) mass") ==
      "consistent";
  config.length = params.real("length", 1.0, "rod length L", Range::above(0));
  config.young = params.real("young", 1.0, "Young's modulus E", Range::above(0));
  config.area = params.real("area", 1.0, "cross-section A", Range::above(0));
  config.density =
      params.real("density", 1.0, "density rho (wave speed c = sqrt(E/rho))", Range::above(0));
  config.load = params.real("load", 1.0, "end load F, switched on at t = 0");
  config.mode = static_cast<int>(
      params.integer("mode", 1, "mode shape added to the initial displacement", 1, kMaxElements));
  if (config.mode > config.elements) {
    throw InputError(
        fmt::format("problem 'elastic_rod': parameter mode={} must be in [1, {}] for elements={}",
                    config.mode, config.elements, config.elements));
  }
  config.amplitude =
      params.real("amplitude", 0.0, "amplitude of that mode in the initial displacement");
  if (config.load == 0 && config.amplitude == 0) {
    throw InputError(
        "problem 'elastic_rod': load=0 and amplitude=0 leave the rod at rest with H = 0; give a "
        "load != 0 or an amplitude != 0");
  }
  if (config.consistent) return std::make_unique<ConsistentRod>(config);
  return std::make_unique<LumpedRod>(config);
}

}  // namespace geomint
