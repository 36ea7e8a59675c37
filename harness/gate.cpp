// Accuracy gates: gates file parsing (toml++), result table loading with scene and variant, and
// the checks (gate.hpp).
#include "harness/gate.hpp"

#include <fmt/format.h>
#include <fnmatch.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "harness/record.hpp"
#include "harness/run_spec.hpp"
#include "harness/toml_reader.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace {

namespace fs = std::filesystem;

std::optional<double> parse_number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return std::nullopt;
  return value;
}

// The columns a gate on `table` may name, from the schema that writes that table (the metric
// columns from the metric table, harness/metrics.hpp); empty for tables without a schema here
// (stability, a gate on every table), whose columns are not checked.
template <typename Record>
std::vector<std::string> schema_names(const std::vector<Column<Record>>& schema) {
  std::vector<std::string> names;
  for (const auto& column : schema) names.push_back(column.name);
  return names;
}
std::vector<std::string> gate_columns(const std::string& table) {
  if (table == "summary") return schema_names(record_schema());
  if (table == "order") return schema_names(order_schema());
  return {};
}

void check_gate_column(const Gate& gate, const std::string& where) {
  const std::vector<std::string> columns = gate_columns(gate.table);
  if (columns.empty() || std::find(columns.begin(), columns.end(), gate.column) != columns.end()) {
    return;
  }
  throw InputError(fmt::format("{}: column '{}' is not a column of table '{}' (one of: {})", where,
                               gate.column, gate.table, fmt::join(columns, ", ")));
}

std::string node_text(const toml::node& node, const std::string& where) {
  if (auto text = node.value<std::string>()) return *text;
  if (auto integer = node.as_integer()) return std::to_string(integer->get());
  if (auto real = node.value<double>()) return format_number(*real);
  throw InputError(fmt::format("{}: values in 'where' must be strings or numbers", where));
}

// Canonical spec of a method or problem, so that defaults written or omitted compare equal.
std::string canonical_spec(const std::string& column, const std::string& text) {
  if (column == "method") return MethodFactory(text).spec();
  return parse_problem(text)->spec();
}

bool is_spec_column(const std::string& column) { return column == "method" || column == "problem"; }

bool values_match(const std::string& expected, const std::string& actual) {
  if (expected == actual) return true;
  const auto a = parse_number(expected), b = parse_number(actual);
  if (!a || !b) return false;
  return std::abs(*a - *b) <= 1e-12 * std::max(std::abs(*a), std::abs(*b));
}

// A band bound must be a number: NaN would make every comparison false.
std::optional<double> bound(TomlBlock& block, const char* key) {
  const auto value = block.optional_number(key);
  if (value && std::isnan(*value)) {
    throw InputError(fmt::format("{}: key '{}' is NaN: a band needs a number", block.where(), key));
  }
  return value;
}

void validate_check(const GateCheck& check, const std::string& where, const char* prefix) {
  if (!check.min && !check.max && !check.equals) {
    throw InputError(fmt::format("{}: give '{}min' and/or '{}max', or '{}equals'", where, prefix,
                                 prefix, prefix));
  }
  if (check.equals && (check.min || check.max)) {
    throw InputError(fmt::format("{}: '{}equals' cannot be combined with '{}min'/'{}max'", where,
                                 prefix, prefix, prefix));
  }
  if (check.min && check.max && *check.min > *check.max) {
    throw InputError(fmt::format("{}: {}min = {} is above {}max = {}", where, prefix, *check.min,
                                 prefix, *check.max));
  }
}

// "fig1_pendulum/summary.csv" → scene and table (the pre-scene `file` key of older gate files).
void parse_legacy_file(const std::string& file, Gate& gate, const std::string& where) {
  const fs::path path(file);
  const auto parts = std::distance(path.begin(), path.end());
  if (parts != 2 || path.extension() != ".csv") {
    throw InputError(fmt::format(
        "{}: 'file' must be '<scene>/<table>.csv' (got '{}'); prefer scene = \"...\" and "
        "table = \"summary\"",
        where, file));
  }
  gate.scene = path.begin()->string();
  gate.table = path.stem().string();
}

ResultFile read_result_file(const fs::path& path) {
  // A damaged table is refused whole (read_csv_file): a row cut inside a number would read as
  // another number and could pass a band the intact table fails.
  CsvTable csv = read_csv_file(path.string());
  ResultTable table{path.stem().string(), std::move(csv.provenance), {}, std::move(csv.rows)};
  return result_file(table, path.string());
}

}  // namespace

