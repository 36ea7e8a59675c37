// Explicit symplectic partitioned Runge–Kutta (splitting) methods for H = T(p) + V(q): the
// tables of SUNDIALS 7's SPRKStep and Blanes & Moan (2002), in sprk_coefficients.hpp
// (GNI §II.2 and §VI.3; McLachlan & Quispel, Acta Numerica 11, 2002).
#include <fmt/format.h>

#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "integrators/sprk_coefficients.hpp"
#include "integrators/time_treatment.hpp"
#include "problems/mass_operator.hpp"
#include "problems/structures/time_dependent.hpp"

namespace geomint {
namespace {

// Each stage is an exact flow of V (kick) or of T = ½pᵀM⁻¹p (drift), so the step is symplectic
// and, on a rotation-invariant V, conserves angular momentum exactly (up to rounding).
// Non-conservative forces are refused (kConservativeOnly): a kick with F(q, v, t) would no longer
// be a Hamiltonian flow, and the tables' orders do not cover it.
//
// ∇V is evaluated only when q has moved since the last evaluation: a table whose last stage is a
// kick with no drift after it (first same as last) pays one gradient less per step, as long as the
// next step starts from the bitwise same q (a caller that edits the state gets a fresh one).
//
// On a time-dependent H(q, p, t) = T(p, t) + V(q, t) (problems/structures/time_dependent.hpp),
// `time=` says where the stages read t:
// - extended (default): the table's splitting of the autonomous K = (T(p, τ) + E) + V(q, τ) in
//   the extended phase space (q, τ; p, E). The clock τ moves with the drifts: a kick at fixed τ
//   is exact, and a drift over the clock interval [τ_a, τ_b] is q ← q + ∫ ∂T/∂p(p, s) ds (p
//   fixed), by 5-point Gauss–Legendre in s (exact to O(h¹¹), so the tables keep their orders up
//   to 10). Symplectic in (q, τ; p, E) to that quadrature error.
// - stages: SPRKStep's stage times (sprkStep_TakeStep, SUNDIALS 6.6+): with the running sums
//   ĉ_i = â_1 + … + â_i and c_i = a_1 + … + a_i, stage i's first substep reads t_n + ĉ_i h and its
//   second t_n + c_i h (each includes its own weight). Measured first order whatever the table
//   (docs/METHODS_SPRK.md): leapfrog's kick reads t_n + h, not t_n + h/2.
// - frozen: t_n throughout (the step of H(q, p, t_n)), first order.
// first=drift swaps the substeps' roles, q moved with the â weights before p is kicked with the a
// weights: the order in which ark_damped_harmonic_symplectic hands SPRKStep its two functions (q̇
// as f1).
enum class FirstSubstep { kKick, kDrift };

class Sprk final : public Integrator, public TreatsTime {
 public:
  Sprk(const coefficients::SprkTable& table, TimeTreatment time, FirstSubstep first)
      : table_(table), time_(time), first_(first) {
    for (size_t i = 0; i < table.a.size(); ++i) {
      drift_.push_back(static_cast<double>(table.a[i]));
      kick_.push_back(static_cast<double>(table.a_hat[i]));
    }
  }

  MethodInfo info() const override {
    unsigned flags = kExplicit | kSymplectic | kVariational | kConservativeOnly;
    if (table_.symmetric) flags |= kSymmetric;
    return {"sprk", table_.order, flags,
            fmt::format("explicit symplectic partitioned RK, {} stages ({}){}", table_.a.size(),
                        table_.source,
                        !table_.nystrom_only ? ""
                        : first_ == FirstSubstep::kKick
                            ? ", order for T quadratic in p (Nyström)"
                            : ", order for V quadratic in q (first=drift)")};
  }

