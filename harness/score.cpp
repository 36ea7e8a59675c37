// Reading and scoring trajectories written by other programs (see score.hpp): a CSV or .npy
// reader that validates the whole file, then the observers of `geomint run` over its rows.
#include "harness/score.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "harness/metrics.hpp"
#include "harness/observers.hpp"
#include "harness/reference.hpp"
#include "harness/run_spec.hpp"
#include "problems/lagrangian.hpp"
#include "problems/mass_operator.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace {

// A file's numbers as rows of t, q and (p or v) columns, before the checks against the problem.
struct Table {
  std::vector<std::vector<double>> rows;  // each: t, q[0..n), then p or v (first order: y only)
  bool velocities = false;
  std::vector<std::string> where;  // per row: "line 7" (CSV) or "row 3" (.npy), for messages
  std::vector<std::string> names;  // column names of the row layout, for messages
};

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw InputError(fmt::format("score: {}: {}", path, what));
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot be read (no such file, or no permission)");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The layout's column names: t, q0.., then p0.. or v0.. (y0.. for a first-order problem).
std::vector<std::string> layout_names(const Problem& problem, bool velocities) {
  const int n = problem.dof();
  const bool first_order = problem.has(kFirstOrderOnly);
  std::vector<std::string> names = {"t"};
  for (int i = 0; i < n; ++i) names.push_back(fmt::format("{}{}", first_order ? "y" : "q", i));
  if (!first_order) {
    for (int i = 0; i < n; ++i) names.push_back(fmt::format("{}{}", velocities ? "v" : "p", i));
  }
  return names;
}

// The header for `problem`, spelled out up to 3 degrees of freedom ("t,q0,q1,p0,p1").
std::string expected_header(const Problem& problem) {
  const int n = problem.dof();
  const auto range = [n](const char* letter) {
    if (n <= 3) {
      std::vector<std::string> names;
      for (int i = 0; i < n; ++i) names.push_back(fmt::format("{}{}", letter, i));
      return fmt::format("{}", fmt::join(names, ","));
    }
    return fmt::format("{0}0,{0}1,...,{0}{1}", letter, n - 1);
  };
  if (problem.has(kFirstOrderOnly)) return fmt::format("t,{}", range("y"));
  return fmt::format("t,{0},{1} or t,{0},{2}", range("q"), range("p"), range("v"));
}

std::string trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return std::string(text.substr(first, last - first + 1));
}

std::vector<std::string> split_fields(std::string_view line) {
  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    fields.push_back(
        trim(line.substr(start, comma == std::string_view::npos ? comma : comma - start)));
    if (comma == std::string_view::npos) return fields;
    start = comma + 1;
  }
}

std::optional<double> parse_number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return std::nullopt;
  return value;  // ±inf, nan and overflow are refused by the finiteness check
}

// The column index of `name` as geomint writes it (q3, q_3); -1 when absent.
int column_of(const std::map<std::string, int>& columns, const std::string& letter, int i) {
  for (const std::string& name :
       {fmt::format("{}{}", letter, i), fmt::format("{}_{}", letter, i)}) {
    if (auto it = columns.find(name); it != columns.end()) return it->second;
  }
  return -1;
}

