// The one TOML layer of the harness (docs/DESIGN.md §5): scene files (harness/scene_file.hpp) and
// gates files (harness/gate.hpp) are read through these typed key readers, so a wrong type, a
// missing or an unknown key is an InputError naming the file, the block and the key alike.
#pragma once

#include <toml++/toml.h>

#include <optional>
#include <set>
#include <string>
#include <vector>

namespace geomint {

// Parses a TOML file. A directory or a syntax error is an InputError: "<kind> '<path>' is a
// directory ..." naming `example`, or "<path>:<line>:<column>: malformed <kind>: <reason>".
toml::table parse_toml_file(const std::string& path, const std::string& kind,
                            const std::string& example);

// The tables of `[[key]]` blocks under `root` (none when the key is absent); InputError when
// `key` is not an array of tables.
std::vector<const toml::table*> array_of_tables(const toml::table& root, const std::string& key,
                                                const std::string& where);

// Reads the keys of one table. Every reader marks its key as known; finish() then rejects the
// keys nobody asked for. `where` prefixes every message ("<file>: [[runs]] 'label'").
class TomlBlock {
 public:
  TomlBlock(const toml::table& table, std::string where)
      : table_(table), where_(std::move(where)) {}

  const std::string& where() const { return where_; }
  // Once the block's name is known, messages name it rather than its position.
  void rename(std::string where) { where_ = std::move(where); }
  const toml::table& table() const { return table_; }
  bool has(const std::string& key) const { return table_.get(key) != nullptr; }

  std::optional<std::string> optional_string(const std::string& key);
  // Integers are accepted as numbers, booleans are not; NaN and inf are returned as given.
  std::optional<double> optional_number(const std::string& key);

  std::string string(const std::string& key, bool required, const std::string& fallback = "");
  double number(const std::string& key, bool required, double fallback = 0);
  // An integer in [min_value, max_value]: TOML integers are 64-bit, and a value outside the
  // range is an error, never a silent truncation.
  long integer(const std::string& key, bool required, long fallback, long min_value,
               long max_value);
  bool boolean(const std::string& key, bool fallback);
  // A non-empty array of strings when required.
  std::vector<std::string> strings(const std::string& key, bool required);
  // A number or an array of numbers.
  std::vector<double> numbers(const std::string& key, bool required);

  // Marks a key read elsewhere (a nested block) as allowed.
  void known(const std::string& key) { seen_.insert(key); }
  // InputError "<where>: unknown key '<key>' (allowed: ...)" for a key no reader asked for.
  void finish() const;

 private:
  const toml::node* lookup(const std::string& key, bool required);
  const toml::table& table_;
  std::string where_;
  std::set<std::string> seen_;
};

}  // namespace geomint
