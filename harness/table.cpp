// CSV/Markdown writers and run provenance (see table.hpp).
#include "harness/table.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <gsl/gsl_version.h>
#include <signal.h>
#include <sundials/sundials_config.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <boost/version.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "harness/blas.hpp"
#include "harness/metrics.hpp"
#include "harness/text_escape.hpp"
#include "problems/parallel.hpp"
#include "problems/spec.hpp"

namespace geomint {

// harness/build_info.cpp, generated at build time by scripts/build_info.cmake.
const char* build_version();
const char* build_git_sha();
const char* build_compiler();
const char* build_flags();

namespace {

std::string cpu_model() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(colon + 2);
    }
  }
  return "unknown";
}

std::string csv_escape(const std::string& value) {
  if (value.find_first_of(",\"\n") == std::string::npos) return value;
  std::string out = "\"";
  for (char c : value) {
    if (c == '"') out += '"';
    out += c == '\n' ? ' ' : c;
  }
  return out + "\"";
}

std::string shorten_number(const std::string& text, int digits) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) return text;
  if (value == std::floor(value) && std::abs(value) < 1e9) return text;
  return fmt::format("{:.{}g}", value, digits);
}

}  // namespace

std::vector<std::pair<std::string, std::string>> provenance(const std::string& command_line) {
  const auto now = std::chrono::system_clock::now();
  std::vector<std::pair<std::string, std::string>> lines = {
      {"geomint", fmt::format("{} ({})", build_version(), build_git_sha())},
      {"compiler", build_compiler()},
      {"flags", build_flags()},
      {"libraries",
       fmt::format("Eigen {}.{}.{}, GSL {}, SUNDIALS {}, Boost {}.{}, fmt {}", EIGEN_WORLD_VERSION,
                   EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION, GSL_VERSION, SUNDIALS_VERSION,
                   BOOST_VERSION / 100000, BOOST_VERSION / 100 % 1000, FMT_VERSION)},
      {"cpu", cpu_model()},
      // Threads of the element loops; results do not depend on it (docs/PERF.md "Threads").
      {"threads", thread_count_description()},
      {"date", fmt::format("{:%Y-%m-%dT%H:%M:%SZ}",
                           fmt::gmtime(std::chrono::system_clock::to_time_t(now)))},
      {"command", command_line},
  };
  add_blas_provenance(lines);
  return lines;
}

const char* column_type_name(ColumnType type) {
  switch (type) {
    case ColumnType::kInteger:
      return "integer";
    case ColumnType::kReal:
      return "real";
    case ColumnType::kText:
      break;
  }
  return "text";
}

std::string real_cell(double value, int decimals) {
  return decimals < 0 ? format_number(value) : fmt::format("{:.{}f}", value, decimals);
}

std::string integer_cell(long value) { return std::to_string(value); }

std::vector<std::string> ResultTable::column_names() const {
  std::vector<std::string> names;
  names.reserve(columns.size());
  for (const auto& column : columns) names.push_back(column.name);
  return names;
}

const TableColumn* ResultTable::column(const std::string& name) const {
  for (const auto& column : columns) {
    if (column.name == name) return &column;
  }
  return nullptr;
}

std::string ResultTable::value(const std::string& key, const std::string& absent) const {
  for (const auto& [name, text] : provenance) {
    if (name == key) return text;
  }
  return absent;
}

std::optional<double> ResultTable::number(size_t row, const std::string& column) const {
  const auto cell = rows.at(row).find(column);
  if (cell == rows.at(row).end() || cell->second.empty()) return std::nullopt;
  // strtod reads the shortest round-trip text back as the same double, and nan/inf as such.
  char* end = nullptr;
  const double value = std::strtod(cell->second.c_str(), &end);
  if (end != cell->second.c_str() + cell->second.size()) return std::nullopt;
  return value;
}

std::string to_csv(const ResultTable& table) {
  return to_csv(table.rows, table.column_names(), table.provenance);
}

const std::vector<std::string>& standard_columns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> out = {"label", "problem", "method",  "family",    "dt",   "tol",
                                    "t_end", "status",  "message", "t_reached", "steps"};
    const auto& metrics = metric_names();
    out.insert(out.end(), metrics.begin(), metrics.end());
    for (const char* name :
         {"order", "declared_order", "points_used", "force_evals", "energy_evals", "hessian_evals",
          "newton_iters", "linear_solves", "factorizations", "rejected", "wall_s", "wall_s_min",
          "wall_s_iqr", "wall_s_repeats", "recursive_passes_per_step"}) {
      out.emplace_back(name);
    }
    return out;
  }();
  return columns;
}

