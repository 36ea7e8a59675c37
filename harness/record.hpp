// The typed record of one run (docs/DESIGN.md §5) and the one column schema that turns records
// into the rows of summary.csv, order_points.csv, `geomint run --out` and table.md: each column
// has one name and one formatting, and a table lists only the columns some record sets.
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
  std::optional<std::string> label;  // [[runs]] block label (sweeps)
  std::optional<long> order_level;   // k of the dt ladder dt0·2⁻ᵏ (order studies)
  std::string problem, method;       // canonical specs (error records: the specs as given)
  std::optional<double> dt;          // fixed-step methods only
  std::optional<double> t_end;
  std::string status;                  // ok, nan, diverged, error, ...
  std::optional<std::string> message;  // why a run failed (or its timing pass did)
  std::optional<double> t_reached;     // failed runs: last step point that passed the checks
  std::optional<long> steps;
  std::map<std::string, double> metrics;  // metric columns of the schema, by name
  std::optional<Counters> counters;       // the integrator's work counters
  std::optional<double> wall_s;           // median of the timing pass
  std::optional<std::string> reference;   // file name of the reference solution used
};

struct RecordColumn {
  std::string name;
  // The formatted cell, or nullopt when the record does not set this column.
  std::function<std::optional<std::string>(const RunRecord&)> value;
};

// Every column a RunRecord can fill, in the order tables list them (standard_columns() order,
// then order_level and reference, the columns only some tables have).
const std::vector<RecordColumn>& record_schema();

// The record as a row of formatted cells. Throws std::logic_error when a metric has no column
// in the schema, so a new metric cannot silently be written under a second spelling.
Row to_row(const RunRecord& record);
std::vector<Row> to_rows(const std::vector<RunRecord>& records);

// The schema columns set in at least one record, in schema order.
std::vector<std::string> record_columns(const std::vector<RunRecord>& records);

// CSV (with provenance lines) of the records over record_columns(records).
std::string records_to_csv(const std::vector<RunRecord>& records,
                           const std::vector<std::pair<std::string, std::string>>& lines);

}  // namespace geomint