Table read_csv(const std::string& path, const std::string& text, const Problem& problem) {
  if (text.empty()) fail(path, "the file is empty (expected a header line, then data rows)");
  if (text.back() != '\n') {
    fail(path, "the last line has no terminating newline: the file was cut short");
  }
  std::vector<std::string_view> lines;
  for (size_t start = 0; start < text.size();) {
    // The text ends in '\n' (checked above), so every line has its end.
    const size_t end = std::min(text.find('\n', start), text.size());
    std::string_view line(text.data() + start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    start = end + 1;
  }
  size_t at = 0;
  std::string series_problem;  // the `# problem:` line of a series `geomint run` wrote
  for (; at < lines.size() && !lines[at].empty() && lines[at][0] == '#'; ++at) {
    constexpr std::string_view kProblemLine = "# problem: ";
    if (lines[at].substr(0, kProblemLine.size()) == kProblemLine) {
      series_problem = std::string(lines[at].substr(kProblemLine.size()));
    }
  }
  if (at == lines.size()) fail(path, "no header line (only comment lines)");
  const std::vector<std::string> header = split_fields(lines[at]);
  if (parse_number(header[0])) {
    fail(path, fmt::format("line {}: no header: the first line is numbers; expected the column "
                           "names {}",
                           at + 1, expected_header(problem)));
  }
  if (!series_problem.empty() && series_problem != problem.spec()) {
    fail(path, fmt::format("the series was written for the problem '{}', not '{}'", series_problem,
                           problem.spec()));
  }
  std::map<std::string, int> columns;
  for (int c = 0; c < static_cast<int>(header.size()); ++c) {
    if (!columns.emplace(header[c], c).second) {
      fail(path, fmt::format("line {}: column '{}' appears twice", at + 1, header[c]));
    }
  }
  const int n = problem.dof();
  const bool first_order = problem.has(kFirstOrderOnly);
  Table table;
  // Which columns hold t, q and p (or v), in layout order.
  std::vector<int> source;
  const auto require = [&](const std::string& letter, int i) {
    const int c = column_of(columns, letter, i);
    if (c < 0) {
      fail(path, fmt::format("line {}: no column {}{} (problem '{}' has {} degrees of freedom: "
                             "the header is {})",
                             at + 1, letter, i, problem.spec(), n, expected_header(problem)));
    }
    source.push_back(c);
  };
  if (columns.count("t") == 0) {
    fail(path,
         fmt::format("line {}: no column t (the header is {})", at + 1, expected_header(problem)));
  }
  source.push_back(columns.at("t"));
  for (int i = 0; i < n; ++i) require(first_order ? "y" : "q", i);
  if (!first_order) {
    const bool has_p = column_of(columns, "p", 0) >= 0;
    const bool has_v = column_of(columns, "v", 0) >= 0;
    if (has_p && has_v) fail(path, "both p and v columns: give momenta or velocities, not both");
    table.velocities = has_v;
    for (int i = 0; i < n; ++i) require(has_v ? "v" : "p", i);
  }
  // A plain file has exactly the layout's columns; a series of `geomint run` (with its `# problem:`
  // line) carries energy, invariants and residuals too, which are recomputed, not read.
  if (series_problem.empty() && header.size() != source.size()) {
    for (const std::string& name : header) {
      if (std::find_if(source.begin(), source.end(), [&](int c) { return header[c] == name; }) ==
          source.end()) {
        fail(path, fmt::format("line {}: unexpected column '{}' (problem '{}': the header is {})",
                               at + 1, name, problem.spec(), expected_header(problem)));
      }
    }
  }
  table.names = layout_names(problem, table.velocities);
  for (size_t l = at + 1; l < lines.size(); ++l) {
    const std::vector<std::string> fields = split_fields(lines[l]);
    if (fields.size() != header.size()) {
      fail(path, fmt::format("line {}: {} fields, the header has {} (a short or cut row)", l + 1,
                             fields.size(), header.size()));
    }
    std::vector<double> row;
    for (size_t k = 0; k < source.size(); ++k) {
      const std::string& field = fields[source[k]];
      const std::optional<double> value = parse_number(field);
      if (!value) {
        fail(path, fmt::format("line {}, column {}: '{}' is not a number", l + 1, header[source[k]],
                               field));
      }
      row.push_back(*value);
    }
    table.rows.push_back(std::move(row));
    table.where.push_back(fmt::format("line {}", l + 1));
  }
  return table;
}

// The NumPy format (numpy.lib.format, versions 1.0 and 2.0): magic "\x93NUMPY", major and minor
// version bytes, the header length (2 bytes little-endian in 1.0, 4 in 2.0), then an ASCII
// Python dict literal with exactly the keys descr, fortran_order and shape, padded with spaces and
// ended by '\n'; then the data.
Table read_npy(const std::string& path, const std::string& bytes, const Problem& problem,
               bool velocities) {
  constexpr std::string_view kMagic("\x93NUMPY", 6);
  if (bytes.size() < 10 || std::string_view(bytes).substr(0, 6) != kMagic) {
    fail(path, "not a .npy file (no \\x93NUMPY magic at its start)");
  }
  const auto byte = [&](size_t i) { return static_cast<uint8_t>(bytes[i]); };
  const int major = byte(6);
  if (major != 1 && major != 2) {
    fail(path,
         fmt::format(".npy format version {}.{} (versions 1.0 and 2.0 are read)", major, byte(7)));
  }
  size_t header_length = 0, data_start = 0;
  if (major == 1) {
    header_length = byte(8) | (byte(9) << 8);
    data_start = 10 + header_length;
  } else {
    if (bytes.size() < 12) fail(path, ".npy header cut short");
    header_length = byte(8) | (byte(9) << 8) | (byte(10) << 16) | (size_t{byte(11)} << 24);
    data_start = 12 + header_length;
  }
  if (data_start > bytes.size()) fail(path, ".npy header cut short");
  const std::string header = bytes.substr(data_start - header_length, header_length);
  if (header.empty() || header.back() != '\n') fail(path, ".npy header does not end with '\\n'");
  // The dict: {'descr': '<f8', 'fortran_order': False, 'shape': (N, M), }, keys in any order.
  std::string dict = trim(header.substr(0, header.size() - 1));
  if (dict.size() < 2 || dict.front() != '{' || dict.back() != '}') {
    fail(path, fmt::format(".npy header is not a dict literal: {}", dict));
  }
  std::map<std::string, std::string> entries;
  {
    std::string body = dict.substr(1, dict.size() - 2);
    size_t i = 0;
    const auto skip_space = [&] {
      while (i < body.size() && (body[i] == ' ')) ++i;
    };
    while (true) {
      skip_space();
      if (i >= body.size()) break;
      if (body[i] != '\'') fail(path, fmt::format(".npy header: a key is not quoted: {}", dict));
      const size_t key_end = body.find('\'', i + 1);
      if (key_end == std::string::npos) fail(path, ".npy header: unterminated key");
      const std::string key = body.substr(i + 1, key_end - i - 1);
      i = key_end + 1;
      skip_space();
      if (i >= body.size() || body[i] != ':') fail(path, ".npy header: no ':' after a key");
      ++i;
      skip_space();
      size_t value_end = i;
      if (i < body.size() && body[i] == '(') {
        value_end = body.find(')', i);
        if (value_end == std::string::npos) fail(path, ".npy header: unterminated shape tuple");
        ++value_end;
      } else if (i < body.size() && body[i] == '\'') {
        value_end = body.find('\'', i + 1);
        if (value_end == std::string::npos) fail(path, ".npy header: unterminated string");
        ++value_end;
      } else {
        while (value_end < body.size() && body[value_end] != ',') ++value_end;
      }
      const std::string value = trim(body.substr(i, value_end - i));
      if (!entries.emplace(key, value).second) {
        fail(path, fmt::format(".npy header: key '{}' twice", key));
      }
      i = value_end;
      skip_space();
      if (i < body.size() && body[i] == ',') ++i;
    }
  }
  for (const auto& [key, value] : entries) {
    if (key != "descr" && key != "fortran_order" && key != "shape") {
      fail(path, fmt::format(".npy header: unexpected key '{}'", key));
    }
  }
  for (const char* key : {"descr", "fortran_order", "shape"}) {
    if (entries.count(key) == 0) fail(path, fmt::format(".npy header: no key '{}'", key));
  }
  if (entries["descr"] != "'<f8'" && entries["descr"] != "'float64'") {
    fail(path, fmt::format(".npy dtype {} (only little-endian float64, '<f8', is read)",
                           entries["descr"]));
  }
  if (entries["fortran_order"] != "False") {
    fail(path, ".npy array in Fortran order (write it C-ordered: numpy.ascontiguousarray)");
  }
  std::vector<long long> shape;
  {
    const std::string& text = entries["shape"];
    std::string inner = text.substr(1, text.size() - 2);
    std::stringstream items(inner);
    std::string item;
    while (std::getline(items, item, ',')) {
      item = trim(item);
      if (item.empty()) continue;
      char* end = nullptr;
      errno = 0;
      const long long value = std::strtoll(item.c_str(), &end, 10);
      if (*end != '\0' || errno != 0 || value < 0) {
        fail(path, fmt::format(".npy header: bad shape {}", text));
      }
      shape.push_back(value);
    }
  }
  const std::vector<std::string> names = layout_names(problem, velocities);
  const auto width = static_cast<long long>(names.size());
  if (shape.size() != 2) {
    fail(path, fmt::format(".npy array of shape {} (a 2-D array rows x {} columns is read: {})",
                           entries["shape"], width, fmt::join(names, ",")));
  }
  if (shape[1] != width) {
    fail(path, fmt::format(".npy array has {} columns; problem '{}' needs {}: {}", shape[1],
                           problem.spec(), width, fmt::join(names, ",")));
  }
  const long long rows = shape[0];
  if (rows > static_cast<long long>(bytes.size())) fail(path, ".npy data cut short");
  const size_t data_bytes = static_cast<size_t>(rows * width) * sizeof(double);
  if (bytes.size() - data_start != data_bytes) {
    fail(path,
         fmt::format(".npy data is {} bytes, the shape ({}, {}) needs {}{}",
                     bytes.size() - data_start, rows, width, data_bytes,
                     bytes.size() - data_start < data_bytes ? " (the file was cut short)" : ""));
  }
  Table table;
  table.velocities = velocities;
  table.names = names;
  for (long long r = 0; r < rows; ++r) {
    std::vector<double> row(static_cast<size_t>(width));
    // Little-endian float64, as the descr says (geomint builds on little-endian machines only).
    std::memcpy(row.data(), bytes.data() + data_start + r * width * sizeof(double),
                width * sizeof(double));
    table.rows.push_back(std::move(row));
    table.where.push_back(fmt::format("row {}", r));
  }
  return table;
}

bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

Trajectory read_trajectory(const std::string& path, const Problem& problem, double start_tol,
                           bool npy_velocities) {
  const std::string bytes = read_bytes(path);
  const bool npy = ends_with(path, ".npy");
  Table table =
      npy ? read_npy(path, bytes, problem, npy_velocities) : read_csv(path, bytes, problem);
  if (table.rows.size() < 2) {
    fail(path, fmt::format("{} data row{}: a trajectory needs the initial state and at least one "
                           "step",
                           table.rows.size(), table.rows.size() == 1 ? "" : "s"));
  }
  for (size_t r = 0; r < table.rows.size(); ++r) {
    const std::vector<double>& row = table.rows[r];
    for (size_t c = 0; c < row.size(); ++c) {
      if (!std::isfinite(row[c])) {
        fail(path, fmt::format("{}, column {}: {} is not a finite number", table.where[r],
                               table.names[c], row[c]));
      }
    }
    if (r > 0 && !(row[0] > table.rows[r - 1][0])) {
      fail(path,
           fmt::format("{}, column t: t = {} does not increase (the row before has {})",
                       table.where[r], format_number(row[0]), format_number(table.rows[r - 1][0])));
    }
  }
  const int n = problem.dof();
  const bool first_order = problem.has(kFirstOrderOnly);
  const LagrangianSystem* lagrangian = problem.as_lagrangian();
  Trajectory trajectory;
  trajectory.path = path;
  trajectory.states.reserve(table.rows.size());
  for (const std::vector<double>& row : table.rows) {
    State state{row[0], Eigen::Map<const Vec>(row.data() + 1, n), Vec()};
    if (!first_order) {
      const Eigen::Map<const Vec> second(row.data() + 1 + n, n);
      if (!table.velocities) {
        state.p = second;
      } else if (lagrangian != nullptr) {
        state.p = lagrangian->momentum(state.q, second);  // p = ∂L/∂v = M(q)v + a(q)
      } else {
        state.p = MassOperator(problem).apply(state.q, second);
      }
    }
    trajectory.states.push_back(std::move(state));
  }
  // The first row against the initial state, in the file's own variables (v compared as v).
  const State initial = problem.initial_state();
  std::vector<double> expected = {initial.t};
  for (double x : initial.q) expected.push_back(x);
  if (!first_order) {
    const Vec second =
        table.velocities
            ? (lagrangian != nullptr ? lagrangian->velocity(initial.q, initial.p)
                                     : Vec(MassOperator(problem).solve(initial.q, initial.p)))
            : initial.p;
    for (double x : second) expected.push_back(x);
  }
  const std::vector<double>& first = table.rows.front();
  for (size_t c = 0; c < expected.size(); ++c) {
    const double allowed = start_tol * std::max(1.0, std::abs(expected[c]));
    if (!(std::abs(first[c] - expected[c]) <= allowed)) {
      fail(path, fmt::format("{}, column {}: the first row is not the initial state of '{}': {} "
                             "= {}, expected {} (difference {:.3g} > --start-tol {:g} x "
                             "max(1, |expected|))",
                             table.where.front(), table.names[c], problem.spec(), table.names[c],
                             format_number(first[c]), format_number(expected[c]),
                             std::abs(first[c] - expected[c]), start_tol));
    }
  }
  return trajectory;
}

const std::vector<std::string>& score_optional_metrics() {
  static const std::vector<std::string> names = {std::string(metric::period_measured.name),
                                                 std::string(metric::energy_growth_exponent.name),
                                                 std::string(metric::valid_time.name)};
  return names;
}

std::vector<std::string> score_metric_errors(const std::vector<std::string>& names) {
  std::vector<std::string> errors;
  const auto& allowed = score_optional_metrics();
  for (const std::string& name : names) {
    if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
      errors.push_back(fmt::format(
          "--metric {}: a trajectory alone gives only {} (the others read the method's step map)",
          name, fmt::join(allowed, ", ")));
    }
  }
  return errors;
}

