// Shared helpers of the command-line verbs (see common.hpp).
#include "harness/cli/common.hpp"

#include <fmt/format.h>

#include <algorithm>

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
      fmt::print(stderr, "{0}: error: unknown command '{1}' (commands: {2}); see {0} --help\n",
                 program, first, listed);
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
  if (named && !unexpected) {
    advice +=
        fmt::format("\n  {} takes {}", named->get_name(), value_phrase(named->get_type_name()));
    if (!named->get_description().empty()) advice += ": " + named->get_description();
  } else if (known_verb) {
    advice += fmt::format("\n  {} takes: {}", verb, fmt::join(names, ", "));
  }
  return advice + fmt::format("\n  see {}", help);
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
