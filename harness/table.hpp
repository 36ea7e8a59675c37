// Result rows and their writers: CSV with `# key: value` provenance lines (docs/DESIGN.md §5),
// written to a temporary file and renamed so a crash never leaves a half-written table, and
// Markdown tables for results/<scene>/table.md.
#pragma once

#include <chrono>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace geomint {

// One output row: column name → formatted value. Absent columns are left empty in a CSV.
using Row = std::map<std::string, std::string>;

// Provenance lines: version, git SHA, compiler and flags, library versions, CPU, date, command.
std::vector<std::pair<std::string, std::string>> provenance(const std::string& command_line);

// What a result table's column holds (docs/DESIGN.md §5 "Tables in memory"): text, an integer
// (counts) or a real number. Its cells are formatted by integer_cell and real_cell only.
enum class ColumnType { kText, kInteger, kReal };

// "text", "integer" or "real".
const char* column_type_name(ColumnType type);

// The cell text of a number, the one place of the tables' number formats: a real is the
// shortest text that reads back as the same double (format_number: the committed results rely
// on it to reproduce bit for bit), or `decimals` digits after the point when given (a fitted
// order, "2.000"); an integer its decimal digits.
std::string real_cell(double value, int decimals = -1);
std::string integer_cell(long value);

struct TableColumn {
  std::string name;
  ColumnType type = ColumnType::kText;
};

// A result table in memory, as `sweep` and `order` return it and every writer consumes it: its
// provenance lines, its typed columns in CSV order and its rows. A row holds each cell as the CSV
// writes it (absent: an empty cell), so the CSV, table.md and the gates see one text, and a real
// cell reads back (number()) as the double it was formatted from, bit for bit. A real column may
// hold a word where there is no number (order_multiplier "n/a"): number() is then nullopt.
struct ResultTable {
  std::string name;  // summary, order, order_points, stability (the CSV's file stem)
  std::vector<std::pair<std::string, std::string>> provenance;
  std::vector<TableColumn> columns;
  std::vector<Row> rows;

  std::vector<std::string> column_names() const;
  // The column of that name, or nullptr.
  const TableColumn* column(const std::string& name) const;
  // The value of a provenance line, or `absent`.
  std::string value(const std::string& key, const std::string& absent = "") const;
  // The cell as a number (nullopt: empty, or no number); nan and inf cells are numbers.
  std::optional<double> number(size_t row, const std::string& column) const;
};

// Columns present in any row, ordered by `preferred` first, then alphabetically.
std::vector<std::string> column_union(const std::vector<Row>& rows,
                                      const std::vector<std::string>& preferred);

// "# key: value\n", the provenance line of every CSV writer: a newline or carriage return in
// `key` or `value` (a path in the command line) becomes a space, as in a cell, since it would end
// the line and make the rest of the value the table's header.
std::string provenance_line(const std::string& key, const std::string& value);

// CSV text (header + rows); values containing ',' or '"' are quoted.
std::string to_csv(const std::vector<Row>& rows, const std::vector<std::string>& columns,
                   const std::vector<std::pair<std::string, std::string>>& provenance_lines);

// The CSV of the table (its provenance lines, header and rows): the text every table file holds.
std::string to_csv(const ResultTable& table);

// Parses CSV text as written by to_csv: `#` provenance lines are skipped, the first other line
// is the header, quoted fields may contain ',' and '""'. Empty fields are left out of the row.
// A damaged table is an InputError naming `source` (the file, when given) and the line: a row
// with fewer or more fields than the header, a text whose last line has no terminating newline
// (a table cut short), a quote that is not closed or stray text after a closing quote, no header.
std::vector<Row> parse_csv(const std::string& text, const std::string& source = "");

// A CSV table as read back: its leading `# key: value` provenance lines, its header's column
// names (parse_csv drops empty cells, so a column whose cells are all empty is known only from
// the header) and its rows.
struct CsvTable {
  std::string path;
  std::vector<std::pair<std::string, std::string>> provenance;
  std::vector<std::string> columns;
  std::vector<Row> rows;
  // The value of a provenance line, or `absent` when the table has none.
  std::string value(const std::string& key, const std::string& absent = "") const;
};

