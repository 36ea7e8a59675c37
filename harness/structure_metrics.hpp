// Optional structure metrics of a run (README "Metrics"; docs/DESIGN.md §3): the symplecticity
// defect of the one-step map, the period measured from zero crossings and the energy-error growth
// exponent. They are computed only when asked for (RunConfig::extra_metrics: `run --metric`, or
// a scene whose table_columns list them), so tables that do not ask keep their columns.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "harness/observers.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

// The names accepted by --metric / implied by table_columns; "period_measured" also reports
// period_err_rel.
const std::vector<std::string>& optional_metric_names();
// InputError naming `option` unless every name is an optional metric.
void check_optional_metrics(const std::vector<std::string>& names, const std::string& option);

// ‖DΦᵀ J DΦ − J‖_max / max(1, ‖DΦ‖²_max) of the one-step map Φ: (q, p) ↦ (q, p) with step h at
// `state` (max norm: the largest entry), J the canonical 2n×2n form. DΦ is a central difference
// with steps ε^{1/3}·max(‖(q, p)‖∞, 1) of maps each run by a fresh integrator from a reset at the
// perturbed state; NaN when a step fails. Its noise floor (~1e-10, README "Metrics") is measured
// by harness/structure_metrics_test.cpp.
double symplecticity_defect(const std::string& method_spec, const Problem& problem,
                            const State& state, double h);

// Whether the defect applies: fixed-step method, unforced and unconstrained problem.
bool symplecticity_defect_applies(const Integrator& method, const Problem& problem);

// Observers for the requested optional trajectory metrics that apply to `problem`.
std::vector<std::unique_ptr<Observer>> make_optional_observers(
    const Problem& problem, const std::vector<std::string>& names);

}  // namespace geomint
