// The metric table (see metrics.hpp).
#include "harness/metrics.hpp"

#include <algorithm>

namespace geomint {

const std::vector<const MetricDecl*>& metric_table() {
  static const std::vector<const MetricDecl*> table = {
#define GEOMINT_METRIC(name, option_rank, companion_of, computed_by) &metric::name,
#define GEOMINT_METRIC_OBSERVED(name, option_rank, factory, computed_by) &metric::name,
#include "harness/metrics.def"
#undef GEOMINT_METRIC
#undef GEOMINT_METRIC_OBSERVED
  };
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
