// Optional structure metrics of a run (docs/USAGE.md "Optional structure metrics"; docs/DESIGN.md
// §3): the symplecticity defect of the one-step map, the period measured from zero crossings and
// the energy-error growth exponent. They are computed only when asked for
// (RunConfig::extra_metrics: `run --metric`, or a scene whose table_columns list them), so tables
// that do not ask keep their columns.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "harness/observers.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

class MethodFactory;  // harness/run_spec.hpp

// The metrics below that take a MethodFactory run fresh integrators from it; their spec-string
// forms parse the spec once and call them (the command line, tests).

// The names accepted by --metric / implied by table_columns; "period_measured" also reports
// period_err_rel.
const std::vector<std::string>& optional_metric_names();
// InputError naming `option` unless every name is an optional metric.
void check_optional_metrics(const std::vector<std::string>& names, const std::string& option);

// ‖DΦᵀ J DΦ − J‖_max / max(1, ‖DΦ‖²_max) of the one-step map Φ: (q, p) ↦ (q, p) with step h at
// `state` (max norm: the largest entry), J the canonical 2n×2n form. DΦ is the method's
// linearised step (Integrator::step_tangent, integrators/tangent.hpp) taken by a fresh integrator
// from a reset at `state`, never a difference quotient; NaN when the step fails. Its floor (round
// off, docs/USAGE.md "Optional structure metrics") is measured by tests/structure_metrics_test.cpp.
double symplecticity_defect(const MethodFactory& method, const Problem& problem, const State& state,
                            double h);
// The same defect of a given 2n×2n DΦ.
double symplecticity_defect(const Eigen::MatrixXd& tangent);

// The largest problem whose linearised step (a dense 2n x 2n matrix) and normal modes (a dense
// eigensolver) are computed: at the limit `geomint modes` takes 0.3 GB and about 100 s (a
// spring_chain on the 2-core development VM); far above it the allocation fails.
inline constexpr int kMaxDenseTangentDof = 2000;

// Why the defect does not apply to `method` on `problem`, or "" when it does: it needs a
// fixed-step method that implements the linearised step there (unforced, unconstrained problems
// with a Hessian; not the library and adaptive solvers) and at most kMaxDenseTangentDof degrees
// of freedom.
std::string symplecticity_defect_not_applicable(const Integrator& method, const Problem& problem);
bool symplecticity_defect_applies(const Integrator& method, const Problem& problem);

// One normal mode of a linear problem (Problem::is_linear) and of a method's one-step map on it:
// ω from the generalised eigenproblem K v = ω²M v (K = ∇²V), and the pair of eigenvalues
// λ = ρe^{±iθ} of DΦ on that mode's (q, p) plane, as the discrete frequency ω̃ = θ/h and the
// amplitude factor per step ρ = max |λ| (1 for a stable symplectic method).
struct DiscreteMode {
  double omega = 0;           // continuous frequency
  double omega_discrete = 0;  // θ/h, θ ∈ [0, π]
  double amplitude = 0;       // ρ
};
// Why the normal-mode metrics do not apply, or "": they need a linear problem and the
// linearised step (symplecticity_defect_not_applicable).
std::string normal_modes_not_applicable(const Integrator& method, const Problem& problem);
// The modes in increasing ω, each with its discrete counterpart: DΦ from step_tangent at the
// problem's initial state (the map is linear, so any state gives the same), transformed to the
// M-orthonormal modal coordinates (q = V x, p = M V y), where every method here (a function of
// hM⁻¹K) is block diagonal with one 2×2 block per mode; the eigenvalues of DΦ are those of the
// blocks. To full relative precision for slow modes too: ω is the long-double Rayleigh quotient
// of the dense eigenvector, and each block is the method's step on the mode's own oscillator
// (unit mass, stiffness ω²) unless that differs from the projected block (then the projected
// one). Empty when not applicable or the step fails.
std::vector<DiscreteMode> discrete_normal_modes(const MethodFactory& method, const Problem& problem,
                                                double h);
// mode_freq_err_max = max over modes with ω > 0 of |ω̃ − ω|/ω, mode_damping_max = max |ρ − 1|;
// added to `metrics` when asked for in `names` and applicable.
void add_normal_mode_metrics(const MethodFactory& method, const Problem& problem, double h,
                             const std::vector<std::string>& names,
                             std::map<std::string, double>& metrics);

// The observer of the requested metrics of `method`'s one-step map on `problem` with step h
// (symplecticity_defect when it applies, mode_freq_err_max, mode_damping_max), computed when the
// run finishes; nullptr when none is requested. `method` makes the fresh integrators.
std::unique_ptr<Observer> make_step_map_observer(const MethodFactory& method,
                                                 const Problem& problem, double h,
                                                 const std::vector<std::string>& names);

}  // namespace geomint