ResultFile result_file(const ResultTable& table, const std::string& path) {
  ResultFile file;
  file.path = path;
  file.table = table.name;
  file.rows = table.rows;
  const std::map<std::string, std::string> lines(table.provenance.begin(), table.provenance.end());
  const auto scene = lines.find("scene");
  const auto variant = lines.find("variant");
  if (scene != lines.end() && !scene->second.empty()) {
    file.scene = scene->second;
    file.variant = variant != lines.end() ? variant->second : "full";
  } else {
    // Files written before the scene lines: results/<scene>[/quick]/<table>.csv.
    const fs::path folder = fs::absolute(path).parent_path();
    file.variant = folder.filename() == "quick" ? "quick" : "full";
    file.scene = (file.variant == "quick" ? folder.parent_path() : folder).filename().string();
  }
  if (file.variant != "full" && file.variant != "quick") {
    throw InputError(fmt::format("gate: result file '{}': unknown variant '{}' (full or quick)",
                                 path, file.variant));
  }
  if (file.scene.empty()) {
    throw InputError(
        fmt::format("gate: result file '{}': cannot tell its scene (no '# scene:' line)", path));
  }
  return file;
}

std::vector<ResultFile> result_files(const std::vector<ResultTable>& tables,
                                     const std::string& folder) {
  std::vector<ResultFile> files;
  for (const auto& table : tables) {
    files.push_back(result_file(table, (fs::path(folder) / (table.name + ".csv")).string()));
  }
  // In the order load_result_files reads a folder's tables: by file name.
  std::sort(files.begin(), files.end(),
            [](const ResultFile& a, const ResultFile& b) { return a.path < b.path; });
  return files;
}

