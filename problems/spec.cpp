// Spec string parsing and the validated parameter reader (see spec.hpp).
#include "problems/spec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
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

std::atomic<SpecParseHook> spec_parse_hook{nullptr};

}  // namespace

void set_spec_parse_hook(SpecParseHook hook) { spec_parse_hook.store(hook); }

void notify_spec_parse(const std::string& text) {
  if (const SpecParseHook hook = spec_parse_hook.load()) hook(text);
}

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
    // "theta0=" (what "theta0=$UNSET" expands to) names the key: it is not read as 0.
    if (eq != std::string::npos && valid_identifier(trim(item.substr(0, eq))) &&
        trim(item.substr(eq + 1)).empty()) {
      throw InputError(fmt::format(
          "malformed spec '{}': key '{}' has an empty value (expected NAME:key=value,...)", text,
          trim(item.substr(0, eq))));
    }
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

namespace {

// Damerau–Levenshtein distance, optimal string alignment form, ignoring case: a swapped pair of
// neighbours ("thta0" → "theta0" is one insertion, "pendlum" one, "hp" ↔ "ph" one) costs 1.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  const auto lower = [](char c) { return std::tolower(static_cast<unsigned char>(c)); };
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
          lower(a[i - 2]) == lower(b[j - 1])) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

}  // namespace

std::vector<std::string> close_matches(const std::string& word,
                                       const std::vector<std::string>& candidates) {
  // A quarter of the length, at least 1: one slip in a short word ("dtt" → "dt", "rnu" → "run"),
  // up to three in a long one, and "q0" is not offered for "xy".
  const std::size_t threshold = std::max<std::size_t>(1, word.size() / 4);
  std::vector<std::pair<std::size_t, std::string>> scored;
  for (const std::string& candidate : candidates) {
    const std::size_t distance = edit_distance(word, candidate);
    if (distance <= threshold && distance < std::max(word.size(), candidate.size())) {
      scored.emplace_back(distance, candidate);
    }
  }
  std::stable_sort(scored.begin(), scored.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<std::string> out;
  for (const auto& [distance, candidate] : scored) {
    if (out.size() < 3 && std::find(out.begin(), out.end(), candidate) == out.end()) {
      out.push_back(candidate);
    }
  }
  return out;
}

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  const std::vector<std::string> matches = close_matches(word, candidates);
  if (matches.empty()) return "";
  std::string listed;
  for (std::size_t i = 0; i < matches.size(); ++i) {
    if (i > 0) listed += i + 1 == matches.size() ? " or " : ", ";
    listed += "'" + matches[i] + "'";
  }
  return fmt::format(" (did you mean {}?)", listed);
}

Params::Params(const Spec& spec, std::string context) : spec_(spec), context_(std::move(context)) {}

const std::string* Params::raw(const std::string& key) {
  auto it = spec_.values.find(key);
  return it == spec_.values.end() ? nullptr : &it->second;
}

void Params::record(ParamDoc doc, const std::string& value) {
  canonical_values_[doc.key] = value;
  docs_.push_back(std::move(doc));
}

bool Range::contains(double x) const {
  const bool above_min = min_open ? x > min : x >= min;
  const bool below_max = max_open ? x < max : x <= max;
  return above_min && below_max && !(nonzero && x == 0);
}

std::string Range::text(const std::string& name) const {
  std::string out;
  if (min == -kInfinity && max == kInfinity) {
    out = "";
  } else if (max == kInfinity) {
    out = fmt::format("{} {}", min_open ? ">" : ">=", format_number(min));
  } else if (min == -kInfinity) {
    out = fmt::format("{} {}", max_open ? "<" : "<=", format_number(max));
  } else if (min == -max && !min_open && !max_open) {
    out = fmt::format("|{}| <= {}", name, format_number(max));
  } else {
    out = fmt::format("in {}{}, {}{}", min_open ? "(" : "[", format_number(min), format_number(max),
                      max_open ? ")" : "]");
  }
  if (nonzero) out += out.empty() ? "!= 0" : " and != 0";
  return out;
}

double Params::read_real(const std::string& key, double default_value) {
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
  return value;
}

double Params::real(const std::string& key, double default_value, const std::string& help,
                    const Range& range) {
  const double value = read_real(key, default_value);
  if (!range.contains(value)) {
    throw InputError(fmt::format("{}: parameter {}={} is out of range (allowed: {})", context_, key,
                                 format_number(value), range.text(key)));
  }
  record({key, format_number(default_value), help, "real",
          range.restricts() ? std::optional<Range>(range) : std::nullopt, range.text(key)},
         format_number(value));
  return value;
}

double Params::real(const std::string& key, double default_value, const std::string& help,
                    const std::function<bool(double)>& ok, const std::string& valid) {
  const double value = read_real(key, default_value);
  if (ok && !ok(value)) {
    throw InputError(fmt::format("{}: parameter {}={} is out of range (allowed: {})", context_, key,
                                 format_number(value), valid.empty() ? "see list" : valid));
  }
  record({key, format_number(default_value), help, "real", std::nullopt, valid},
         format_number(value));
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
  Range range = Range::closed(static_cast<double>(min_value), static_cast<double>(max_value));
  record({key, std::to_string(default_value), help, "integer", range,
          fmt::format("{}..{}", min_value, max_value)},
         std::to_string(value));
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
  record({key, default_value, fmt::format("{} ({})", help, fmt::join(choices, "|")), "choice",
          std::nullopt, fmt::format("{}", fmt::join(choices, "|"))},
         value);
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
  record({key, default_value ? "true" : "false", help, "flag", std::nullopt, "true|false"},
         value ? "true" : "false");
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
  record({key, "", help, "reals", std::nullopt,
          fmt::format("a/b/c, each |x| <= {:g}", kMaxParameterMagnitude)},
         fmt::format("{}", fmt::join(formatted, "/")));
  if (values.empty()) omitted_at_default_.insert(key);
  return values;
}

std::string Params::text(const std::string& key, const std::string& default_value,
                         const std::string& help) {
  const std::string* given_text = raw(key);
  const std::string value = given_text ? *given_text : default_value;
  record({key, default_value, help, "text", std::nullopt, "text without commas"}, value);
  if (value.empty()) omitted_at_default_.insert(key);
  return value;
}

void Params::finish() const {
  for (const auto& [key, value] : spec_.values) {
    if (canonical_values_.count(key) == 0) {
      std::vector<std::string> valid;
      for (const auto& doc : docs_) valid.push_back(doc.key);
      throw InputError(fmt::format(
          "{}: unknown parameter '{}'{} (valid: {})", context_, key, did_you_mean(key, valid),
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
