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

RecordColumn text(const std::string& name, std::optional<std::string> RunRecord::*field) {
  return {name, ColumnType::kText, [field](const RunRecord& record) { return record.*field; }};
}

RecordColumn real(const std::string& name, std::optional<double> RunRecord::*field) {
  return {name, ColumnType::kReal, [field](const RunRecord& record) -> std::optional<std::string> {
            if (!(record.*field)) return std::nullopt;
            return real_cell(*(record.*field));
          }};
}

RecordColumn integer(const std::string& name, std::optional<long> RunRecord::*field) {
  return {name, ColumnType::kInteger,
          [field](const RunRecord& record) -> std::optional<std::string> {
            if (!(record.*field)) return std::nullopt;
            return integer_cell(*(record.*field));
          }};
}

RecordColumn required_text(const std::string& name, std::string RunRecord::*field) {
  return {name, ColumnType::kText,
          [field](const RunRecord& record) { return std::optional(record.*field); }};
}

std::vector<RecordColumn> build_schema() {
  std::vector<RecordColumn> schema = {
      text("label", &RunRecord::label),
      required_text("problem", &RunRecord::problem),
      required_text("method", &RunRecord::method),
      text("family", &RunRecord::family),
      real("dt", &RunRecord::dt),
      real("t_end", &RunRecord::t_end),
      required_text("status", &RunRecord::status),
      text("message", &RunRecord::message),
      real("t_reached", &RunRecord::t_reached),
      integer("steps", &RunRecord::steps),
  };
  for (const auto& name : metric_names()) {
    schema.push_back({name, ColumnType::kReal, [name = name](const RunRecord& r) {
                        const auto found = r.metrics.find(name);
                        if (found == r.metrics.end()) return std::optional<std::string>();
                        return std::optional(real_cell(found->second));
                      }});
  }
  for (const auto& [name, member] : counter_columns()) {
    schema.push_back({name, ColumnType::kInteger, [member = member](const RunRecord& r) {
                        if (!r.counters) return std::optional<std::string>();
                        return std::optional(integer_cell((*r.counters).*member));
                      }});
  }
  schema.push_back(real("wall_s", &RunRecord::wall_s));
  schema.push_back(real("wall_s_min", &RunRecord::wall_s_min));
  schema.push_back(real("wall_s_iqr", &RunRecord::wall_s_iqr));
  schema.push_back(integer("wall_s_repeats", &RunRecord::wall_s_repeats));
  schema.push_back(real("recursive_passes_per_step", &RunRecord::recursive_passes_per_step));
  schema.push_back(integer("order_level", &RunRecord::order_level));
  schema.push_back(text("reference", &RunRecord::reference));
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
  return order ? real_cell(*order, 3) : "";
}
}  // namespace

const std::vector<Column<OrderRecord>>& order_schema() {
  using Cell = std::optional<std::string>;
  static const std::vector<Column<OrderRecord>> schema = {
      {"label", ColumnType::kText, [](const OrderRecord& r) { return r.label; }},
      {"problem", ColumnType::kText, [](const OrderRecord& r) { return Cell(r.problem); }},
      {"method", ColumnType::kText, [](const OrderRecord& r) { return Cell(r.method); }},
      {"order", ColumnType::kReal,
       [](const OrderRecord& r) { return fitted_order_cell(r, r.order); }},
      {"order_q", ColumnType::kReal,
       [](const OrderRecord& r) { return fitted_order_cell(r, r.order_q); }},
      {"order_p", ColumnType::kReal,
       [](const OrderRecord& r) { return fitted_order_cell(r, r.order_p); }},
      // "n/a" where the problem has no exact multipliers: a word, not a number (number()).
      {"order_multiplier", ColumnType::kReal,
       [](const OrderRecord& r) -> Cell {
         if (r.ran && !r.multiplier_applies) return "n/a";
         return fitted_order_cell(r, r.order_multiplier);
       }},
      {"declared_order", ColumnType::kInteger,
       [](const OrderRecord& r) -> Cell {
         if (!r.ran) return std::nullopt;
         return integer_cell(r.declared_order);
       }},
      // The dt of the fitted points, space-separated: one text cell.
      {"points_used", ColumnType::kText,
       [](const OrderRecord& r) -> Cell {
         if (!r.ran) return std::nullopt;
         std::vector<std::string> dts;
         for (double dt : r.points_used) dts.push_back(real_cell(dt));
         return fmt::format("{}", fmt::join(dts, " "));
       }},
      {"status", ColumnType::kText, [](const OrderRecord& r) { return Cell(r.status); }},
      {"message", ColumnType::kText, [](const OrderRecord& r) { return r.message; }},
      {"t_end", ColumnType::kReal,
       [](const OrderRecord& r) -> Cell {
         if (!r.t_end) return std::nullopt;
         return real_cell(*r.t_end);
       }},
  };
  return schema;
}

Row to_row(const OrderRecord& record) { return row_of(order_schema(), record); }

std::string records_to_csv(const std::vector<RunRecord>& records,
                           const std::vector<std::pair<std::string, std::string>>& lines) {
  return to_csv(record_table("", records, lines));
}

ColumnType record_column_type(const std::string& name) {
  for (const auto& column : record_schema()) {
    if (column.name == name) return column.type;
  }
  return ColumnType::kText;
}

ResultTable record_table(const std::string& name, const std::vector<RunRecord>& records,
                         const std::vector<std::pair<std::string, std::string>>& lines) {
  return {name, lines, typed_columns_of(record_schema(), records), to_rows(records)};
}

ResultTable order_table(const std::vector<OrderRecord>& records,
                        const std::vector<std::pair<std::string, std::string>>& lines) {
  return {"order", lines, typed_columns_of(order_schema(), records), to_rows(records)};
}

}  // namespace geomint
