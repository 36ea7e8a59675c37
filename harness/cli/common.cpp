// Shared helpers of the command-line verbs (see common.hpp).
#include "harness/cli/common.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "harness/paths.hpp"
#include "harness/run.hpp"
#include "problems/problem.hpp"

namespace geomint::cli {

void inform(const Context& context, const std::string& line) {
  if (!context.quiet) fmt::print(stderr, "{}\n", line);
}

std::string program_name(int argc, char** argv) {
  if (argc < 1 || argv[0] == nullptr) return "geomint";
  std::string name = argv[0];
  const std::size_t slash = name.find_last_of('/');
  if (slash != std::string::npos) name.erase(0, slash + 1);
  return name.empty() ? "geomint" : name;
}

std::string joined_command_line(int argc, char** argv) {
  std::string out = "geomint";
  for (int i = 1; i < argc; ++i) out += " " + shell_quoted(argv[i]);
  return out;
}

bool check_command(const std::string& program, const std::vector<std::string>& commands, int argc,
                   char** argv) {
  const std::string listed = fmt::format("{}", fmt::join(commands, ", "));
  if (argc < 2) {
    fmt::print(stderr, "{0}: error: a command is required ({1}); see {0} --help\n", program,
               listed);
    return false;
  }
  const std::string first = argv[1];
  if (first.empty() || first[0] != '-') {
    if (std::find(commands.begin(), commands.end(), first) == commands.end()) {
      fmt::print(stderr, "{0}: error: unknown command '{1}'{3} (commands: {2}); see {0} --help\n",
                 program, first, listed, did_you_mean(first, commands));
      return false;
    }
  }
  return true;
}

namespace {

// What a CLI11 type name means to a user: "FLOAT" → "a number", "INT:INT in [1 - 256]" → "an
// integer in [1 - 256]".
std::string value_phrase(const std::string& type_name) {
  const std::string type = type_name.substr(0, type_name.find(':'));
  std::string check =
      type_name.find(':') == std::string::npos ? "" : type_name.substr(type_name.find(':') + 1);
  if (check.rfind(type + " ", 0) == 0) check.erase(0, type.size() + 1);
  std::string phrase = type == "FLOAT"  ? "a number"
                       : type == "INT"  ? "an integer"
                       : type == "UINT" ? "a non-negative integer"
                       : type == "TEXT" ? "text"
                       : type.empty()   ? "no value (a flag)"
                                        : type;
  if (!check.empty()) phrase += " " + check;
  return phrase;
}

}  // namespace

// CLI11 says what was wrong ("Could not convert: --dt = 1e-5x", "The following argument was not
// expected: --frob"); spec errors also say what is allowed. So does this: the option the
// message names, with what it takes, or the options the verb has, and its --help.
std::string parse_error_advice(const CLI::App& app, const std::vector<std::string>& commands,
                               const std::string& program, int argc, char** argv,
                               const CLI::ParseError& error) {
  const std::string verb = argc >= 2 ? argv[1] : "";
  const bool known_verb = std::find(commands.begin(), commands.end(), verb) != commands.end();
  const CLI::App* command = known_verb ? app.get_subcommand(verb) : &app;
  const std::string help =
      known_verb ? fmt::format("{} {} --help", program, verb) : fmt::format("{} --help", program);
  const std::string what = error.what();
  // The option the message names: the longest name found as a whole word ("--shard" is not
  // "--shards").
  const CLI::Option* named = nullptr;
  std::size_t named_length = 0;
  std::vector<std::string> names;
  for (const CLI::Option* option : command->get_options()) {
    const std::string name = option->get_name();
    if (name == "--help" || name.empty()) continue;
    names.push_back(name);
    for (std::size_t at = what.find(name); at != std::string::npos; at = what.find(name, at + 1)) {
      const std::size_t end = at + name.size();
      const bool word = (at == 0 || what[at - 1] == ' ') &&
                        (end == what.size() || what[end] == ' ' || what[end] == ':' ||
                         what[end] == '=' || what[end] == ',');
      if (word && name.size() > named_length) {
        named = option;
        named_length = name.size();
      }
    }
  }
  const bool unexpected = dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr;
  std::string advice = what;
  if (unexpected) {
    // "--dtt" → "did you mean '--dt'?": the first unexpected word that looks like an option.
    for (int i = 2; i < argc; ++i) {
      std::string word = argv[i];
      if (word.rfind("--", 0) != 0 ||
          command->get_option_no_throw(word.substr(0, word.find('=')))) {
        continue;
      }
      word = word.substr(0, word.find('='));
      if (what.find(word) == std::string::npos) continue;
      // Compared without the dashes every option shares, which would widen the threshold.
      std::vector<std::string> bare, close;
      for (const std::string& name : names) {
        if (name.rfind("--", 0) == 0) bare.push_back(name.substr(2));
      }
      for (const std::string& match : close_matches(word.substr(2), bare)) {
        close.push_back("--" + match);
      }
      const std::string suggestion = did_you_mean(word, close);
      if (!suggestion.empty()) advice += fmt::format("\n  '{}'{}", word, suggestion);
      break;
    }
  }
  if (named && !unexpected) {
    advice +=
        fmt::format("\n  {} takes {}", named->get_name(), value_phrase(named->get_type_name()));
    if (!named->get_description().empty()) advice += ": " + named->get_description();
  } else if (known_verb) {
    advice += fmt::format("\n  {} takes: {}", verb, fmt::join(names, ", "));
  }
  return advice + fmt::format("\n  see {}", help);
}

CLI::Validator finite_range(double min, double max) {
  return CLI::Validator(
      [min, max](std::string& text) -> std::string {
        const char* begin = text.c_str();
        char* end = nullptr;
        const double value = std::strtod(begin, &end);
        if (end == begin || *end != '\0') return fmt::format("'{}' is not a number", text);
        // !(in range), not (out of range): NaN compares false both ways.
        if (!(std::isfinite(value) && value >= min && value <= max)) {
          return fmt::format("{} is out of range (allowed: a finite number in [{:g}, {:g}])", text,
                             min, max);
        }
        return "";
      },
      fmt::format("FLOAT in [{:g} - {:g}]", min, max));
}

CLI::Validator integer_range(long min, long max) {
  return CLI::Validator(
      [min, max](std::string& text) -> std::string {
        if (text.empty()) return "an empty value is not allowed (an unset shell variable?)";
        long value = 0;
        const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
        if (result.ec != std::errc() || result.ptr != text.data() + text.size()) {
          return fmt::format("'{}' is not an integer in [{}, {}]", text, min, max);
        }
        if (value < min || value > max) {
          return fmt::format("{} is out of range (allowed: an integer in [{}, {}])", text, min,
                             max);
        }
        return "";
      },
      fmt::format("INT in [{} - {}]", min, max));
}

namespace {

// True when a help text already says its default ("default: the problem's", "(default 10",
// "0 = none, the default"); "defaults" ("its parameters and their defaults") does not count.
bool states_default(const std::string& help) {
  for (std::size_t at = help.find("default"); at != std::string::npos;
       at = help.find("default", at + 1)) {
    if (at + 7 == help.size() || help[at + 7] != 's') return true;
  }
  return false;
}

}  // namespace

void harden_options(CLI::App& command) {
  const CLI::Validator non_empty(
      [](std::string& text) -> std::string {
        return text.empty() ? "an empty value is not allowed (an unset shell variable?)" : "";
      },
      "");
  const CLI::Validator not_nan(
      [](std::string& text) -> std::string {
        const char* begin = text.c_str();
        char* end = nullptr;
        const double value = std::strtod(begin, &end);
        return end != begin && *end == '\0' && std::isnan(value)
                   ? "NaN is not allowed (a number is required)"
                   : "";
      },
      "");
  for (CLI::Option* option : command.get_options()) {
    if (option->get_expected_max() == 0) continue;  // a flag (--help, --quick) takes no value
    option->check(non_empty);
    if (option->get_type_name().rfind("FLOAT", 0) == 0) option->check(not_nan);
    if (option->get_required()) continue;
    // The default as the help states it: "(default: 3)", or "(default: none)" when unset.
    option->capture_default_str();
    std::string value = option->get_default_str();
    option->default_str("");
    if (states_default(option->get_description())) continue;
    if (value.empty() || value == "[]") value = "none";
    option->description(fmt::format("{} (default: {})", option->get_description(), value));
  }
}

std::string diverge_factor_help() {
  return fmt::format(
      "stop a conservative run as 'diverged' when its relative energy error exceeds this "
      "(default {:g}; 0 or inf: never)",
      kDefaultDivergeFactor);
}

const char* const kInitialStateHelp =
    "start from the state in this CSV (rows q,p, or q,v under a 'q,v' header; one per dof): "
    "the problem spec key initial=FILE";

void add_initial_state(std::string& problem_spec, const std::string& initial_path) {
  if (initial_path.empty()) return;
  // A comma would end the spec item; the spec (and so every CSV row) records the file.
  if (initial_path.find(',') != std::string::npos) {
    throw InputError(fmt::format("--initial: the path '{}' may not contain a comma", initial_path));
  }
  problem_spec += (problem_spec.find(':') == std::string::npos ? ":" : ",") +
                  std::string(kInitialStateKey) + "=" + initial_path;
}

}  // namespace geomint::cli
