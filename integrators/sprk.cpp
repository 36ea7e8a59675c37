// Explicit symplectic partitioned Runge–Kutta (splitting) methods for H = T(p) + V(q): the
// tables of SUNDIALS 7's SPRKStep and Blanes & Moan (2002), in sprk_coefficients.hpp
// (GNI §II.2 and §VI.3; McLachlan & Quispel, Acta Numerica 11, 2002).
#include <fmt/format.h>

#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "integrators/sprk_coefficients.hpp"
#include "problems/mass_operator.hpp"

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
class Sprk final : public Integrator {
 public:
  explicit Sprk(const coefficients::SprkTable& table) : table_(table) {
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
                        table_.nystrom_only ? ", order for T quadratic in p (Nyström)" : "")};
  }

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
  const coefficients::SprkTable& table_;
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
  for (const auto& table : coefficients::kSprkTables) {
    if (table.name == name) return std::make_unique<Sprk>(table);
  }
  throw InputError("sprk: unknown table=" + name);  // unreachable: choice() checked it
}

}  // namespace geomint