  TimeTreatment time_treatment() const override { return time_; }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "no formula in geomint: the limit of the table's product of kick and drift matrices is "
        "not derived here");
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    cached_problem_ = nullptr;
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    if (problem.has(kForce)) {
      return StepStatus::failure(
          "unsupported_force",
          fmt::format("sprk integrates separable conservative systems only; problem '{}' has a "
                      "non-conservative force",
                      problem.name()));
    }
    if (const auto* hamiltonian = problem.as<TimeDependentHamiltonian>()) {
      return step_time_dependent(*hamiltonian, state, h);
    }
    if (first_ == FirstSubstep::kDrift) return step_drift_first(problem, state, h);
    bool gradient_current =
        cached_problem_ == &problem && cached_q_.size() == state.q.size() && cached_q_ == state.q;
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    const double t0 = state.t;
    for (size_t i = 0; i < kick_.size(); ++i) {
      if (kick_[i] != 0) {
        if (!gradient_current) eval_gradient(problem, state.q, gradient_);
        gradient_current = true;
        state.p -= (kick_[i] * h) * gradient_;
      }
      if (drift_[i] != 0) {
        state.q += (drift_[i] * h) * inverse_mass.cwiseProduct(state.p);
        gradient_current = false;
      }
    }
    // t₀ + h, not a sum over the stages, whose negative weights would leave round-off in t.
    state.t = t0 + h;
    cached_problem_ = gradient_current ? &problem : nullptr;
    if (gradient_current) cached_q_ = state.q;
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  // Stage i: the substep first_ with weight â_i, then the other with a_i, at the times time_
  // says (see the class comment). The weights and running sums are the doubles SPRKStep forms,
  // so with time=stages the SUNDIALS example's steps are reproduced to rounding.
  StepStatus step_time_dependent(const TimeDependentHamiltonian& hamiltonian, State& state,
                                 double h) {
    const double t0 = state.t;
    double c_hat = 0, c = 0;
    for (size_t i = 0; i < kick_.size(); ++i) {
      const double first_weight = kick_[i], second_weight = drift_[i];
      const double first_start = t0 + c_hat * h, second_start = t0 + c * h;
      c_hat += first_weight;
      c += second_weight;
      if (time_ == TimeTreatment::kExtendedPhaseSpace) {
        // The clock moves with the drifts, over the drift's own interval.
        if (first_ == FirstSubstep::kKick) {
          if (first_weight != 0) kick(hamiltonian, state, first_weight * h, second_start);
          if (second_weight != 0) drift_over(hamiltonian, state, second_start, t0 + c * h);
        } else {
          if (first_weight != 0) drift_over(hamiltonian, state, first_start, t0 + c_hat * h);
          if (second_weight != 0) kick(hamiltonian, state, second_weight * h, t0 + c_hat * h);
        }
        continue;
      }
      const bool frozen = time_ == TimeTreatment::kFrozenPerStep;
      const double t_first = frozen ? t0 : t0 + c_hat * h;
      const double t_second = frozen ? t0 : t0 + c * h;
      if (first_ == FirstSubstep::kKick) {
        if (first_weight != 0) kick(hamiltonian, state, first_weight * h, t_first);
        if (second_weight != 0) drift(hamiltonian, state, second_weight * h, t_second);
      } else {
        if (first_weight != 0) drift(hamiltonian, state, first_weight * h, t_first);
        if (second_weight != 0) kick(hamiltonian, state, second_weight * h, t_second);
      }
    }
    state.t = t0 + h;
    ++counters_.steps;
    return StepStatus::success();
  }
  void kick(const TimeDependentHamiltonian& hamiltonian, State& state, double weight, double t) {
    hamiltonian.momentum_rate(state.q, state.p, t, rate_);
    ++counters_.force_evals;
    state.p += weight * rate_;
  }
  void drift(const TimeDependentHamiltonian& hamiltonian, State& state, double weight, double t) {
    hamiltonian.velocity(state.p, t, rate_);
    state.q += weight * rate_;
  }
  // q ← q + ∫_{t_a}^{t_b} ∂T/∂p(p, s) ds with p fixed (the exact flow of T(p, τ) + E), by
  // Gauss–Legendre with 5 nodes (degree 9 exact).
  void drift_over(const TimeDependentHamiltonian& hamiltonian, State& state, double t_a,
                  double t_b) {
    static constexpr double kNodes[5] = {-0.9061798459386639927976269, -0.5384693101056830910363144,
                                         0.0, 0.5384693101056830910363144,
                                         0.9061798459386639927976269};
    static constexpr double kWeights[5] = {0.2369268850561890875142640, 0.4786286704993664680412915,
                                           0.5688888888888888888888889, 0.4786286704993664680412915,
                                           0.2369268850561890875142640};
    const double middle = 0.5 * (t_a + t_b), half = 0.5 * (t_b - t_a);
    increment_ = Vec::Zero(state.q.size());
    for (int k = 0; k < 5; ++k) {
      hamiltonian.velocity(state.p, middle + half * kNodes[k], rate_);
      increment_ += (half * kWeights[k]) * rate_;
    }
    state.q += increment_;
  }

