// The metric table: every metric column of a run record (docs/DESIGN.md §3) declared once, with
// what computes it and whether it must be asked for. The schema, the record writer, `run --metric`
// and the gates all read their metric names from here.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace geomint {

struct MetricDecl {
  std::string_view name;  // the column name in every table
  // What computes it and when it applies (an observer or a function, and its file).
  std::string_view computed_by;
  // > 0: a name `run --metric` (and a scene's table_columns) accepts, at this position in the
  // list the help text and the error message print; 0: not a name one asks for.
  int option_rank = 0;
  // The optional metric that brings this column along (period_err_rel with period_measured);
  // nullptr for an option itself and for the metrics computed whenever they apply.
  const MetricDecl* companion_of = nullptr;

  // Computed only when asked for (an option or a companion of one).
  constexpr bool optional() const { return option_rank > 0 || companion_of != nullptr; }
  // The key of the metric in RunRecord::metrics.
  std::string key() const { return std::string(name); }
};

// One constant per metric, named as its column. Every cell is written by format_number (shortest
// round-trip text), which the committed results rely on to reproduce bit for bit.
namespace metric {
// clang-format off
inline constexpr MetricDecl energy_err_max{"energy_err_max", "EnergyObserver (harness/observers.cpp): |H − H_ref|/|H₀| over the step points; problems with an energy reference"};
inline constexpr MetricDecl energy_err_final{"energy_err_final", "EnergyObserver (harness/observers.cpp): the same error at the last step point"};
inline constexpr MetricDecl energy_drift{"energy_drift", "EnergyObserver (harness/observers.cpp): slope of the per-window maxima of the energy error"};
inline constexpr MetricDecl modified_energy_err_max{"modified_energy_err_max", "modified energy observer (harness/modified_energy.cpp): methods with a known modified Hamiltonian", 10};
inline constexpr MetricDecl modified_energy_err_slope{"modified_energy_err_slope", "modified energy observer (harness/modified_energy.cpp)", 0, &modified_energy_err_max};
inline constexpr MetricDecl energy_err_slope{"energy_err_slope", "modified energy observer (harness/modified_energy.cpp)", 0, &modified_energy_err_max};
inline constexpr MetricDecl energy_growth_exponent{"energy_growth_exponent", "growth observer (harness/structure_metrics.cpp): unforced problems", 3};
inline constexpr MetricDecl momentum_err_max{"momentum_err_max", "MomentumObserver (harness/observers.cpp): problems with a linear momentum"};
inline constexpr MetricDecl angular_momentum_err_max{"angular_momentum_err_max", "MomentumObserver (harness/observers.cpp): problems with an angular momentum"};
inline constexpr MetricDecl casimir_err_max{"casimir_err_max", "CasimirObserver (harness/observers.cpp): problems with a Casimir"};
inline constexpr MetricDecl constraint_err_max{"constraint_err_max", "ConstraintObserver (harness/observers.cpp): constrained problems"};
inline constexpr MetricDecl constraint_vel_err_max{"constraint_vel_err_max", "ConstraintObserver (harness/observers.cpp): constrained problems"};
inline constexpr MetricDecl orthogonality_err_max{"orthogonality_err_max", "OrthogonalityObserver (harness/observers.cpp): problems with an attitude matrix"};
inline constexpr MetricDecl magnetic_moment_err_max{"magnetic_moment_err_max", "MagneticMomentObserver (harness/observers.cpp): charged particles"};
inline constexpr MetricDecl symplecticity_defect{"symplecticity_defect", "symplecticity defect observer (harness/structure_metrics.cpp): fixed-step methods with a linearised step", 1};
inline constexpr MetricDecl symplecticity_defect_map{"symplecticity_defect_map", "map defect observer (harness/map_defect.cpp)", 6};
inline constexpr MetricDecl symplecticity_defect_map_fd_err{"symplecticity_defect_map_fd_err", "map defect observer (harness/map_defect.cpp)", 0, &symplecticity_defect_map};
inline constexpr MetricDecl symplecticity_defect_map_slope{"symplecticity_defect_map_slope", "map defect observer (harness/map_defect.cpp)", 0, &symplecticity_defect_map};
inline constexpr MetricDecl lyapunov_max{"lyapunov_max", "chaos observer (harness/chaos_metrics.cpp)", 7};
inline constexpr MetricDecl megno{"megno", "chaos observer (harness/chaos_metrics.cpp)", 8};
inline constexpr MetricDecl megno_final{"megno_final", "chaos observer (harness/chaos_metrics.cpp)", 0, &megno};
inline constexpr MetricDecl chaos_tangent_fd{"chaos_tangent_fd", "chaos observer (harness/chaos_metrics.cpp)", 0, &lyapunov_max};
inline constexpr MetricDecl valid_time{"valid_time", "valid time observer (harness/chaos_metrics.cpp): an exact solution or a reference", 9};
inline constexpr MetricDecl valid_time_reached{"valid_time_reached", "valid time observer (harness/chaos_metrics.cpp)", 0, &valid_time};
inline constexpr MetricDecl mode_freq_err_max{"mode_freq_err_max", "normal mode observer (harness/structure_metrics.cpp): linear problems", 4};
inline constexpr MetricDecl mode_damping_max{"mode_damping_max", "normal mode observer (harness/structure_metrics.cpp): linear problems", 5};
inline constexpr MetricDecl error_final{"error_final", "ExactErrorObserver, EndReferenceObserver (harness/observers.cpp), reference observer (harness/reference.cpp)"};
inline constexpr MetricDecl error_max{"error_max", "ExactErrorObserver (harness/observers.cpp), reference observer (harness/reference.cpp)"};
inline constexpr MetricDecl scd{"scd", "EndReferenceObserver (harness/observers.cpp): problems with an end reference"};
inline constexpr MetricDecl phase_err{"phase_err", "PhaseObserver (harness/observers.cpp): periodic unforced problems with an exact solution"};
inline constexpr MetricDecl period_err{"period_err", "PhaseObserver (harness/observers.cpp)"};
inline constexpr MetricDecl period_measured{"period_measured", "period observer (harness/structure_metrics.cpp): unforced problems", 2};
inline constexpr MetricDecl period_err_rel{"period_err_rel", "period observer (harness/structure_metrics.cpp): a known period", 0, &period_measured};
inline constexpr MetricDecl perihelion_err{"perihelion_err", "PericentreObserver (harness/observers.cpp): eccentric planar orbits"};
// clang-format on
}  // namespace metric

// Every metric, in the column order of every table (between `steps` and `order`).
const std::vector<const MetricDecl*>& metric_table();

// The names of metric_table(), in that order.
const std::vector<std::string>& metric_names();

// The declaration named `name`, or nullptr when no metric has that name.
const MetricDecl* find_metric(std::string_view name);

// Whether `metric` is among the names asked for (RunConfig::extra_metrics).
bool requested(const std::vector<std::string>& names, const MetricDecl& metric);

}  // namespace geomint
