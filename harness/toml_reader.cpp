// The typed TOML key readers shared by scene and gates files (see toml_reader.hpp).
#include "harness/toml_reader.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdint>
#include <filesystem>
#include <fstream>

#include "problems/spec.hpp"

namespace geomint {

toml::table parse_toml_file(const std::string& path, const std::string& kind,
                            const std::string& example) {
  // toml++ says only "File could not be opened": say which of the usual reasons it is.
  namespace fs = std::filesystem;
  std::error_code filesystem_error;
  const fs::file_status status = fs::status(path, filesystem_error);
  if (status.type() == fs::file_type::not_found) {
    throw InputError(fmt::format("{} '{}' does not exist (expected e.g. {})", kind, path, example));
  }
  if (filesystem_error) {
    throw InputError(
        fmt::format("{} '{}' cannot be accessed: {}", kind, path, filesystem_error.message()));
  }
  if (fs::is_directory(status)) {
    throw InputError(
        fmt::format("{} '{}' is a directory, not a file (expected e.g. {})", kind, path, example));
  }
  if (!std::ifstream(path)) {
    throw InputError(fmt::format("{} '{}' cannot be read: {}", kind, path,
                                 std::error_code(errno, std::generic_category()).message()));
  }
  try {
    return toml::parse_file(path);
  } catch (const toml::parse_error& error) {
    throw InputError(fmt::format("{}:{}:{}: malformed {}: {}", path, error.source().begin.line,
                                 error.source().begin.column, kind, error.description()));
  }
}

std::vector<const toml::table*> array_of_tables(const toml::table& root, const std::string& key,
                                                const std::string& where) {
  std::vector<const toml::table*> out;
  const toml::node* node = root.get(key);
  if (!node) return out;
  const auto not_tables = [&] {
    return InputError(fmt::format("{}: '{}' must be an array of tables ([[{}]])", where, key, key));
  };
  const toml::array* array = node->as_array();
  if (!array) throw not_tables();
  for (const auto& item : *array) {
    const toml::table* table = item.as_table();
    if (!table) throw not_tables();
    out.push_back(table);
  }
  return out;
}

const toml::node* TomlBlock::lookup(const std::string& key, bool required) {
  seen_.insert(key);
  const toml::node* node = table_.get(key);
  if (!node && required) {
    throw InputError(fmt::format("{}: missing required key '{}'", where_, key));
  }
  return node;
}

std::optional<std::string> TomlBlock::optional_string(const std::string& key) {
  const toml::node* node = lookup(key, false);
  if (!node) return std::nullopt;
  if (auto value = node->value<std::string>()) return *value;
  throw InputError(fmt::format("{}: key '{}' must be a string", where_, key));
}

std::optional<double> TomlBlock::optional_number(const std::string& key) {
  const toml::node* node = lookup(key, false);
  if (!node) return std::nullopt;
  auto value = node->value<double>();
  if (!value || node->is_boolean()) {
    throw InputError(fmt::format("{}: key '{}' must be a number", where_, key));
  }
  return *value;
}

std::string TomlBlock::string(const std::string& key, bool required, const std::string& fallback) {
  lookup(key, required);
  return optional_string(key).value_or(fallback);
}

double TomlBlock::number(const std::string& key, bool required, double fallback) {
  lookup(key, required);
  return optional_number(key).value_or(fallback);
}

long TomlBlock::integer(const std::string& key, bool required, long fallback, long min_value,
                        long max_value) {
  const toml::node* node = lookup(key, required);
  if (!node) return fallback;
  const auto* value = node->as_integer();
  if (!value) throw InputError(fmt::format("{}: key '{}' must be an integer", where_, key));
  const std::int64_t number = value->get();
  if (number < min_value || number > max_value) {
    throw InputError(fmt::format("{}: key '{}' must be in {}..{} (got {})", where_, key, min_value,
                                 max_value, number));
  }
  return static_cast<long>(number);
}

bool TomlBlock::boolean(const std::string& key, bool fallback) {
  const toml::node* node = lookup(key, false);
  if (!node) return fallback;
  if (auto value = node->value<bool>()) return *value;
  throw InputError(fmt::format("{}: key '{}' must be true or false", where_, key));
}

std::vector<std::string> TomlBlock::strings(const std::string& key, bool required) {
  std::vector<std::string> out;
  const toml::node* node = lookup(key, required);
  if (!node) return out;
  const auto wrong_type = [&] {
    return InputError(fmt::format("{}: key '{}' must be an array of strings", where_, key));
  };
  const toml::array* array = node->as_array();
  if (!array) throw wrong_type();
  for (const auto& item : *array) {
    auto value = item.value<std::string>();
    if (!value) throw wrong_type();
    out.push_back(*value);
  }
  if (required && out.empty()) throw InputError(fmt::format("{}: key '{}' is empty", where_, key));
  return out;
}

std::vector<double> TomlBlock::numbers(const std::string& key, bool required) {
  std::vector<double> out;
  const toml::node* node = lookup(key, required);
  if (!node) return out;
  if (auto value = node->value<double>()) return {*value};
  const toml::array* array = node->as_array();
  if (!array) {
    throw InputError(
        fmt::format("{}: key '{}' must be a number or an array of numbers", where_, key));
  }
  for (const auto& item : *array) {
    auto value = item.value<double>();
    if (!value) {
      throw InputError(fmt::format("{}: key '{}' must be an array of numbers", where_, key));
    }
    out.push_back(*value);
  }
  return out;
}

void TomlBlock::finish() const {
  for (const auto& [key, node] : table_) {
    if (!seen_.count(std::string(key.str()))) {
      throw InputError(fmt::format("{}: unknown key '{}' (allowed: {})", where_, key.str(),
                                   fmt::join(seen_, ", ")));
    }
  }
}

}  // namespace geomint
