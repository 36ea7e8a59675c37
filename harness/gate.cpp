// Accuracy gates: gates file parsing (toml++), result CSV loading and the checks (gate.hpp).
#include "harness/gate.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "integrators/integrator.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace {

std::optional<double> parse_number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return std::nullopt;
  return value;
}

std::string node_text(const toml::node& node, const std::string& where) {
  if (auto text = node.value<std::string>()) return *text;
  if (auto integer = node.as_integer()) return std::to_string(integer->get());
  if (auto real = node.value<double>()) return format_number(*real);
  throw InputError(fmt::format("{}: values in 'where' must be strings or numbers", where));
}

// Canonical spec of a method or problem, so that defaults written or omitted compare equal.
std::string canonical_spec(const std::string& column, const std::string& text) {
  if (column == "method") return make_integrator(text)->spec();
  return make_problem(text)->spec();
}

bool is_spec_column(const std::string& column) { return column == "method" || column == "problem"; }

bool values_match(const std::string& expected, const std::string& actual) {
  if (expected == actual) return true;
  const auto a = parse_number(expected), b = parse_number(actual);
  if (!a || !b) return false;
  return std::abs(*a - *b) <= 1e-12 * std::max(std::abs(*a), std::abs(*b));
}

}  // namespace

std::vector<Gate> load_gates(const std::string& path) {
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& error) {
    throw InputError(fmt::format("gates file '{}': {} (line {})", path, error.description(),
                                 error.source().begin.line));
  }
  for (const auto& [key, node] : root) {
    if (key.str() != "gate") {
      throw InputError(
          fmt::format("gates file '{}': unknown top-level key '{}' (allowed: [[gate]] blocks)",
                      path, key.str()));
    }
  }
  const toml::array* blocks = root["gate"].as_array();
  if (!blocks || blocks->empty()) {
    throw InputError(fmt::format("gates file '{}': no [[gate]] blocks", path));
  }
  const std::set<std::string> allowed = {"name", "file", "where", "column", "min", "max", "equals"};
  std::vector<Gate> gates;
  int index = 0;
  for (const toml::node& block_node : *blocks) {
    ++index;
    const toml::table* block = block_node.as_table();
    std::string where = fmt::format("gates file '{}', gate {}", path, index);
    if (!block) throw InputError(where + ": must be a table ([[gate]])");
    for (const auto& [key, node] : *block) {
      if (!allowed.count(std::string(key.str()))) {
        throw InputError(fmt::format(
            "{}: unknown key '{}' (allowed: name, file, where, column, min, max, equals)", where,
            key.str()));
      }
    }
    Gate gate;
    auto text = [&](const char* key, bool required) -> std::string {
      const toml::node* node = block->get(key);
      if (!node) {
        if (required) throw InputError(fmt::format("{}: missing key '{}'", where, key));
        return "";
      }
      if (auto value = node->value<std::string>()) return *value;
      throw InputError(fmt::format("{}: key '{}' must be a string", where, key));
    };
    auto number = [&](const char* key) -> std::optional<double> {
      const toml::node* node = block->get(key);
      if (!node) return std::nullopt;
      if (auto value = node->value<double>()) return *value;
      throw InputError(fmt::format("{}: key '{}' must be a number", where, key));
    };
    gate.name = text("name", true);
    where = fmt::format("gates file '{}', gate '{}'", path, gate.name);
    gate.file = text("file", false);
    gate.column = text("column", true);
    gate.min = number("min");
    gate.max = number("max");
    if (block->get("equals")) gate.equals = text("equals", true);
    if (!gate.min && !gate.max && !gate.equals) {
      throw InputError(where + ": give 'min' and/or 'max', or 'equals'");
    }
    if (gate.equals && (gate.min || gate.max)) {
      throw InputError(where + ": 'equals' cannot be combined with 'min'/'max'");
    }
    if (gate.min && gate.max && *gate.min > *gate.max) {
      throw InputError(fmt::format("{}: min = {} is above max = {}", where, *gate.min, *gate.max));
    }
    if (const toml::node* node = block->get("where")) {
      const toml::table* conditions = node->as_table();
      if (!conditions) {
        throw InputError(where + ": 'where' must be an inline table, e.g. { method = \"rk4\" }");
      }
      for (const auto& [key, value] : *conditions) {
        const std::string column(key.str());
        std::string expected = node_text(value, where);
        if (is_spec_column(column)) {
          try {
            expected = canonical_spec(column, expected);
          } catch (const InputError& error) {
            throw InputError(fmt::format("{}: where.{}: {}", where, column, error.what()));
          }
        }
        gate.where.emplace_back(column, expected);
      }
    }
    gates.push_back(std::move(gate));
  }
  return gates;
}

