// Spec strings "NAME" or "NAME:key=value,key=value" (docs/DESIGN.md §2) and the typed, validated
// parameter reader that every factory uses; the canonical spec (defaults filled in, keys
// sorted) is what CSV files record. Bad input throws InputError (the CLI turns it into exit 2).
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace geomint {

// Bad user input: unknown name or key, malformed value, out-of-range parameter.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Spec {
  std::string name;
  std::map<std::string, std::string> values;  // as written by the user

  // Throws InputError on "", ":", "a:=1", "a:b", duplicate keys.
  static Spec parse(const std::string& text);
};

// A test hook: when set, called with the text of every problem and method spec that make_problem
// and make_integrator parse, on the thread that parses it (harness/sweep_test.cpp counts
// the parses of a sweep with it). nullptr (the default): nothing is called.
using SpecParseHook = void (*)(const std::string& text);
void set_spec_parse_hook(SpecParseHook hook);
// Called by make_problem and make_integrator with the text they parse.
void notify_spec_parse(const std::string& text);

// The extra parameter sets a registry entry lists for the registry-driven tests
// (integrators/registry.def, problems/registry.def): "a=1;a=2,b=3" -> {"a=1", "a=2,b=3"}.
std::vector<std::string> split_variants(const std::string& text);

// Throws InputError unless `name` can be a registry name (letters, digits, '_'): what
// register_method() and register_problem() accept; `kind` is "method" or "problem".
void check_registration_name(const std::string& name, const std::string& kind);

// Candidates within an edit distance of a quarter of the word's length, at least 1
// (Damerau–Levenshtein, optimal string alignment; case-insensitive), closest first, at most three:
// what "did you mean" offers for a misspelt name, key, verb or option.
std::vector<std::string> close_matches(const std::string& word,
                                       const std::vector<std::string>& candidates);
// " (did you mean 'x' or 'y'?)" from close_matches, "" when nothing is close.
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);

// The allowed values of a numeric parameter, as data rather than code: Params checks a value
// against it and `geomint list NAME` prints it, so the printed range is the enforced one.
struct Range {
  static constexpr double kInfinity = std::numeric_limits<double>::infinity();
  double min = -kInfinity;
  double max = kInfinity;
  bool min_open = false, max_open = false;
  bool nonzero = false;  // additionally != 0 (a charge, a field)

  static Range above(double x) { return {x, kInfinity, true, false}; }          // > x
  static Range at_least(double x) { return {x, kInfinity, false, false}; }      // >= x
  static Range closed(double a, double b) { return {a, b, false, false}; }      // [a, b]
  static Range closed_open(double a, double b) { return {a, b, false, true}; }  // [a, b)
  static Range open(double a, double b) { return {a, b, true, true}; }          // (a, b)
  static Range open_closed(double a, double b) { return {a, b, true, false}; }  // (a, b]
  static Range magnitude(double m) { return closed(-m, m); }                    // |x| <= m
  static Range non_zero() {
    Range range;
    range.nonzero = true;
    return range;
  }

  bool contains(double x) const;
  // "> 0", ">= 0", "in [0, 1)", "|theta0| <= 1000" (for name "theta0"), "!= 0"; "" when
  // unrestricted.
  std::string text(const std::string& name = "x") const;
  bool restricts() const { return nonzero || min > -kInfinity || max < kInfinity; }
};

// Documentation of one parameter, collected while a factory reads its parameters: its kind
// ("real", "integer", "choice", "flag", "reals", "text"), default, help, and for numbers the
// range the reader enforces (`range` set) or, for the older lambda form, its description.
struct ParamDoc {
  std::string key;
  std::string default_value;
  std::string help;
  std::string kind;
  std::optional<Range> range;
  std::string allowed;  // what is allowed, as printed by `geomint list NAME`
};

// Bound on the magnitude of every real parameter (Params::real).
inline constexpr double kMaxParameterMagnitude = 1e15;

// Reads typed parameters from a Spec. Each getter records the key (with its default and help)
// so that finish() can reject unknown keys by listing the valid ones, and canonical() can
// print every parameter. `context` ("method 'hp'") prefixes every message.
class Params {
 public:
  Params(const Spec& spec, std::string context);

  // Real parameter in `range` (docs/PROBLEMS.md: ranges are data, printed by `geomint list
  // NAME`). Every real parameter must also satisfy |x| <= kMaxParameterMagnitude: larger values
  // square or multiply into overflow (ω², k·x²) or leave no digits for a step (θ + hω at
  // θ = 1e308).
  double real(const std::string& key, double default_value, const std::string& help,
              const Range& range = Range{});
  // The older form: a predicate and its description `valid` ("> 0"). `geomint list` prints the
  // description but cannot check it against the predicate; prefer a Range.
  double real(const std::string& key, double default_value, const std::string& help,
              const std::function<bool(double)>& ok, const std::string& valid);
  // Integer parameter, bounds inclusive.
  long integer(const std::string& key, long default_value, const std::string& help, long min_value,
               long max_value);
  // One of `choices`.
  std::string choice(const std::string& key, const std::string& default_value,
                     const std::vector<std::string>& choices, const std::string& help);
  bool flag(const std::string& key, bool default_value, const std::string& help);
  // A list of reals written "a/b/c" (a comma would end the spec item); each entry obeys the
  // bound of real(). Empty when the key is absent.
  std::vector<double> reals(const std::string& key, const std::string& help);
  // Free text (a file path), no commas.
  std::string text(const std::string& key, const std::string& default_value,
                   const std::string& help);

  // True when the user wrote this key (for parameters whose default depends on others).
  bool given(const std::string& key) const { return spec_.values.count(key) > 0; }

  // Leaves `key` (already read) out of canonical() while it has its default value: for options
  // that choose how a result is computed, not what (a linear solver run to the same Newton
  // tolerance), or for a parameter added later whose default is the problem as it was (a driving
  // amplitude of 0), so that adding one does not rename every committed run.
  void omit_default_from_canonical(const std::string& key);

  // Throws InputError naming any key that no getter read, with the list of valid keys.
  void finish() const;
  // "name:key=value,..." with every parameter read, keys sorted; "name" when there are none.
  std::string canonical() const;
  const std::vector<ParamDoc>& docs() const { return docs_; }
  const std::string& name() const { return spec_.name; }

 private:
  const std::string* raw(const std::string& key);
  void record(ParamDoc doc, const std::string& value);
  double read_real(const std::string& key, double default_value);

  Spec spec_;
  std::string context_;
  std::vector<ParamDoc> docs_;
  std::map<std::string, std::string> canonical_values_;
  std::set<std::string> omitted_at_default_;  // omit_default_from_canonical
};

// Formats a double so that it round-trips and stays short for common values ("0.5", "1e-08").
std::string format_number(double value);

}  // namespace geomint