namespace {

// The same file reached by two spellings must be recognised (a cycle through "./x.toml").
fs::path canonical_or_absolute(const fs::path& path) {
  std::error_code error;
  const fs::path canonical = fs::weakly_canonical(fs::absolute(path), error);
  return error ? fs::absolute(path).lexically_normal() : canonical;
}

bool has_wildcard(const std::string& text) {
  return text.find_first_of("*?[") != std::string::npos;
}

// The files an `include` entry names: a path relative to the folder of the including file (or
// absolute); a component with * ? [...] matches the names in its folder (fnmatch, no hidden
// names), sorted. A plain path that does not exist, or a pattern that matches nothing, is an
// input error naming the including file.
std::vector<fs::path> resolve_include(const fs::path& from, const std::string& include) {
  const std::string where = fmt::format("gates file '{}': include '{}'", from.string(), include);
  if (include.empty()) throw InputError(where + ": an empty path");
  const fs::path relative(include);
  const fs::path base = relative.is_absolute() ? fs::path() : from.parent_path();
  std::vector<fs::path> found = {base};
  for (const fs::path& component : relative) {
    std::vector<fs::path> next;
    const std::string part = component.string();
    if (!has_wildcard(part)) {
      for (const auto& prefix : found) next.push_back(prefix / component);
    } else {
      for (const auto& prefix : found) {
        std::error_code error;
        const fs::path folder = prefix.empty() ? fs::path(".") : prefix;
        if (!fs::is_directory(folder, error)) continue;
        for (const auto& entry : fs::directory_iterator(folder, error)) {
          const std::string name = entry.path().filename().string();
          if (fnmatch(part.c_str(), name.c_str(), FNM_PERIOD) == 0) next.push_back(prefix / name);
        }
      }
      std::sort(next.begin(), next.end());
    }
    found = std::move(next);
  }
  std::vector<fs::path> files;
  for (const auto& path : found) {
    std::error_code error;
    if (fs::is_regular_file(path, error)) files.push_back(path.lexically_normal());
  }
  if (files.empty()) {
    throw InputError(has_wildcard(include)
                         ? fmt::format("{}: the pattern matches no file", where)
                         : fmt::format("{}: no such file '{}'", where,
                                       (base / relative).lexically_normal().string()));
  }
  return files;
}

// A gates file beside a scene.toml is that scene's own: its gates name that scene (or none),
// so a gate copied from another scene's file cannot sit where it never applies.
void check_scene_folder(const fs::path& path, const std::vector<Gate>& gates, std::size_t first) {
  const fs::path folder = canonical_or_absolute(path).parent_path();
  std::error_code error;
  if (!fs::exists(folder / "scene.toml", error)) return;
  const std::string scene = folder.filename().string();
  for (std::size_t k = first; k < gates.size(); ++k) {
    if (!gates[k].scene.empty() && gates[k].scene != scene) {
      throw InputError(fmt::format(
          "gates file '{}', gate '{}': scene '{}' is not the scene of the folder it sits in "
          "('{}'); move the gate to results/{}/gates.toml",
          path.string(), gates[k].name, gates[k].scene, scene, gates[k].scene));
    }
  }
}

// Reads one gates file and, depth first in the order given, the files it includes; `chain` holds
// the files being read (an include back onto one of them is a cycle), `origin` the file each gate
// name came from (a name may appear once across every file read).
void load_gates_file(const fs::path& path, std::vector<fs::path>& chain,
                     std::map<std::string, std::string>& origin, std::vector<Gate>& gates) {
  const std::string file_where = fmt::format("gates file '{}'", path.string());
  const toml::table root = parse_toml_file(path.string(), "gates file", "GATES.toml");
  TomlBlock top(root, file_where);
  top.known("gate");
  const std::vector<std::string> includes = top.strings("include", false);
  top.finish();
  const auto blocks = array_of_tables(root, "gate", file_where);
  if (blocks.empty() && includes.empty()) {
    throw InputError(fmt::format("{}: no [[gate]] blocks and no 'include'", file_where));
  }
  chain.push_back(canonical_or_absolute(path));
  const std::size_t first_own = gates.size();
  int index = 0;
  for (const toml::table* table : blocks) {
    ++index;
    TomlBlock block(*table, fmt::format("{}, gate {}", file_where, index));
    // Unknown keys are reported first, before a missing key they may be a typo of.
    for (const char* key : {"name", "scene", "table", "variants", "file", "where", "column", "min",
                            "max", "equals", "quick_min", "quick_max", "quick_equals"}) {
      block.known(key);
    }
    block.finish();
    Gate gate;
    gate.name = block.string("name", true);
    gate.file = path.string();
    block.rename(fmt::format("gates file '{}', gate '{}'", path.string(), gate.name));
    if (const auto [first, inserted] = origin.emplace(gate.name, gate.file); !inserted) {
      throw InputError(first->second == gate.file
                           ? fmt::format("{}: name used twice", block.where())
                           : fmt::format("{}: name used twice (also in gates file '{}')",
                                         block.where(), first->second));
    }
    gate.column = block.string("column", true);
    if (const auto file = block.optional_string("file")) {
      if (table->get("scene") || table->get("table")) {
        throw InputError(
            fmt::format("{}: give 'scene'/'table' or 'file', not both", block.where()));
      }
      parse_legacy_file(*file, gate, block.where());
    }
    if (const auto scene = block.optional_string("scene")) gate.scene = *scene;
    if (const auto table_name = block.optional_string("table")) gate.table = *table_name;
    if (const toml::node* node = table->get("variants")) {
      const toml::array* array = node->as_array();
      gate.variants.clear();
      if (array) {
        for (const auto& item : *array) {
          const auto value = item.value<std::string>();
          if (!value || (*value != "full" && *value != "quick")) {
            throw InputError(
                fmt::format("{}: 'variants' must list \"full\" and/or \"quick\"", block.where()));
          }
          gate.variants.push_back(*value);
        }
      }
      if (!array || gate.variants.empty()) {
        throw InputError(
            fmt::format("{}: 'variants' must be a non-empty array of \"full\", "
                        "\"quick\"",
                        block.where()));
      }
    }
    gate.full.min = bound(block, "min");
    gate.full.max = bound(block, "max");
    gate.full.equals = block.optional_string("equals");
    validate_check(gate.full, block.where(), "");
    const auto quick_min = bound(block, "quick_min");
    const auto quick_max = bound(block, "quick_max");
    const auto quick_equals = block.optional_string("quick_equals");
    if (quick_min || quick_max || quick_equals) {
      GateCheck quick = gate.full;
      if (quick_equals) quick = GateCheck{std::nullopt, std::nullopt, quick_equals};
      if (quick_min || quick_max) quick.equals.reset();
      if (quick_min) quick.min = quick_min;
      if (quick_max) quick.max = quick_max;
      validate_check(quick, block.where(), "quick_");
      gate.quick = quick;
    }
    if (const toml::node* node = table->get("where")) {
      const toml::table* conditions = node->as_table();
      if (!conditions) {
        throw InputError(block.where() +
                         ": 'where' must be an inline table, e.g. { method = \"rk4\" }");
      }
      for (const auto& [key, value] : *conditions) {
        const std::string where_column(key.str());
        std::string expected = node_text(value, block.where());
        if (is_spec_column(where_column)) {
          try {
            expected = canonical_spec(where_column, expected);
          } catch (const InputError& error) {
            throw InputError(
                fmt::format("{}: where.{}: {}", block.where(), where_column, error.what()));
          }
        }
        gate.where.emplace_back(where_column, expected);
      }
    }
    check_gate_column(gate, block.where());
    gates.push_back(std::move(gate));
  }
  check_scene_folder(path, gates, first_own);
  for (const std::string& include : includes) {
    for (const fs::path& included : resolve_include(path, include)) {
      const fs::path canonical = canonical_or_absolute(included);
      if (std::find(chain.begin(), chain.end(), canonical) != chain.end()) {
        std::vector<std::string> cycle;
        for (const auto& file : chain) cycle.push_back(file.string());
        cycle.push_back(canonical.string());
        throw InputError(fmt::format("{}: include '{}' is a cycle ({})", file_where, include,
                                     fmt::join(cycle, " -> ")));
      }
      // Two includes reaching one file (a pattern and a name of it) would repeat its gates.
      std::set<std::string> read;
      for (const Gate& gate : gates) read.insert(gate.file);
      if (std::any_of(read.begin(), read.end(), [&canonical](const std::string& file) {
            return canonical_or_absolute(file) == canonical;
          })) {
        throw InputError(fmt::format("{}: include '{}' reaches '{}', which is already included",
                                     file_where, include, included.string()));
      }
      load_gates_file(included, chain, origin, gates);
    }
  }
  chain.pop_back();
}

}  // namespace