std::vector<ResultFile> load_result_files(const std::vector<std::string>& paths) {
  if (paths.empty()) throw InputError("gate: give at least one result CSV file");
  std::vector<ResultFile> files;
  for (const auto& path : paths) {
    std::ifstream stream(path);
    if (!stream) throw InputError(fmt::format("gate: cannot read result file '{}'", path));
    std::stringstream text;
    text << stream.rdbuf();
    try {
      files.push_back({path, parse_csv(text.str())});
    } catch (const std::runtime_error& error) {
      throw InputError(fmt::format("gate: result file '{}': {}", path, error.what()));
    }
  }
  return files;
}

std::vector<GateOutcome> check_gates(const std::vector<Gate>& gates,
                                     const std::vector<ResultFile>& files) {
  std::map<std::pair<std::string, std::string>, std::string> canonical_cache;
  auto row_value = [&](const Row& row, const std::string& column) -> std::optional<std::string> {
    const auto found = row.find(column);
    if (found == row.end()) return std::nullopt;
    if (!is_spec_column(column)) return found->second;
    auto [entry, inserted] = canonical_cache.try_emplace({column, found->second}, found->second);
    if (inserted) {
      try {
        entry->second = canonical_spec(column, found->second);
      } catch (const InputError&) {
        // A spec this build no longer knows: compare its text as written.
      }
    }
    return entry->second;
  };

  std::vector<GateOutcome> outcomes;
  for (const Gate& gate : gates) {
    GateOutcome outcome;
    outcome.gate = &gate;
    outcome.passed = true;
    for (const ResultFile& file : files) {
      const bool file_matches =
          gate.file.empty() || (file.path.size() >= gate.file.size() &&
                                file.path.compare(file.path.size() - gate.file.size(),
                                                  gate.file.size(), gate.file) == 0);
      if (!file_matches) continue;
      for (const Row& row : file.rows) {
        bool selected = true;
        for (const auto& [column, expected] : gate.where) {
          const auto actual = row_value(row, column);
          if (!actual || !values_match(expected, *actual)) {
            selected = false;
            break;
          }
        }
        if (!selected) continue;
        ++outcome.rows_checked;
        const std::string label = fmt::format("{}: method={} problem={}{}", file.path,
                                              row.count("method") ? row.at("method") : "-",
                                              row.count("problem") ? row.at("problem") : "-",
                                              row.count("dt") ? " dt=" + row.at("dt") : "");
        const auto actual = row_value(row, gate.column);
        bool ok = false;
        std::string verdict;
        if (!actual) {
          verdict = fmt::format("column '{}' is empty or absent", gate.column);
        } else if (gate.equals) {
          ok = *actual == *gate.equals;
          verdict = fmt::format("{} = '{}' (required '{}')", gate.column, *actual, *gate.equals);
        } else {
          const auto value = parse_number(*actual);
          ok = value && !std::isnan(*value) && (!gate.min || *value >= *gate.min) &&
               (!gate.max || *value <= *gate.max);
          verdict = fmt::format("{} = {} (required in [{}, {}])", gate.column, *actual,
                                gate.min ? format_number(*gate.min) : "-inf",
                                gate.max ? format_number(*gate.max) : "inf");
        }
        outcome.passed = outcome.passed && ok;
        outcome.lines.push_back(fmt::format("{} {}: {}", ok ? "ok  " : "FAIL", label, verdict));
      }
    }
    if (outcome.rows_checked == 0) {
      outcome.passed = false;
      outcome.lines.push_back("FAIL no result row matches this gate's 'file' and 'where'");
    }
    outcomes.push_back(std::move(outcome));
  }
  return outcomes;
}

}  // namespace geomint
