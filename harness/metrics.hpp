// The metric table: every metric column of a run record (docs/DESIGN.md §3) declared once, in
// metrics.def, with what computes it, the factory of its observer and whether it must be asked for.
// The schema, the record writer, `run --metric`, the run's observers and the gates read it.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace geomint {

class Observer;
struct ObserverContext;
// The observers of one run (harness/observers.hpp).
using ObserverList = std::vector<std::unique_ptr<Observer>>;
// Adds the observer of a metric row to `observers` when the metric applies to the run in
// `context` (and, for an option, was asked for); adds nothing otherwise.
using ObserverFactory = void (*)(const ObserverContext& context, ObserverList& observers);

// The observer factories of metrics.def, each defined in its observer's file.
#define GEOMINT_METRIC(name, option_rank, companion_of, computed_by)
#define GEOMINT_METRIC_OBSERVED(name, option_rank, factory, computed_by) \
  void factory(const ObserverContext& context, ObserverList& observers);
#include "harness/metrics.def"
#undef GEOMINT_METRIC
#undef GEOMINT_METRIC_OBSERVED

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
  // The factory of the observer that writes this column and the ones below it that have none;
  // nullptr on those.
  ObserverFactory observer = nullptr;

  // Computed only when asked for (an option or a companion of one).
  constexpr bool optional() const { return option_rank > 0 || companion_of != nullptr; }
  // The key of the metric in RunRecord::metrics.
  std::string key() const { return std::string(name); }
};

// One constant per row of metrics.def, named as its column. Every cell is written by
// format_number (shortest round-trip text), which the committed results rely on to reproduce bit
// for bit.
namespace metric {
#define GEOMINT_METRIC(name, option_rank, companion_of, computed_by) \
  inline constexpr MetricDecl name{#name, computed_by, option_rank, companion_of};
#define GEOMINT_METRIC_OBSERVED(name, option_rank, factory, computed_by) \
  inline constexpr MetricDecl name{#name, computed_by, option_rank, nullptr, &factory};
#include "harness/metrics.def"
#undef GEOMINT_METRIC
#undef GEOMINT_METRIC_OBSERVED
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