RunRecord score_trajectory(const Problem& problem, const Trajectory& trajectory,
                           const ScoreConfig& config) {
  const std::vector<State>& states = trajectory.states;
  const double t0 = states.front().t;
  const double t_end = states.back().t - t0;
  const double first_step = states[1].t - t0;
  RunRecord record;
  record.problem = problem.spec();
  record.method = trajectory.path;
  record.t_end = t_end;
  record.steps = static_cast<long>(states.size()) - 1;
  record.status = "ok";
  // dt only for a uniform grid (as a fixed-step run has one).
  bool uniform = true;
  for (size_t k = 1; k < states.size() && uniform; ++k) {
    const double expected = t0 + static_cast<double>(k) * first_step;
    uniform = std::abs(states[k].t - expected) <= 1e-9 * std::max(1.0, std::abs(expected));
  }
  if (uniform) record.dt = first_step;
  // The reference as run_one picks it: one whose rows reach the last time.
  std::shared_ptr<const ReferenceSolution> reference;
  if (!problem.has(kExact) && !config.reference_dir.empty()) {
    const std::string path = reference_path(config.reference_dir, problem);
    if (std::filesystem::exists(path)) {
      auto loaded = load_reference(path, problem);
      if (loaded->row_at(t0 + t_end) >= 0) {
        reference = std::move(loaded);
        record.reference = std::filesystem::path(path).filename().string();
      }
    }
  }
  // No divergence rule: a trajectory is measured as written, not stopped.
  ObserverList observers = make_observers({.problem = problem,
                                           .metrics = config.extra_metrics,
                                           .dt = first_step,
                                           .diverge_factor = 0,
                                           .reference = reference});
  for (auto& observer : observers) observer->begin(problem, states.front(), t_end);
  for (size_t k = 1; k < states.size(); ++k) {
    for (auto& observer : observers) observer->observe(problem, states[k]);
  }
  for (const auto& observer : observers) observer->finish(record.metrics);
  return record;
}

