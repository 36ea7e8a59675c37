// Spec string parsing and the validated parameter reader (see spec.hpp).
#include "problems/spec.hpp"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>

namespace geomint {
namespace {

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const auto last = s.find_last_not_of(" \t");
  return s.substr(first, last - first + 1);
}

bool valid_identifier(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  }
  return true;
}

}  // namespace

Spec Spec::parse(const std::string& text) {
  Spec spec;
  const auto colon = text.find(':');
  spec.name = trim(text.substr(0, colon));
  if (!valid_identifier(spec.name)) {
    throw InputError(fmt::format("malformed spec '{}': expected NAME or NAME:key=value,...", text));
  }
  if (colon == std::string::npos) return spec;
  std::string rest = text.substr(colon + 1);
  size_t start = 0;
  while (start <= rest.size()) {
    const auto comma = rest.find(',', start);
    const std::string item =
        trim(rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    const auto eq = item.find('=');
    if (eq == std::string::npos || !valid_identifier(trim(item.substr(0, eq))) ||
        trim(item.substr(eq + 1)).empty()) {
      throw InputError(fmt::format(
          "malformed spec '{}': item '{}' is not key=value (expected NAME:key=value,...)", text,
          item));
    }
    const std::string key = trim(item.substr(0, eq));
    if (!spec.values.emplace(key, trim(item.substr(eq + 1))).second) {
      throw InputError(fmt::format("malformed spec '{}': key '{}' given twice", text, key));
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return spec;
}

std::string format_number(double value) {
  // Shortest representation that round-trips.
  char buffer[64];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

void check_registration_name(const std::string& name, const std::string& kind) {
  bool plain = !name.empty();
  for (char c : name) {
    plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
  }
  if (!plain) {
    throw InputError(fmt::format(
        "register_{}: name '{}' must be non-empty letters, digits and '_' (it is a spec name)",
        kind, name));
  }
}

std::vector<std::string> split_variants(const std::string& text) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start < text.size()) {
    const auto semicolon = text.find(';', start);
    out.push_back(text.substr(start, semicolon - start));
    if (semicolon == std::string::npos) break;
    start = semicolon + 1;
  }
  return out;
}

Params::Params(const Spec& spec, std::string context) : spec_(spec), context_(std::move(context)) {}

const std::string* Params::raw(const std::string& key) {
  auto it = spec_.values.find(key);
  return it == spec_.values.end() ? nullptr : &it->second;
}

void Params::record(const std::string& key, const std::string& default_value,
                    const std::string& help, const std::string& value) {
  docs_.push_back({key, default_value, help});
  canonical_values_[key] = value;
}

double Params::real(const std::string& key, double default_value, const std::string& help,
                    const std::function<bool(double)>& ok, const std::string& valid) {
  double value = default_value;
  if (const std::string* text = raw(key)) {
    const char* begin = text->c_str();
    char* end = nullptr;
    value = std::strtod(begin, &end);
    if (end == begin || *end != '\0' || !std::isfinite(value)) {
      throw InputError(
          fmt::format("{}: parameter {}='{}' is not a finite number", context_, key, *text));
    }
  }
  if (!(std::abs(value) <= kMaxParameterMagnitude)) {
    throw InputError(fmt::format("{}: parameter {}={} is out of range (allowed: |{}| <= {:g})",
                                 context_, key, format_number(value), key, kMaxParameterMagnitude));
  }
  if (ok && !ok(value)) {
    throw InputError(fmt::format("{}: parameter {}={} is out of range (allowed: {})", context_, key,
                                 format_number(value), valid.empty() ? "see list" : valid));
  }
  record(key, format_number(default_value), help, format_number(value));
  return value;
}

long Params::integer(const std::string& key, long default_value, const std::string& help,
                     long min_value, long max_value) {
  long value = default_value;
  if (const std::string* text = raw(key)) {
    const auto result = std::from_chars(text->data(), text->data() + text->size(), value);
    if (result.ec != std::errc() || result.ptr != text->data() + text->size()) {
      throw InputError(
          fmt::format("{}: parameter {}='{}' is not an integer", context_, key, *text));
    }
  }
  if (value < min_value || value > max_value) {
    throw InputError(fmt::format("{}: parameter {}={} is out of range (allowed: {}..{})", context_,
                                 key, value, min_value, max_value));
  }
  record(key, std::to_string(default_value), help, std::to_string(value));
  return value;
}

std::string Params::choice(const std::string& key, const std::string& default_value,
                           const std::vector<std::string>& choices, const std::string& help) {
  std::string value = default_value;
  if (const std::string* text = raw(key)) value = *text;
  bool found = false;
  for (const auto& c : choices) found = found || c == value;
  if (!found) {
    throw InputError(fmt::format("{}: parameter {}='{}' is not allowed (allowed: {})", context_,
                                 key, value, fmt::join(choices, ", ")));
  }
  record(key, default_value, fmt::format("{} ({})", help, fmt::join(choices, "|")), value);
  return value;
}

bool Params::flag(const std::string& key, bool default_value, const std::string& help) {
  bool value = default_value;
  if (const std::string* text = raw(key)) {
    if (*text == "true" || *text == "1") {
      value = true;
    } else if (*text == "false" || *text == "0") {
      value = false;
    } else {
      throw InputError(fmt::format("{}: parameter {}='{}' is not a boolean (allowed: true, false)",
                                   context_, key, *text));
    }
  }
  record(key, default_value ? "true" : "false", help, value ? "true" : "false");
  return value;
}

std::vector<double> Params::reals(const std::string& key, const std::string& help) {
  std::vector<double> values;
  std::vector<std::string> formatted;
  if (const std::string* text = raw(key)) {
    size_t start = 0;
    while (true) {
      const auto slash = text->find('/', start);
      const std::string item =
          text->substr(start, slash == std::string::npos ? slash : slash - start);
      char* end = nullptr;
      const double value = std::strtod(item.c_str(), &end);
      if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(value) ||
          !(std::abs(value) <= kMaxParameterMagnitude)) {
        throw InputError(
            fmt::format("{}: parameter {}='{}' is not a list of finite numbers a/b/c (entry '{}')",
                        context_, key, *text, item));
      }
      values.push_back(value);
      formatted.push_back(format_number(value));
      if (slash == std::string::npos) break;
      start = slash + 1;
    }
  }
  record(key, "", help, fmt::format("{}", fmt::join(formatted, "/")));
  if (values.empty()) omitted_at_default_.insert(key);
  return values;
}

std::string Params::text(const std::string& key, const std::string& default_value,
                         const std::string& help) {
  const std::string* given_text = raw(key);
  const std::string value = given_text ? *given_text : default_value;
  record(key, default_value, help, value);
  if (value.empty()) omitted_at_default_.insert(key);
  return value;
}

void Params::finish() const {
  for (const auto& [key, value] : spec_.values) {
    if (canonical_values_.count(key) == 0) {
      std::vector<std::string> valid;
      for (const auto& doc : docs_) valid.push_back(doc.key);
      throw InputError(
          fmt::format("{}: unknown parameter '{}' (valid: {})", context_, key,
                      valid.empty() ? "none" : fmt::format("{}", fmt::join(valid, ", "))));
    }
  }
}

void Params::omit_default_from_canonical(const std::string& key) {
  const auto value = canonical_values_.find(key);
  if (value == canonical_values_.end()) return;
  for (const ParamDoc& doc : docs_) {
    if (doc.key == key && doc.default_value == value->second) omitted_at_default_.insert(key);
  }
}

std::string Params::canonical() const {
  std::string out = spec_.name;
  char separator = ':';
  for (const auto& [key, value] : canonical_values_) {
    if (omitted_at_default_.count(key)) continue;
    out += separator;
    out += key + "=" + value;
    separator = ',';
  }
  return out;
}

}  // namespace geomint