std::vector<std::string> column_union(const std::vector<Row>& rows,
                                      const std::vector<std::string>& preferred) {
  std::set<std::string> present;
  for (const auto& row : rows) {
    for (const auto& [key, value] : row) present.insert(key);
  }
  std::vector<std::string> columns;
  for (const auto& name : preferred) {
    if (present.erase(name)) columns.push_back(name);
  }
  columns.insert(columns.end(), present.begin(), present.end());
  return columns;
}

namespace {

// "'<source>' line <n>: " (or "CSV line <n>: " for text of no named file).
std::string csv_where(const std::string& source, size_t line_number) {
  return source.empty() ? fmt::format("CSV line {}: ", line_number)
                        : fmt::format("'{}' line {}: ", source, line_number);
}

// Splits one record as to_csv writes it: a field is either unquoted (no '"') or quoted from
// its first to its last character ("" is a literal quote). to_csv never lets a quoted field span
// lines, so a quote still open at the end of the line is damage, as is text after a closing
// quote. Returns the fields, or the reason the line is malformed in `error`.
std::vector<std::string> split_csv_line(const std::string& line, std::string& error) {
  std::vector<std::string> fields(1);
  size_t i = 0;
  while (true) {
    if (i < line.size() && line[i] == '"') {
      const size_t open = i++;
      while (true) {
        if (i >= line.size()) {
          error = fmt::format("the quote opened at column {} is not closed", open + 1);
          return fields;
        }
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') {
            fields.back() += '"';
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        fields.back() += line[i++];
      }
      if (i < line.size() && line[i] != ',') {
        error = fmt::format("text after the closing quote at column {}", i);
        return fields;
      }
    } else {
      while (i < line.size() && line[i] != ',') {
        if (line[i] == '"') {
          error = fmt::format("a quote inside an unquoted field at column {}", i + 1);
          return fields;
        }
        fields.back() += line[i++];
      }
    }
    if (i >= line.size()) return fields;
    ++i;  // the ','
    fields.emplace_back();
  }
}

}  // namespace

std::string CsvTable::value(const std::string& key, const std::string& absent) const {
  for (const auto& [name, text] : provenance) {
    if (name == key) return text;
  }
  return absent;
}

CsvTable parse_csv_table(const std::string& text, const std::string& source) {
  CsvTable table;
  table.path = source;
  // Every writer ends every line with '\n': a last line without one is a table cut short (a
  // number cut inside reads as another number, so it must not be parsed at all).
  if (!text.empty() && text.back() != '\n') {
    const size_t lines = static_cast<size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
    throw InputError(csv_where(source, lines) +
                     "the last line has no terminating newline (the table is cut short)");
  }
  bool header_seen = false;
  size_t line_number = 0;
  for (size_t start = 0; start < text.size();) {
    const size_t end = text.find('\n', start);
    std::string line = text.substr(start, end - start);
    start = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty() && line[0] == '#') {
      if (!header_seen && line.rfind("# ", 0) == 0) {
        const auto colon = line.find(": ");
        if (colon != std::string::npos && colon >= 2) {
          table.provenance.emplace_back(line.substr(2, colon - 2), line.substr(colon + 2));
        }
      }
      continue;
    }
    if (line.empty()) continue;
    std::string error;
    auto fields = split_csv_line(line, error);
    if (!error.empty()) throw InputError(csv_where(source, line_number) + error);
    if (!header_seen) {
      table.columns = std::move(fields);
      header_seen = true;
      continue;
    }
    if (fields.size() != table.columns.size()) {
      throw InputError(csv_where(source, line_number) +
                       fmt::format("{} fields, the header has {} (a damaged or truncated table)",
                                   fields.size(), table.columns.size()));
    }
    Row row;
    for (size_t i = 0; i < fields.size(); ++i) {
      if (!fields[i].empty()) row[table.columns[i]] = std::move(fields[i]);
    }
    table.rows.push_back(std::move(row));
  }
  if (!header_seen) {
    throw InputError((source.empty() ? std::string("CSV text") : fmt::format("'{}'", source)) +
                     " has no header line (an empty or truncated table)");
  }
  return table;
}

std::vector<Row> parse_csv(const std::string& text, const std::string& source) {
  return parse_csv_table(text, source).rows;
}

