// Symmetric composition Ψ_h = Φ_{γ_s h} ∘ … ∘ Φ_{γ_1 h} of a symmetric second-order base method
// Φ (Hairer, Lubich & Wanner, GNI §II.4 and §V.3; Yoshida 1990, Suzuki 1990, McLachlan 1995,
// Kahan & Li 1997); coefficients in high_order_coefficients.hpp.
#include <fmt/format.h>

#include <vector>

#include "integrators/high_order_coefficients.hpp"
#include "integrators/integrator.hpp"

namespace geomint {
namespace {

// The base method is built through the registry (make_integrator), so the composition runs the
// very integrator that `stormer_verlet` or `hp:alpha=0.5` name. A composition of symplectic,
// symmetric, variational maps is all three (GNI §V.3; Marsden & West 2001, §2.5): the flags are
// the base's. The order is the scheme's, valid for a symmetric base of order 2.
//
// State t after a step is set to t₀ + h rather than accumulated over the substeps, whose
// negative γ_i would leave round-off in t.
class Composition final : public Integrator {
 public:
  Composition(const coefficients::CompositionScheme& scheme, std::string base_name,
              std::unique_ptr<Integrator> base)
      : scheme_(scheme), base_name_(std::move(base_name)), base_(std::move(base)) {
    for (const long double gamma : scheme.gamma) gamma_.push_back(static_cast<double>(gamma));
  }

  MethodInfo info() const override {
    return {"composition", scheme_.order, base_->info().flags,
            fmt::format("symmetric composition ({}) of {}, GNI §V.3", scheme_.source, base_name_)};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "no formula in geomint: the composed map's limit (from the product of the base steps' "
        "matrices at γ_i h) is not derived here");
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    base_->reset(problem, state, gamma_.front() * h);
    steps_ = 0;
  }

  // DΦ = DΦ_s ⋯ DΦ_1: the base's tangents at the intermediate states.
  bool has_step_tangent(const Problem& problem) const override {
    return base_->has_step_tangent(problem);
  }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    Eigen::MatrixXd stage;
    tangent = Eigen::MatrixXd::Identity(2 * problem.dof(), 2 * problem.dof());
    return substeps(state, h, [&](double substep) {
      const StepStatus status = base_->step_tangent(problem, state, substep, stage);
      tangent = stage * tangent;
      return status;
    });
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    return substeps(state, h, [&](double substep) { return base_->step(problem, state, substep); });
  }

 private:
  // Runs `base_step(γ_i h)` for every stage, then sets t and the counters.
  template <class BaseStep>
  StepStatus substeps(State& state, double h, BaseStep&& base_step) {
    const double t0 = state.t;
    for (size_t i = 0; i < gamma_.size(); ++i) {
      const StepStatus status = base_step(gamma_[i] * h);
      if (!status.ok) {
        counters_ = base_->counters();
        counters_.steps = steps_;
        return StepStatus::failure(status.reason, fmt::format("substep {} of {}: {}", i + 1,
                                                              gamma_.size(), status.message));
      }
    }
    state.t = t0 + h;
    // The base counts every evaluation and solve; a composite step is one step.
    counters_ = base_->counters();
    counters_.steps = ++steps_;
    return StepStatus::success();
  }

  const coefficients::CompositionScheme& scheme_;
  std::string base_name_;
  std::unique_ptr<Integrator> base_;
  std::vector<double> gamma_;
  long steps_ = 0;
};

// The valid bases: registry names whose default instance is a fixed-step symmetric method of
// order 2, which is what the composition order conditions assume (GNI §V.3.2), plus the
// hp_midpoint alias; a method added to the registry is a valid base the day it lands. The base is
// a name, its parameters at their defaults: a nested spec would collide with the composition's own
// "key=value," syntax.
const std::vector<std::string>& symmetric_second_order_methods() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> found;
    for (const auto& entry : integrator_registry()) {
      // The wrappers: neither is a symmetric second-order base, and building penalty here would
      // build composition again while this list is being initialised (penalty lists its bases
      // the same way).
      if (entry.name == "composition" || entry.name == "penalty") continue;
      const MethodInfo info = make_integrator(entry.name)->info();
      if ((info.flags & kSymmetric) && info.order == 2 && !(info.flags & kAdaptive)) {
        found.push_back(entry.name);
      }
    }
    found.emplace_back("hp_midpoint");
    return found;
  }();
  return names;
}

}  // namespace

std::unique_ptr<Integrator> make_composition(Params& params) {
  const std::string base = params.choice(
      "base", "stormer_verlet", symmetric_second_order_methods(),
      "symmetric second-order base step: any registered method whose defaults are a fixed-step "
      "symmetric method of order 2, or hp_midpoint = hp:alpha=0.5");
  std::vector<std::string> scheme_names;
  for (const auto& scheme : coefficients::kCompositionSchemes) {
    scheme_names.emplace_back(scheme.name);
  }
  const std::string scheme_name =
      params.choice("scheme", "yoshida4", scheme_names,
                    "coefficients: yoshida4 (order 4, s=3), suzuki4 (4, s=5), yoshida6 (6, s=7), "
                    "kahan_li6 (6, s=9), kahan_li8 (8, s=17), mclachlan8 (8, s=15)");
  const coefficients::CompositionScheme* scheme = nullptr;
  for (const auto& candidate : coefficients::kCompositionSchemes) {
    if (candidate.name == scheme_name) scheme = &candidate;
  }
  // RATTLE's substeps each end on the constraint manifold with tangent momenta, so the
  // composition stays on it too (checked in tests/constraints_test.cpp).
  std::string base_spec = base == "hp_midpoint" ? "hp:alpha=0.5" : base;
  // Compensated summation (GNI §VIII.5) lives in the base: the stages run on one base object
  // without the state being edited between them, so its carried errors span every stage.
  const bool compensated = params.flag(
      "compensated", false,
      "Kahan's compensated summation of every stage's increments (base=stormer_verlet only)");
  params.omit_default_from_canonical("compensated");
  if (compensated) {
    if (base != "stormer_verlet") {
      throw InputError(
          "composition: compensated=true needs base=stormer_verlet (the base that "
          "implements compensated summation), not base=" +
          base);
    }
    base_spec = "stormer_verlet:compensated=true";
  }
  base_spec = with_base_max_iter(params, base_spec, "composition");
  return std::make_unique<Composition>(*scheme, base_spec, make_integrator(base_spec));
}

}  // namespace geomint