std::vector<Gate> load_gates(const std::string& path) {
  std::vector<fs::path> chain;
  std::map<std::string, std::string> origin;
  std::vector<Gate> gates;
  load_gates_file(path, chain, origin, gates);
  if (gates.empty()) {
    throw InputError(fmt::format("gates file '{}': its includes hold no [[gate]] blocks", path));
  }
  return gates;
}

std::vector<ResultFile> load_result_files(const std::vector<std::string>& paths) {
  if (paths.empty()) throw InputError("gate: give at least one result CSV file or scene folder");
  std::vector<ResultFile> files;
  for (const auto& path : paths) {
    std::error_code error;
    const auto status = fs::status(path, error);
    if (error || !fs::exists(status)) {
      throw InputError(fmt::format("gate: result path '{}' does not exist", path));
    }
    if (fs::is_directory(status)) {
      std::vector<fs::path> tables;
      for (const auto& entry : fs::directory_iterator(path)) {
        if (entry.is_regular_file() && entry.path().extension() == ".csv") {
          tables.push_back(entry.path());
        }
      }
      if (tables.empty()) {
        throw InputError(
            fmt::format("gate: folder '{}' holds no result table (*.csv); give results/<scene> or "
                        "results/<scene>/quick after a sweep",
                        path));
      }
      std::sort(tables.begin(), tables.end());
      for (const auto& table : tables) files.push_back(read_result_file(table));
    } else {
      files.push_back(read_result_file(path));
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
    outcome.applicable = false;
    for (const ResultFile& file : files) {
      const bool of_scene = gate.scene.empty() || file.scene == gate.scene;
      const bool of_variant = std::find(gate.variants.begin(), gate.variants.end(), file.variant) !=
                              gate.variants.end();
      if (!of_scene || !of_variant) continue;
      outcome.applicable = true;
      if (!gate.table.empty() && file.table != gate.table) continue;
      const GateCheck& check = gate.check_for(file.variant);
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
        const std::string label = fmt::format("{}{}: label={} method={} problem={}{}", file.path,
                                              file.variant == "quick" ? " (quick)" : "",
                                              row.count("label") ? row.at("label") : "-",
                                              row.count("method") ? row.at("method") : "-",
                                              row.count("problem") ? row.at("problem") : "-",
                                              row.count("dt") ? " dt=" + row.at("dt") : "");
        const auto actual = row_value(row, gate.column);
        bool ok = false;
        std::string verdict;
        if (!actual) {
          verdict = fmt::format("column '{}' is empty or absent", gate.column);
        } else if (check.equals) {
          ok = *actual == *check.equals;
          verdict = fmt::format("{} = '{}' (required '{}')", gate.column, *actual, *check.equals);
        } else {
          const auto value = parse_number(*actual);
          ok = value && !std::isnan(*value) && (!check.min || *value >= *check.min) &&
               (!check.max || *value <= *check.max);
          verdict = fmt::format("{} = {} (required in [{}, {}])", gate.column, *actual,
                                check.min ? format_number(*check.min) : "-inf",
                                check.max ? format_number(*check.max) : "inf");
        }
        outcome.passed = outcome.passed && ok;
        outcome.lines.push_back(fmt::format("{} {}: {}", ok ? "ok  " : "FAIL", label, verdict));
      }
    }
    if (!outcome.applicable) {
      outcome.passed = true;
      outcome.lines.push_back(fmt::format("not applicable: no result of scene '{}' ({}) was given",
                                          gate.scene, fmt::join(gate.variants, "/")));
    } else if (outcome.rows_checked == 0) {
      outcome.passed = false;
      outcome.lines.push_back(fmt::format(
          "FAIL no row of table '{}' matches this gate's 'where' in the results given for scene "
          "'{}'",
          gate.table.empty() ? "*" : gate.table, gate.scene.empty() ? "*" : gate.scene));
    }
    outcomes.push_back(std::move(outcome));
  }
  return outcomes;
}

}  // namespace geomint
