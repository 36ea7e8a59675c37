// The metric table (see metrics.hpp).
#include "harness/metrics.hpp"

#include <algorithm>

namespace geomint {

const std::vector<const MetricDecl*>& metric_table() {
  using namespace metric;
  static const std::vector<const MetricDecl*> table = {&energy_err_max,
                                                       &energy_err_final,
                                                       &energy_drift,
                                                       &modified_energy_err_max,
                                                       &modified_energy_err_slope,
                                                       &energy_err_slope,
                                                       &energy_growth_exponent,
                                                       &momentum_err_max,
                                                       &angular_momentum_err_max,
                                                       &casimir_err_max,
                                                       &constraint_err_max,
                                                       &constraint_vel_err_max,
                                                       &orthogonality_err_max,
                                                       &magnetic_moment_err_max,
                                                       &symplecticity_defect,
                                                       &symplecticity_defect_map,
                                                       &symplecticity_defect_map_fd_err,
                                                       &symplecticity_defect_map_slope,
                                                       &lyapunov_max,
                                                       &megno,
                                                       &megno_final,
                                                       &chaos_tangent_fd,
                                                       &valid_time,
                                                       &valid_time_reached,
                                                       &mode_freq_err_max,
                                                       &mode_damping_max,
                                                       &error_final,
                                                       &error_max,
                                                       &scd,
                                                       &phase_err,
                                                       &period_err,
                                                       &period_measured,
                                                       &period_err_rel,
                                                       &perihelion_err};
  return table;
}

const std::vector<std::string>& metric_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const MetricDecl* decl : metric_table()) out.push_back(decl->key());
    return out;
  }();
  return names;
}

const MetricDecl* find_metric(std::string_view name) {
  for (const MetricDecl* decl : metric_table()) {
    if (decl->name == name) return decl;
  }
  return nullptr;
}

bool requested(const std::vector<std::string>& names, const MetricDecl& metric) {
  return std::find(names.begin(), names.end(), metric.name) != names.end();
}

}  // namespace geomint
