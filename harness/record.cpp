// The run record's column schema and writers (see record.hpp).
#include "harness/record.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "harness/metrics.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace {

// A new field of Counters needs its column in counter_columns() (named, in that order, in
// standard_columns()): this fails to compile until it has one, so no counter is left out of the
// tables or written under a second spelling.
constexpr int kCounterFields = 8;  // steps (from the run loop, not the integrator) + 7 below
static_assert(sizeof(Counters) == kCounterFields * sizeof(long),
              "a Counters field was added or removed: update counter_columns() in record.cpp");

const std::vector<std::pair<const char*, long Counters::*>>& counter_columns() {
  static const std::vector<std::pair<const char*, long Counters::*>> columns = {
      {"force_evals", &Counters::force_evals},
      {"energy_evals", &Counters::energy_evals},
      {"hessian_evals", &Counters::hessian_evals},
      {"newton_iters", &Counters::newton_iters},
      {"linear_solves", &Counters::linear_solves},
      {"factorizations", &Counters::factorizations},
      {"rejected", &Counters::rejected}};
  return columns;
}

template <typename T>
std::function<std::optional<std::string>(const RunRecord&)> text(
    std::optional<T> RunRecord::*field) {
  return [field](const RunRecord& record) { return record.*field; };
}

std::function<std::optional<std::string>(const RunRecord&)> real(
    std::optional<double> RunRecord::*field) {
  return [field](const RunRecord& record) -> std::optional<std::string> {
    if (!(record.*field)) return std::nullopt;
    return format_number(*(record.*field));
  };
}

std::function<std::optional<std::string>(const RunRecord&)> integer(
    std::optional<long> RunRecord::*field) {
  return [field](const RunRecord& record) -> std::optional<std::string> {
    if (!(record.*field)) return std::nullopt;
    return std::to_string(*(record.*field));
  };
}

std::vector<RecordColumn> build_schema() {
  std::vector<RecordColumn> schema = {
      {"label", text(&RunRecord::label)},
      {"problem", [](const RunRecord& r) { return std::optional(r.problem); }},
      {"method", [](const RunRecord& r) { return std::optional(r.method); }},
      {"family", text(&RunRecord::family)},
      {"dt", real(&RunRecord::dt)},
      {"t_end", real(&RunRecord::t_end)},
      {"status", [](const RunRecord& r) { return std::optional(r.status); }},
      {"message", text(&RunRecord::message)},
      {"t_reached", real(&RunRecord::t_reached)},
      {"steps", integer(&RunRecord::steps)},
  };
  for (const auto& name : metric_names()) {
    schema.push_back({name, [name = name](const RunRecord& r) {
                        const auto found = r.metrics.find(name);
                        if (found == r.metrics.end()) return std::optional<std::string>();
                        return std::optional(format_number(found->second));
                      }});
  }
  for (const auto& [name, member] : counter_columns()) {
    schema.push_back({name, [member = member](const RunRecord& r) {
                        if (!r.counters) return std::optional<std::string>();
                        return std::optional(std::to_string((*r.counters).*member));
                      }});
  }
  schema.push_back({"wall_s", real(&RunRecord::wall_s)});
  schema.push_back({"wall_s_min", real(&RunRecord::wall_s_min)});
  schema.push_back({"wall_s_iqr", real(&RunRecord::wall_s_iqr)});
  schema.push_back({"wall_s_repeats", integer(&RunRecord::wall_s_repeats)});
  schema.push_back({"order_level", integer(&RunRecord::order_level)});
  schema.push_back({"reference", text(&RunRecord::reference)});
  return schema;
}

}  // namespace

const std::vector<RecordColumn>& record_schema() {
  static const std::vector<RecordColumn> schema = build_schema();
  return schema;
}

Row to_row(const RunRecord& record) {
  for (const auto& [name, value] : record.metrics) {
    if (find_metric(name) == nullptr) {
      throw std::logic_error(fmt::format(
          "metric '{}' is not declared in the metric table (harness/metrics.hpp)", name));
    }
  }
  return row_of(record_schema(), record);
}

std::vector<std::string> record_columns(const std::vector<RunRecord>& records) {
  return columns_of(record_schema(), records);
}

namespace {
// A fitted order to 3 decimals, empty when there was no fit, no cell when the ladder did not run.
std::optional<std::string> fitted_order_cell(const OrderRecord& r,
                                             const std::optional<double>& order) {
  if (!r.ran) return std::nullopt;
  return order ? fmt::format("{:.3f}", *order) : "";
}
}  // namespace

const std::vector<Column<OrderRecord>>& order_schema() {
  using Cell = std::optional<std::string>;
  static const std::vector<Column<OrderRecord>> schema = {
      {"label", [](const OrderRecord& r) { return r.label; }},
      {"problem", [](const OrderRecord& r) { return Cell(r.problem); }},
      {"method", [](const OrderRecord& r) { return Cell(r.method); }},
      {"order", [](const OrderRecord& r) { return fitted_order_cell(r, r.order); }},
      {"order_q", [](const OrderRecord& r) { return fitted_order_cell(r, r.order_q); }},
      {"order_p", [](const OrderRecord& r) { return fitted_order_cell(r, r.order_p); }},
      {"order_multiplier",
       [](const OrderRecord& r) -> Cell {
         if (r.ran && !r.multiplier_applies) return "n/a";
         return fitted_order_cell(r, r.order_multiplier);
       }},
      {"declared_order",
       [](const OrderRecord& r) -> Cell {
         if (!r.ran) return std::nullopt;
         return std::to_string(r.declared_order);
       }},
      {"points_used",
       [](const OrderRecord& r) -> Cell {
         if (!r.ran) return std::nullopt;
         std::vector<std::string> dts;
         for (double dt : r.points_used) dts.push_back(format_number(dt));
         return fmt::format("{}", fmt::join(dts, " "));
       }},
      {"status", [](const OrderRecord& r) { return Cell(r.status); }},
      {"message", [](const OrderRecord& r) { return r.message; }},
      {"t_end",
       [](const OrderRecord& r) -> Cell {
         if (!r.t_end) return std::nullopt;
         return format_number(*r.t_end);
       }},
  };
  return schema;
}

Row to_row(const OrderRecord& record) { return row_of(order_schema(), record); }

std::string records_to_csv(const std::vector<RunRecord>& records,
                           const std::vector<std::pair<std::string, std::string>>& lines) {
  return to_csv(to_rows(records), record_columns(records), lines);
}

}  // namespace geomint
