// The typed records of a run and of an order study (docs/DESIGN.md §3) and the column schemas
// that turn them into the rows of summary.csv, order_points.csv, order.csv, `geomint run/order
// --out` and table.md: each column has one name and one format; a table lists only the columns
// some record sets.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "harness/table.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

// Absent optionals are empty cells (and columns no record sets are left out of the table).
struct RunRecord {
  std::optional<std::string> label;   // [[runs]] block label (sweeps)
  std::optional<long> order_level;    // k of the dt ladder dt0·2⁻ᵏ (order studies)
  std::string problem, method;        // canonical specs (error records: the specs as given)
  std::optional<std::string> family;  // method_family() of the method (sweeps and runs)
  std::optional<double> dt;           // fixed-step methods only
  std::optional<double> t_end;
  std::string status;                  // ok, nan, diverged, error, ...
  std::optional<std::string> message;  // why a run failed (or its timing pass did)
  std::optional<double> t_reached;     // failed runs: last step point that passed the checks
  std::optional<long> steps;
  std::map<std::string, double> metrics;  // metric columns of the schema, by name
  std::optional<Counters> counters;       // the integrator's work counters
  // Timing pass (harness/run.hpp TimingStats): wall_s is the median of the timed repeats, as
  // before repeats had a spread; wall_s_min and wall_s_iqr (Q3 − Q1) their minimum and
  // interquartile range, wall_s_repeats their count (fewer than asked: the budget cut them).
  std::optional<double> wall_s, wall_s_min, wall_s_iqr;
  std::optional<long> wall_s_repeats;
  // Recursive passes per step of the timing pass's warm-up run (tree problems only).
  std::optional<double> recursive_passes_per_step;
  std::optional<std::string> reference;  // file name of the reference solution used
};

// One order study (order.csv). A study that threw has only problem, method, status and
// message; one whose ladder ran has every fit column, left empty when there is no fit.
struct OrderRecord {
  std::optional<std::string> label;  // [[orders]] block label (sweeps)
  std::string problem, method;
  bool ran = false;             // the ladder ran: the fit columns are written
  std::optional<double> order;  // the fitted order; nullopt: no fit
  // The same fit on ‖q − q_exact‖, ‖p − p_exact‖ and |λ − λ_exact| alone (harness/order.hpp);
  // multiplier_applies is false when the problem has no exact multipliers (column "n/a").
  std::optional<double> order_q, order_p, order_multiplier;
  bool multiplier_applies = false;
  int declared_order = 0;              // MethodInfo::order
  std::vector<double> points_used;     // dt of the ladder points in the fit
  std::string status;                  // ok, no_fit, error
  std::optional<std::string> message;  // why points were dropped, or why there is no fit
  std::optional<double> t_end;
};

// A column of a record's table: its one name, its type and its cell (formatted by real_cell or
// integer_cell for the number types).
template <typename Record>
struct Column {
  std::string name;
  ColumnType type;
  // The formatted cell, or nullopt when the record does not set this column.
  std::function<std::optional<std::string>(const Record&)> value;
};
using RecordColumn = Column<RunRecord>;

template <typename Record>
Row row_of(const std::vector<Column<Record>>& schema, const Record& record) {
  Row row;
  for (const auto& column : schema) {
    if (auto cell = column.value(record)) row[column.name] = std::move(*cell);
  }
  return row;
}

// The schema columns set in at least one record, in schema order, with their types.
template <typename Record>
std::vector<TableColumn> typed_columns_of(const std::vector<Column<Record>>& schema,
                                          const std::vector<Record>& records) {
  std::vector<TableColumn> columns;
  for (const auto& column : schema) {
    for (const auto& record : records) {
      if (column.value(record)) {
        columns.push_back({column.name, column.type});
        break;
      }
    }
  }
  return columns;
}

// The schema columns set in at least one record, in schema order.
template <typename Record>
std::vector<std::string> columns_of(const std::vector<Column<Record>>& schema,
                                    const std::vector<Record>& records) {
  std::vector<std::string> columns;
  for (const auto& column : schema) {
    for (const auto& record : records) {
      if (column.value(record)) {
        columns.push_back(column.name);
        break;
      }
    }
  }
  return columns;
}

// Every column a RunRecord can fill, in the order tables list them (standard_columns() order,
// then order_level and reference, the columns only some tables have).
const std::vector<RecordColumn>& record_schema();

// The record as a row of formatted cells. Throws std::logic_error when a metric has no column
// in the schema, so a new metric cannot silently be written under a second spelling.
Row to_row(const RunRecord& record);

// The schema columns set in at least one record, in schema order.
std::vector<std::string> record_columns(const std::vector<RunRecord>& records);

// order.csv's schema (label, problem, method, order, declared_order, points_used, status,
// message, t_end) and its rows.
const std::vector<Column<OrderRecord>>& order_schema();
Row to_row(const OrderRecord& record);

// CSV (with provenance lines) of the records over record_columns(records).
std::string records_to_csv(const std::vector<RunRecord>& records,
                           const std::vector<std::pair<std::string, std::string>>& lines);

template <typename Record>
std::vector<Row> to_rows(const std::vector<Record>& records) {
  std::vector<Row> rows;
  rows.reserve(records.size());
  for (const auto& record : records) rows.push_back(to_row(record));
  return rows;
}

// The type of a run record's column `name` (record_schema()); text for a name it does not have.
ColumnType record_column_type(const std::string& name);

// The in-memory table of run records (summary.csv, `geomint run --out`) over record_columns().
ResultTable record_table(const std::string& name, const std::vector<RunRecord>& records,
                         const std::vector<std::pair<std::string, std::string>>& lines);

// order.csv's table of order studies over the order_schema() columns they set.
ResultTable order_table(const std::vector<OrderRecord>& records,
                        const std::vector<std::pair<std::string, std::string>>& lines);

}  // namespace geomint
