// Tao's explicit method for non-separable H(q, p) (Tao, Phys. Rev. E 94, 043303, 2016, eq. (2)–(4);
// ../shared/MECHANICS.md §4): Strang splitting of H(q, y) + H(x, p) + ω·(coupling) on the extended
// phase space (q, p, x, y), order 2, and Yoshida's triple jump of it, order 4.
#include <cmath>
#include <string>

#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"
#include "integrators/step_implementation.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// The three flows are exact: H(q, y) moves only p and x, H(x, p) only q and y, and the coupling
// ½ω²|q − x|²_W + ½|p − y|²_{W⁻¹} (an oscillator of frequency ω between the copies) rotates
// (√(Wω)(q − x), (p − y)/√(Wω)) by the angle 2ωδ while q + x and p + y stay. Tao writes
// ω(½|q − x|² + ½|p − y|²), which adds a length to a momentum; with W a constant diagonal mass (the
// problem's mass, or the diagonal of M(q₀) on a non-separable problem, fixed at reset) the
// coupling has units of energy, the flow stays exact and the map symplectic, and the method is
// invariant under L → cL and under a change of units (Tao's form loses every digit of an
// electron, p ~ 1e-24 against q ~ 1e-5). With W = 1 it is Tao's in the variables (√ω q, p/√ω).
// The copy (x, y) starts at (q₀, p₀) in reset() and is carried between steps: the method is a
// symplectic, symmetric map on (q, p, x, y), so its steps continue each other; restarting it at
// every step would change it. As a map on (q, p) alone it is neither symplectic nor symmetric, and
// it is declared as neither (the registry's structure checks would fail it, rightly). Separable
// problems evaluate v = M⁻¹p and L_q = −∇V directly; non-separable ones through their
// LagrangianSystem.
class Tao final : public Integrator {
 public:
  Tao(double omega, int order) : omega_given_(omega), order_(order) {}

  MethodInfo info() const override {
    return {"tao", order_, kExplicit | kConservativeOnly | kGeneralLagrangian,
            "Tao 2016 (Phys. Rev. E 94, 043303) extended phase space splitting, coupling omega; "
            "order 4 by Yoshida's triple jump"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "no formula in geomint: the limit depends on the coupling omega as well as on h");
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    x_ = state.q;
    y_ = state.p;
    // ω has units 1/time, so a fixed default suits one time scale only (ω = 20 leaves an
    // electron's gyration at 1.8e11 rad/s effectively uncoupled): by default it follows the
    // problem's fastest frequency at the start.
    omega_ = omega_given_;
    if (omega_ == 0.0) {
      const double fastest = problem.has(kOmegaMax) ? problem.omega_max(state.q) : 0.0;
      omega_ = std::isfinite(fastest) && fastest > 0.0 ? kDefaultCoupling * fastest : 20.0;
    }
    // W = diag M(q₀) through the mass operator, for either kind.
    DenseMatrix mass;
    MassOperator(problem).dense(state.q, mass);
    weight_ = mass.diagonal();
  }

  // The one step for the separable and the general kind (they differ only in evaluate()).
  StepStatus step(const Problem& problem, State& state, double h) override {
    mark_step_implementation();
    if (x_.size() != state.q.size()) reset(problem, state, h);
    const LagrangianSystem* general = problem.as_lagrangian();
    if (order_ == 2) {
      strang(problem, general, state, h);
    } else {
      // Yoshida 1990: γ₁ = 1/(2 − 2^{1/3}), γ₂ = 1 − 2γ₁.
      const double outer = 1.0 / (2.0 - std::cbrt(2.0));
      strang(problem, general, state, outer * h);
      strang(problem, general, state, (1.0 - 2.0 * outer) * h);
      strang(problem, general, state, outer * h);
    }
    state.t += h;
    ++counters_.steps;
    if (!state.q.allFinite() || !state.p.allFinite() || !x_.allFinite() || !y_.allFinite()) {
      return StepStatus::failure("nan", "tao: non-finite state");
    }
    return StepStatus::success();
  }

 private:
  // v = H_p(q, p) and L_q(q, v) = −H_q(q, p).
  void evaluate(const Problem& problem, const LagrangianSystem* general, const Vec& q, const Vec& p,
                Vec& v, Vec& L_q) {
    ++counters_.force_evals;
    if (general) {
      v = general->velocity(q, p);
      general->lagrangian_q(q, v, L_q);
    } else {
      v = MassOperator(problem).solve(q, p);
      problem.gradient(q, L_q);
      L_q = -L_q;
    }
  }

  // φ_A^{δ/2} φ_B^{δ/2} φ_C^{δ} φ_B^{δ/2} φ_A^{δ/2} (Tao 2016, eq. (4)).
  void strang(const Problem& problem, const LagrangianSystem* general, State& state, double delta) {
    flow_a(problem, general, state, delta / 2);
    flow_b(problem, general, state, delta / 2);
    flow_c(state, delta);
    flow_b(problem, general, state, delta / 2);
    flow_a(problem, general, state, delta / 2);
  }

  // H(q, y): ṗ = −H_q(q, y), ẋ = H_p(q, y).
  void flow_a(const Problem& problem, const LagrangianSystem* general, State& state, double delta) {
    evaluate(problem, general, state.q, y_, velocity_, force_);
    state.p += delta * force_;
    x_ += delta * velocity_;
  }

  // H(x, p): q̇ = H_p(x, p), ẏ = −H_q(x, p).
  void flow_b(const Problem& problem, const LagrangianSystem* general, State& state, double delta) {
    evaluate(problem, general, x_, state.p, velocity_, force_);
    state.q += delta * velocity_;
    y_ += delta * force_;
  }

  // ½ω²|q − x|²_W + ½|p − y|²_{W⁻¹}: d(q − x)/dt = 2W⁻¹(p − y), d(p − y)/dt = −2ω²W(q − x).
  void flow_c(State& state, double delta) {
    const double c = std::cos(2 * omega_ * delta);
    const double s = std::sin(2 * omega_ * delta);
    const Vec q_sum = state.q + x_, p_sum = state.p + y_;
    const Vec q_diff = state.q - x_, p_diff = state.p - y_;
    const Vec stiffness = omega_ * weight_;  // Wω, a mass per time
    const Vec q_rotated = c * q_diff + s * p_diff.cwiseQuotient(stiffness);
    const Vec p_rotated = -s * q_diff.cwiseProduct(stiffness) + c * p_diff;
    state.q = (q_sum + q_rotated) / 2;
    x_ = (q_sum - q_rotated) / 2;
    state.p = (p_sum + p_rotated) / 2;
    y_ = (p_sum - p_rotated) / 2;
  }

  static constexpr double kDefaultCoupling = 1.0;  // ω / omega_max when omega is not given
  double omega_given_;                             // 0: from the problem's omega_max
  double omega_ = 20.0;
  int order_;
  Vec x_, y_;   // the extended copies of q and p
  Vec weight_;  // W, the coupling's metric
  Vec velocity_, force_;
};

}  // namespace

std::unique_ptr<Integrator> make_tao(Params& params) {
  const double omega = params.real(
      "omega", 0.0,
      "coupling between the two copies of phase space, units 1/time (errors grow with it; too "
      "small lets the copies drift apart); 0: the problem's omega_max at the start, or "
      "20 where the problem has none",
      Range::at_least(0));
  const std::string order =
      params.choice("order", "2", {"2", "4"}, "2 (Strang) or 4 (Yoshida's triple jump)");
  return std::make_unique<Tao>(omega, order == "4" ? 4 : 2);
}

}  // namespace geomint