CsvTable read_csv_file(const std::string& path) {
  if (std::filesystem::is_directory(path)) {
    throw InputError(fmt::format("'{}' is a folder, not a CSV table", path));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot read '{}'", path));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(fmt::format("cannot read '{}'", path));
  return parse_csv_table(text, path);
}

std::string provenance_line(const std::string& key, const std::string& value) {
  const auto one_line = [](std::string text) {
    std::replace_if(
        text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
    return text;
  };
  return fmt::format("# {}: {}\n", one_line(key), one_line(value));
}

std::string to_csv(const std::vector<Row>& rows, const std::vector<std::string>& columns,
                   const std::vector<std::pair<std::string, std::string>>& provenance_lines) {
  std::string out;
  for (const auto& [key, value] : provenance_lines) out += provenance_line(key, value);
  out += fmt::format("{}\n", fmt::join(columns, ","));
  for (const auto& row : rows) {
    std::string line;
    for (size_t i = 0; i < columns.size(); ++i) {
      if (i) line += ',';
      auto it = row.find(columns[i]);
      if (it != row.end()) line += csv_escape(it->second);
    }
    out += line + "\n";
  }
  return out;
}

namespace {

// RFC 8259's number grammar: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
bool is_json_number(const std::string& text) {
  const auto digit = [&](size_t at) {
    return at < text.size() && text[at] >= '0' && text[at] <= '9';
  };
  size_t at = 0;
  if (at < text.size() && text[at] == '-') ++at;
  if (!digit(at)) return false;
  if (text[at] == '0') {
    ++at;
  } else {
    while (digit(at)) ++at;
  }
  if (at < text.size() && text[at] == '.') {
    if (!digit(++at)) return false;
    while (digit(at)) ++at;
  }
  if (at < text.size() && (text[at] == 'e' || text[at] == 'E')) {
    ++at;
    if (at < text.size() && (text[at] == '+' || text[at] == '-')) ++at;
    if (!digit(at)) return false;
    while (digit(at)) ++at;
  }
  return at == text.size();
}

// How the CSV writers spell a non-finite double (std::to_chars, fmt); JSON has no literal for it.
bool is_non_finite_word(const std::string& text) {
  return text == "nan" || text == "-nan" || text == "inf" || text == "-inf";
}

std::string json_string(const std::string& text) { return "\"" + json_escaped(text) + "\""; }

}  // namespace

std::string to_json(const CsvTable& table) {
  // A number column: a finite number somewhere and nothing but numbers and non-finite words
  // (a status "nan" alone is text).
  std::vector<bool> numeric(table.columns.size(), false);
  for (size_t i = 0; i < table.columns.size(); ++i) {
    bool finite_seen = false, other_seen = false;
    for (const auto& row : table.rows) {
      const auto cell = row.find(table.columns[i]);
      if (cell == row.end()) continue;
      finite_seen = finite_seen || is_json_number(cell->second);
      other_seen =
          other_seen || (!is_json_number(cell->second) && !is_non_finite_word(cell->second));
    }
    numeric[i] = finite_seen && !other_seen;
  }
  std::string out = "{\n  \"provenance\": {";
  std::set<std::string> keys;
  for (const auto& [key, value] : table.provenance) {
    if (!keys.insert(key).second) continue;  // the first value wins, as in CsvTable::value
    out += fmt::format("{}\n    {}: {}", keys.size() > 1 ? "," : "", json_string(key),
                       json_string(value));
  }
  out += keys.empty() ? "},\n" : "\n  },\n";
  out += "  \"columns\": [";
  for (size_t i = 0; i < table.columns.size(); ++i) {
    out += (i ? ", " : "") + json_string(table.columns[i]);
  }
  out += "],\n  \"types\": {";
  for (size_t i = 0; i < table.columns.size(); ++i) {
    out += fmt::format("{}{}: \"{}\"", i ? ", " : "", json_string(table.columns[i]),
                       numeric[i] ? "number" : "string");
  }
  out += "},\n  \"rows\": [";
  for (size_t r = 0; r < table.rows.size(); ++r) {
    const Row& row = table.rows[r];
    out += r ? ",\n    {" : "\n    {";
    for (size_t i = 0; i < table.columns.size(); ++i) {
      const auto cell = row.find(table.columns[i]);
      std::string value = "null";
      if (cell != row.end()) {
        value =
            numeric[i] && is_json_number(cell->second) ? cell->second : json_string(cell->second);
      }
      out += fmt::format("{}{}: {}", i ? ", " : "", json_string(table.columns[i]), value);
    }
    out += "}";
  }
  out += table.rows.empty() ? "]\n}\n" : "\n  ]\n}\n";
  return out;
}

TableFormat parse_table_format(const std::string& text, const std::string& option) {
  if (text == "csv") return TableFormat::kCsv;
  if (text == "json") return TableFormat::kJson;
  throw InputError(
      fmt::format("{}: '{}' is not a table format (allowed: csv, json)", option, text));
}

std::string to_markdown(const std::vector<Row>& rows, const std::vector<std::string>& columns,
                        int digits) {
  std::string out = "| " + fmt::format("{}", fmt::join(columns, " | ")) + " |\n|";
  for (size_t i = 0; i < columns.size(); ++i) out += "---|";
  out += "\n";
  for (const auto& row : rows) {
    out += "|";
    for (const auto& column : columns) {
      auto it = row.find(column);
      std::string cell = it == row.end() ? "" : shorten_number(it->second, digits);
      for (auto& c : cell) {
        if (c == '|') c = '/';
      }
      out += " " + cell + " |";
    }
    out += "\n";
  }
  return out;
}

namespace {

// <path>.<pid>.<n>.h<tag>.tmp: unique per process and per writer, so parallel writers never share
// one; the tag names the machine and PID namespace whose <pid> it is (temporary_host_tag).
std::string temporary_name(const std::string& path) {
  static std::atomic<unsigned long> counter{0};
  return fmt::format("{}.{}.{}.h{}.tmp", path, ::getpid(), counter++, temporary_host_tag());
}

std::string first_line_of(const char* path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

// The temporaries this process has open, for the SIGTERM/SIGINT handler. A signal handler may
// call only async-signal-safe functions, so the registry is a fixed array of fixed buffers whose
// slots are claimed with lock-free atomics: no allocation, no lock a handler could wait on. A
// path that does not fit, or a writer beyond the last slot, is simply not registered (a rerun
// removes what it leaves, remove_stale_temporaries).
struct TemporarySlot {
  std::atomic<int> state{0};  // kFree, kFilling (being written or cleared), kLive
  char path[4096];
};
constexpr int kFree = 0, kFilling = 1, kLive = 2;
constexpr size_t kTemporarySlots = 256;
TemporarySlot g_temporaries[kTemporarySlots];

int register_temporary(const std::string& path) {
  if (path.size() >= sizeof(TemporarySlot::path)) return -1;
  for (size_t i = 0; i < kTemporarySlots; ++i) {
    int expected = kFree;
    if (g_temporaries[i].state.compare_exchange_strong(expected, kFilling)) {
      std::memcpy(g_temporaries[i].path, path.c_str(), path.size() + 1);
      g_temporaries[i].state.store(kLive);
      return static_cast<int>(i);
    }
  }
  return -1;
}

void unregister_temporary(int slot) {
  if (slot < 0) return;
  g_temporaries[slot].state.store(kFilling);
  g_temporaries[slot].path[0] = '\0';
  g_temporaries[slot].state.store(kFree);
}

extern "C" void remove_temporaries_and_reraise(int signal_number) {
  const int saved_errno = errno;
  for (auto& slot : g_temporaries) {
    if (slot.state.load() == kLive) ::unlink(slot.path);
  }
  // The default action then ends the process as the signal would have: a shell, Slurm or a
  // parent sees "killed by SIGTERM", not an exit code.
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  ::sigaction(signal_number, &default_action, nullptr);
  ::raise(signal_number);
  errno = saved_errno;
}

// A temporary of an output as read back from its name: "<name>.<pid>.<n>.h<tag>.tmp", or the
// untagged "<name>.<pid>.<n>.tmp" of earlier geomint versions (tag empty).
struct TemporaryName {
  std::string name, tag;
  long pid = -1;  // -1: not a temporary's name
};

TemporaryName parse_temporary_name(const std::string& file) {
  const std::string suffix = ".tmp";
  if (file.size() <= suffix.size() ||
      file.compare(file.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return {};
  }
  std::string rest = file.substr(0, file.size() - suffix.size());
  // Fields from the end: [h<tag>,] <n>, <pid>; what precedes them is the output's name.
  const auto take_last = [&rest]() -> std::string {
    const auto dot = rest.rfind('.');
    if (dot == std::string::npos || dot == 0) return "";
    std::string field = rest.substr(dot + 1);
    rest.resize(dot);
    return field;
  };
  const auto digits = [](const std::string& text) {
    return !text.empty() && text.size() <= 18 &&
           std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  TemporaryName parsed;
  std::string field = take_last();
  if (field.size() == 17 && field[0] == 'h' &&
      std::all_of(field.begin() + 1, field.end(),
                  [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); })) {
    parsed.tag = field.substr(1);
    field = take_last();
  }
  const std::string pid = take_last();
  if (!digits(field) || !digits(pid) || rest.empty()) return {};
  parsed.name = rest;
  parsed.pid = std::stol(pid);
  return parsed;
}

}  // namespace

void remove_temporaries_on_signals() {
  for (const int signal_number : {SIGTERM, SIGINT}) {
    struct sigaction previous {};
    ::sigaction(signal_number, nullptr, &previous);
    // A signal the caller ignores (nohup, a background job's SIGINT) stays ignored.
    if (previous.sa_handler == SIG_IGN) continue;
    struct sigaction action {};
    action.sa_handler = remove_temporaries_and_reraise;
    sigemptyset(&action.sa_mask);
    ::sigaction(signal_number, &action, nullptr);
  }
}

std::string temporary_host_tag() {
  static const std::string tag = [] {
    char host[256] = {};
    if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
    // The PID namespace's identity ("pid:[4026531836]"): two containers, or `unshare --pid`, on
    // one host and boot number their processes independently.
    char name_space[256] = {};
    const ssize_t length = ::readlink("/proc/self/ns/pid", name_space, sizeof name_space - 1);
    if (length < 0) name_space[0] = '\0';
    const std::string identity = fmt::format(
        "{}\n{}\n{}", host, first_line_of("/proc/sys/kernel/random/boot_id"), name_space);
    std::uint64_t hash = 14695981039346656037ull;  // FNV-1a 64
    for (unsigned char c : identity) {
      hash ^= c;
      hash *= 1099511628211ull;
    }
    return fmt::format("{:016x}", hash);
  }();
  return tag;
}

size_t remove_stale_temporaries(const std::string& folder,
                                const std::function<bool(const std::string&)>& is_output) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(folder, error)) return 0;
  size_t removed = 0;
  const long self = ::getpid();
  const std::string here = temporary_host_tag();
  const auto now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    const TemporaryName temporary = parse_temporary_name(it->path().filename().string());
    if (temporary.pid < 0 || !is_output(temporary.name)) continue;
    if (temporary.tag == here) {
      // A writer of this machine and PID namespace: kept while it is alive; a dead one (kill -9,
      // an out-of-memory kill) left debris.
      if (temporary.pid == self) continue;
      if (temporary.pid <= std::numeric_limits<pid_t>::max() &&
          (::kill(static_cast<pid_t>(temporary.pid), 0) == 0 || errno == EPERM)) {
        continue;
      }
    } else {
      // Another node of a shared file system, another container, or a geomint whose temporaries
      // carried no tag: its PID says nothing here. Only age tells it is gone (a lost node).
      std::error_code time_error;
      const auto written = fs::last_write_time(it->path(), time_error);
      if (time_error || now - written < kForeignTemporaryAge) continue;
    }
    std::error_code ignored;
    removed += fs::remove(it->path(), ignored);
  }
  return removed;
}

AtomicFileWriter::AtomicFileWriter(const std::string& path) : path_(path) {
  const std::filesystem::path target(path);
  if (target.has_parent_path()) std::filesystem::create_directories(target.parent_path());
  temporary_ = temporary_name(path);
  // Registered before the file exists, so a signal between open and registration cannot
  // leave it behind.
  slot_ = register_temporary(temporary_);
  out_.open(temporary_, std::ios::binary | std::ios::trunc);
  if (!out_) {
    unregister_temporary(slot_);
    throw std::runtime_error(fmt::format("cannot write '{}'", temporary_));
  }
}

AtomicFileWriter::~AtomicFileWriter() {
  if (committed_) return;
  out_.close();
  std::remove(temporary_.c_str());
  unregister_temporary(slot_);
}

void AtomicFileWriter::commit() {
  out_.flush();
  const bool written = static_cast<bool>(out_);
  out_.close();
  committed_ = true;
  if (!written || out_.fail()) {
    std::remove(temporary_.c_str());
    unregister_temporary(slot_);
    throw std::runtime_error(fmt::format("cannot write '{}'", path_));
  }
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    std::remove(temporary_.c_str());
    unregister_temporary(slot_);
    throw std::runtime_error(fmt::format("cannot rename '{}' to '{}'", temporary_, path_));
  }
  unregister_temporary(slot_);
}

void write_file_atomic(const std::string& path, const std::string& text) {
  AtomicFileWriter writer(path);
  writer.stream() << text;
  writer.commit();
}

}  // namespace geomint
