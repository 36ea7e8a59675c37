// Average-vector-field discrete gradient method, order 2, symmetric, energy-preserving
// (McLachlan, Quispel & Robidoux 1999; Quispel & McLaren 2008, J. Phys. A 41 045206):
// y₁ = y₀ + h J ∫₀¹ ∇H((1−ξ)y₀ + ξy₁) dξ, on separable H = ½pᵀM⁻¹p + V(q) with diagonal M.
#include <fmt/format.h>

#include <cmath>
#include <vector>

#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "problems/mass_operator.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace {

// Gauss–Legendre nodes and weights on [0, 1]: Newton on the Legendre polynomial P_n from the
// Chebyshev guesses (Abramowitz & Stegun 25.4.29; Numerical Recipes §4.6 "gauleg").
void gauss_legendre_unit(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  nodes.assign(n, 0.0);
  weights.assign(n, 0.0);
  const double pi = std::acos(-1.0);
  for (int i = 0; i < n; ++i) {
    double x = std::cos(pi * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = x;  // P_0, P_1, then the three-term recurrence up to P_n
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) p0 = 1.0;
      derivative = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / derivative;
      x -= dx;
      if (std::abs(dx) <= 1e-16) break;
    }
    nodes[i] = 0.5 * (1.0 - x);  // [−1, 1] → [0, 1], ascending in ξ
    weights[i] = 1.0 / ((1.0 - x * x) * derivative * derivative);  // 2/((1−x²)P'²) · ½
  }
}

// With the mean velocity v̄ = (q₁ − q₀)/h = M⁻¹(p₀ + p₁)/2 as unknown, the step is
//   R(v̄) = M v̄ − p₀ + (h/2) Σᵢ wᵢ ∇V(q₀ + ξᵢ h v̄) = 0,
//   ∂R/∂v̄ = M + (h²/2) Σᵢ wᵢ ξᵢ ∇²V(q₀ + ξᵢ h v̄)   (symmetric),
// then q₁ = q₀ + h v̄, p₁ = 2M v̄ − p₀. The n-node rule integrates ∇V exactly along the segment
// when V is a polynomial of degree ≤ 2n (∇V of degree ≤ 2n − 1 in ξ): then
// H(y₁) − H(y₀) = (p₁ − p₀)ᵀ v̄ + ∫∇V·(q₁ − q₀) = 0 exactly, and energy is kept to round-off plus
// the Newton tolerance (polished). For other V (pendulum, Kepler) the energy error is the
// quadrature error, O((h|v̄|)^{2n+1}) per step. Not symplectic (a discrete gradient map is
// symplectic only for quadratic H); symmetric, since swapping y₀ ↔ y₁, h ↔ −h leaves it unchanged.
class AverageVectorField final : public Integrator {
 public:
  AverageVectorField(int nodes, const NewtonOptions& newton) : newton_(newton) {
    newton_.options().polish = true;  // energy to round-off, not to the tolerance
    gauss_legendre_unit(nodes, nodes_, weights_);
  }

  MethodInfo info() const override {
    return {"avf", 2,
            kImplicit | kSymmetric | kNeedsHessian | kConservativeOnly | kEnergyPreserving,
            fmt::format("average vector field, {}-node Gauss-Legendre quadrature (energy exact "
                        "for polynomial V of degree <= {}); Quispel-McLaren 2008; "
                        "McLachlan-Quispel-Robidoux 1999",
                        nodes_.size(), 2 * nodes_.size())};
  }

  StabilityPrediction predicted_linear_stability() const override {
    // On q̈ = −ω²q with V quadratic, AVF is the implicit midpoint rule (GNI §VI.4): A-stable.
    return StabilityPrediction::unconditional();
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    newton_.forget_pattern();
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    const Vec& mass = MassOperator(problem).constant_diagonal();
    update_sparse_mass_matrix(problem, mass_diagonal_, mass_matrix_);
    // (h/2) Σ wᵢ ∇V(q₀ + ξᵢ h v̄), memoised on v̄ (the first residual repeats the scale's).
    bool memo_valid = false;
    Vec memo_v;
    const auto mean_impulse = [&](const Vec& v, Vec& out) {
      if (memo_valid && memo_v == v) return;
      memo_valid = true;
      memo_v = v;
      out.setZero(v.size());
      for (std::size_t i = 0; i < nodes_.size(); ++i) {
        eval_gradient(problem, state.q + (nodes_[i] * h) * v, gradient_);
        out += weights_[i] * gradient_;
      }
      out *= h / 2;
    };
    double inner_scale = 0.0;
    NewtonSystem system;
    system.symmetric = true;
    system.inner_term_scale = [&] { return inner_scale; };
    system.residual = [&](const Vec& v, Vec& residual) {
      mean_impulse(v, impulse_);
      residual = mass.cwiseProduct(v) - state.p + impulse_;
    };
    system.jacobian = [&](const Vec& v, SparseMatrix& jacobian) {
      jacobian = mass_matrix_;
      inner_scale = 0.0;
      for (std::size_t i = 0; i < nodes_.size(); ++i) {
        const Vec q_node = state.q + (nodes_[i] * h) * v;
        eval_hessian(problem, q_node, hessian_);
        inner_scale =
            std::max(inner_scale, std::abs(h / 2) * gradient_term_scale(hessian_, q_node));
        jacobian += (h * h / 2 * weights_[i] * nodes_[i]) * hessian_;
      }
    };

    Vec v = MassOperator(problem).solve(state.q, state.p);
    mean_impulse(v, impulse_);
    const double residual_scale = robust_norm(state.p) + robust_norm(impulse_);
    const NewtonResult result = newton_.solve(system, v, residual_scale);
    counters_.newton_iters += result.iterations;
    counters_.linear_solves += result.linear_solves;
    counters_.factorizations += result.factorizations;
    if (!result.converged) return StepStatus::failure(result.reason, describe(result));

    state.q += h * v;
    state.p = 2 * mass.cwiseProduct(v) - state.p;
    state.t += h;
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  NewtonSolver newton_;
  std::vector<double> nodes_, weights_;
  Vec mass_diagonal_;
  SparseMatrix mass_matrix_, hessian_;
  Vec impulse_, gradient_;
};

}  // namespace

std::unique_ptr<Integrator> make_avf(Params& params) {
  const long nodes = params.integer(
      "nodes", 4,
      "Gauss-Legendre nodes of the average ∫₀¹∇V dξ (energy exact for polynomial V of degree ≤ "
      "2·nodes)",
      1, 16);
  const NewtonOptions newton = read_newton_options(params, "|p| + h|∇V|/2");
  return std::make_unique<AverageVectorField>(static_cast<int>(nodes), newton);
}

}  // namespace geomint
