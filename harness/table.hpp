// Result rows and their writers: CSV with `# key: value` provenance lines (docs/DESIGN.md §5),
// written to a temporary file and renamed so a crash never leaves a half-written table, and
// Markdown tables for results/<scene>/table.md.
#pragma once

#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace geomint {

// One output row: column name → formatted value. Absent columns are left empty in a CSV.
using Row = std::map<std::string, std::string>;

// Provenance lines: version, git SHA, compiler and flags, library versions, CPU, date, command.
std::vector<std::pair<std::string, std::string>> provenance(const std::string& command_line);

// Columns present in any row, ordered by `preferred` first, then alphabetically.
std::vector<std::string> column_union(const std::vector<Row>& rows,
                                      const std::vector<std::string>& preferred);

// CSV text (header + rows); values containing ',' or '"' are quoted.
std::string to_csv(const std::vector<Row>& rows, const std::vector<std::string>& columns,
                   const std::vector<std::pair<std::string, std::string>>& provenance_lines);

// Parses CSV text as written by to_csv: `#` provenance lines are skipped, the first other line
// is the header, quoted fields may contain ',' and '""'. Empty fields are left out of the row.
// Throws std::runtime_error naming the line when a row has more fields than the header.
std::vector<Row> parse_csv(const std::string& text);

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
};

// The column order every geomint CSV uses.
const std::vector<std::string>& standard_columns();

}  // namespace geomint