// Parses `text` (see parse_csv); `source` names it in messages.
CsvTable parse_csv_table(const std::string& text, const std::string& source);

// Reads and parses the CSV file at `path`: the one reader of every table geomint reads back
// (gate, merge, --markdown-only, --timing-only, shards). InputError naming the file when it
// cannot be read or is damaged (see parse_csv).
CsvTable read_csv_file(const std::string& path);

// The JSON of a table as read back from its CSV (docs/USAGE.md "JSON tables", the schema
// docs/schema/table.schema.json): {"provenance": {key: value}, "columns": [names in CSV order],
// "types": {column: "number" or "string"}, "rows": [{column: cell}]}. A column is "number" when
// it holds a JSON number literal and every other non-empty cell is one or nan/-nan/inf/-inf (a
// status "nan" alone stays text); its cells are then the CSV's
// digits as JSON numbers (so they parse to the same doubles) and its non-finite cells the strings
// "nan", "-nan", "inf", "-inf". Every row has every column; an empty cell is null. Strings are
// valid UTF-8 (invalid bytes → U+FFFD) with control characters escaped. A provenance key given
// twice keeps its first value, as CsvTable::value does.
std::string to_json(const CsvTable& table);

// The formats `run`, `order` and `sweep` write their tables in (--format).
enum class TableFormat { kCsv, kJson };

// "csv" or "json"; anything else is an InputError naming `option`, the value and the allowed
// values.
TableFormat parse_table_format(const std::string& text, const std::string& option);

// Markdown pipe table; numbers are shortened to `digits` significant digits for reading.
std::string to_markdown(const std::vector<Row>& rows, const std::vector<std::string>& columns,
                        int digits = 3);

// Writes `text` to `path` via a temporary file in the same directory and rename(2).
// Creates the parent directory. Throws std::runtime_error on I/O failure.
void write_file_atomic(const std::string& path, const std::string& text);

// Streams text to `path` through a temporary file in the same folder (parent folders created),
// renamed onto `path` by commit(). Destroyed without commit — an exception, a failed run that
// is abandoned — it removes the temporary file, so no partial file is ever left under `path`.
// Throws std::runtime_error on I/O failure.
class AtomicFileWriter {
 public:
  explicit AtomicFileWriter(const std::string& path);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;
  std::ostream& stream() { return out_; }
  void commit();

 private:
  std::string path_, temporary_;
  std::ofstream out_;
  bool committed_ = false;
  int slot_ = -1;  // in the registry of live temporaries (remove_temporaries_on_signals)
};

// Installs handlers of SIGTERM (what Slurm sends at a time limit) and SIGINT that remove the
// temporary files of this process's unfinished AtomicFileWriters, then end the process by the
// signal's default action. Signals the process ignores stay ignored. Called by `geomint` at start;
// a library user decides for their own program.
void remove_temporaries_on_signals();

// 16 hex digits naming this machine and PID namespace (host name, boot id, the namespace of
// /proc/self/ns/pid): an AtomicFileWriter's temporary is `<name>.<pid>.<n>.h<tag>.tmp`, so a
// PID is only ever looked up where it was issued.
std::string temporary_host_tag();

// How old (last written) a temporary of another machine or PID namespace, or one without a tag,
// must be before remove_stale_temporaries takes it for debris: a live writer of another node
// writes its file far more often than this (docs/CLUSTER.md "Shared file systems").
inline constexpr std::chrono::hours kForeignTemporaryAge{24};

// Removes the temporaries `<name>.<pid>.<n>.h<tag>.tmp` in `folder` that an AtomicFileWriter left
// when its process was killed (kill -9, a lost node): `name` must satisfy is_output, and either
// the tag is this machine's and namespace's and the pid is neither this process nor a live one,
// or the tag is another's (or absent) and the file was last written kForeignTemporaryAge ago or
// more. Returns how many were removed.
size_t remove_stale_temporaries(const std::string& folder,
                                const std::function<bool(const std::string&)>& is_output);

// The column order every geomint CSV uses.
const std::vector<std::string>& standard_columns();

}  // namespace geomint