OrderFit score_order(const Problem& problem, const std::vector<Trajectory>& trajectories,
                     const std::vector<RunRecord>& records) {
  if (static_cast<int>(trajectories.size()) < kMinOrderLevels) {
    throw InputError(
        fmt::format("score --order: {} file{} given; a fit needs at least {}, at "
                    "successively smaller steps",
                    trajectories.size(), trajectories.size() == 1 ? "" : "s", kMinOrderLevels));
  }
  std::vector<double> dts;
  const double t_last = trajectories.front().states.back().t;
  for (const Trajectory& trajectory : trajectories) {
    const double dt = trajectory.states[1].t - trajectory.states[0].t;
    if (!dts.empty() && !(dt < dts.back())) {
      throw InputError(
          fmt::format("score --order: {}: its first step {} is not smaller than the "
                      "previous file's {} (give the files from the largest step to "
                      "the smallest)",
                      trajectory.path, format_number(dt), format_number(dts.back())));
    }
    const double t = trajectory.states.back().t;
    if (std::abs(t - t_last) > 1e-9 * std::max(1.0, std::abs(t_last))) {
      throw InputError(fmt::format(
          "score --order: {}: it ends at t = {}, {} at t = {} (every "
          "file must end at the same time)",
          trajectory.path, format_number(t), trajectories.front().path, format_number(t_last)));
    }
    dts.push_back(dt);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const bool exact = std::all_of(records.begin(), records.end(), [](const RunRecord& record) {
    return record.metrics.count(metric::error_final.key()) > 0;
  });
  const State& finest = trajectories.back().states.back();
  const State initial = problem.initial_state();
  double state_scale = std::sqrt(initial.q.squaredNorm() + initial.p.squaredNorm());
  std::vector<double> errors;
  for (size_t i = 0; i < trajectories.size(); ++i) {
    const State& last = trajectories[i].states.back();
    state_scale = std::max(state_scale, std::sqrt(last.q.squaredNorm() + last.p.squaredNorm()));
    errors.push_back(
        exact ? records[i].metrics.at(metric::error_final.key())
              : std::sqrt((last.q - finest.q).squaredNorm() + (last.p - finest.p).squaredNorm()));
  }
  // Without an exact solution the finest file is the reference and has no error of its own.
  if (!exact) errors.back() = nan;
  constexpr double kPlateau = 1e-13;  // as order_study
  OrderFit fit = fit_order(dts, errors, kPlateau, kAsymptoticErrorFraction * state_scale);
  if (!exact) fit.note += std::string(fit.note.empty() ? "" : "; ") + "error vs finest file";
  return fit;
}

}  // namespace geomint