  // first=drift on a time-free problem: q ← q + h â_i M⁻¹p, then p ← p − h a_i ∇V(q).
  StepStatus step_drift_first(const Problem& problem, State& state, double h) {
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    const double t0 = state.t;
    for (size_t i = 0; i < kick_.size(); ++i) {
      if (kick_[i] != 0) state.q += (kick_[i] * h) * inverse_mass.cwiseProduct(state.p);
      if (drift_[i] != 0) {
        eval_gradient(problem, state.q, gradient_);
        state.p -= (drift_[i] * h) * gradient_;
      }
    }
    state.t = t0 + h;
    cached_problem_ = nullptr;
    ++counters_.steps;
    return StepStatus::success();
  }

  const coefficients::SprkTable& table_;
  TimeTreatment time_;
  FirstSubstep first_;
  Vec rate_;       // q̇ or ṗ of a time-dependent H at one substep
  Vec increment_;  // drift_over's quadrature sum
  std::vector<double> drift_, kick_;
  const Problem* cached_problem_ = nullptr;
  Vec cached_q_;  // q at which gradient_ = ∇V(q) was evaluated
  Vec gradient_;
};

}  // namespace

std::unique_ptr<Integrator> make_sprk(Params& params) {
  std::vector<std::string> names;
  for (const auto& table : coefficients::kSprkTables) names.emplace_back(table.name);
  const std::string name = params.choice(
      "table", "mclachlan4", names,
      "coefficients (orders): euler1 (1), leapfrog2, pseudo_leapfrog2, mclachlan2 (2), ruth3, "
      "mclachlan3 (3), candy_rozmus4, mclachlan4 (4), mclachlan5 (5), yoshida6 (6), "
      "suzuki_umeno8 (8), sofroniou10 (10): SUNDIALS SPRKStep's tables; blanes_moan4, "
      "blanes_moan6: Blanes & Moan 2002 SRKN_6^b, SRKN_11^b (order for T quadratic in p)");
  const std::string time = params.choice(
      "time", "extended", {"extended", "stages", "frozen"},
      "on a time-dependent H(q, p, t): extended (the splitting in the extended phase space, the "
      "clock moving with the drifts), stages (SPRKStep's stage times t_n + c_i h, first order) or "
      "frozen (H(q, p, t_n) for the whole step, first order)");
  const TimeTreatment treatment = time == "extended" ? TimeTreatment::kExtendedPhaseSpace
                                  : time == "stages" ? TimeTreatment::kStageTimes
                                                     : TimeTreatment::kFrozenPerStep;
  params.omit_default_from_canonical("time");
  const FirstSubstep first =
      params.choice("first", "kick", {"kick", "drift"},
                    "the substep each stage starts with, with the â weights: kick (p, as "
                    "SPRKStep documents f1) or drift (q; SUNDIALS' "
                    "ark_damped_harmonic_symplectic passes q' as f1)") == "drift"
          ? FirstSubstep::kDrift
          : FirstSubstep::kKick;
  params.omit_default_from_canonical("first");
  for (const auto& table : coefficients::kSprkTables) {
    if (table.name == name) return std::make_unique<Sprk>(table, treatment, first);
  }
  throw InputError("sprk: unknown table=" + name);  // unreachable: choice() checked it
}

}  // namespace geomint
