// CSV/Markdown writers and run provenance (see table.hpp).
#include "harness/table.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <gsl/gsl_version.h>
#include <sundials/sundials_config.h>
#include <unistd.h>

#include <Eigen/Core>
#include <atomic>
#include <boost/version.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "harness/blas.hpp"
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
      {"date", fmt::format("{:%Y-%m-%dT%H:%M:%SZ}",
                           fmt::gmtime(std::chrono::system_clock::to_time_t(now)))},
      {"command", command_line},
  };
  add_blas_provenance(lines);
  return lines;
}

const std::vector<std::string>& standard_columns() {
  static const std::vector<std::string> columns = {"label",
                                                   "problem",
                                                   "method",
                                                   "dt",
                                                   "tol",
                                                   "t_end",
                                                   "status",
                                                   "message",
                                                   "t_reached",
                                                   "steps",
                                                   "energy_err_max",
                                                   "energy_err_final",
                                                   "energy_drift",
                                                   "energy_growth_exponent",
                                                   "momentum_err_max",
                                                   "angular_momentum_err_max",
                                                   "casimir_err_max",
                                                   "constraint_err_max",
                                                   "constraint_vel_err_max",
                                                   "symplecticity_defect",
                                                   "mode_freq_err_max",
                                                   "mode_damping_max",
                                                   "error_final",
                                                   "error_max",
                                                   "scd",
                                                   "phase_err",
                                                   "period_err",
                                                   "period_measured",
                                                   "period_err_rel",
                                                   "perihelion_err",
                                                   "order",
                                                   "declared_order",
                                                   "points_used",
                                                   "force_evals",
                                                   "energy_evals",
                                                   "hessian_evals",
                                                   "newton_iters",
                                                   "linear_solves",
                                                   "factorizations",
                                                   "rejected",
                                                   "wall_s"};
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

std::vector<Row> parse_csv(const std::string& text) {
  // Splits one record; a quoted field runs to the next unpaired quote ("" is a literal quote).
  auto split = [](const std::string& line) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = !quoted;
      } else if (c == ',' && !quoted) {
        fields.emplace_back();
      } else {
        fields.back() += c;
      }
    }
    return fields;
  };
  std::vector<Row> rows;
  std::vector<std::string> header;
  std::istringstream in(text);
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const auto fields = split(line);
    if (header.empty()) {
      header = fields;
      continue;
    }
    if (fields.size() > header.size()) {
      throw std::runtime_error("CSV line " + std::to_string(line_number) + " has " +
                               std::to_string(fields.size()) + " fields, the header " +
                               std::to_string(header.size()));
    }
    Row row;
    for (size_t i = 0; i < fields.size(); ++i) {
      if (!fields[i].empty()) row[header[i]] = fields[i];
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string to_csv(const std::vector<Row>& rows, const std::vector<std::string>& columns,
                   const std::vector<std::pair<std::string, std::string>>& provenance_lines) {
  std::string out;
  for (const auto& [key, value] : provenance_lines) out += fmt::format("# {}: {}\n", key, value);
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

// <path>.<pid>.<n>.tmp: unique per process and per writer, so parallel writers never share one.
std::string temporary_name(const std::string& path) {
  static std::atomic<unsigned long> counter{0};
  return fmt::format("{}.{}.{}.tmp", path, ::getpid(), counter++);
}

}  // namespace

AtomicFileWriter::AtomicFileWriter(const std::string& path) : path_(path) {
  const std::filesystem::path target(path);
  if (target.has_parent_path()) std::filesystem::create_directories(target.parent_path());
  temporary_ = temporary_name(path);
  out_.open(temporary_, std::ios::binary | std::ios::trunc);
  if (!out_) throw std::runtime_error(fmt::format("cannot write '{}'", temporary_));
}

AtomicFileWriter::~AtomicFileWriter() {
  if (committed_) return;
  out_.close();
  std::remove(temporary_.c_str());
}

void AtomicFileWriter::commit() {
  out_.flush();
  const bool written = static_cast<bool>(out_);
  out_.close();
  if (!written || out_.fail()) {
    std::remove(temporary_.c_str());
    committed_ = true;
    throw std::runtime_error(fmt::format("cannot write '{}'", path_));
  }
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    std::remove(temporary_.c_str());
    committed_ = true;
    throw std::runtime_error(fmt::format("cannot rename '{}' to '{}'", temporary_, path_));
  }
  committed_ = true;
}

void write_file_atomic(const std::string& path, const std::string& text) {
  AtomicFileWriter writer(path);
  writer.stream() << text;
  writer.commit();
}

}  // namespace geomint
