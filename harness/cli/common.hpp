// What every verb of the geomint command line (harness/run_main.cpp, docs/CLI.md) shares: exit
// codes, the per-invocation context, the Verb record each harness/cli/<verb>.cpp returns, and the
// helpers that turn CLI11's parse errors into messages naming the option and what it takes.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace geomint::cli {

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitInternal = 3;

// What a verb knows of the invocation besides its options: the name its messages start with,
// the `# command:` provenance line, and --quiet (every verb takes it: no progress, no
// informational line on stderr; errors and exit codes unchanged).
struct Context {
  std::string program;
  std::string command_line;
  bool quiet = false;
};

// An informational line on stderr ("sweep done", "merged", an order's ladder), which --quiet
// drops; errors are printed directly and never dropped.
void inform(const Context& context, const std::string& line);

// One verb: its CLI11 subcommand (options bound to an options struct the closure owns) and what
// runs it. Throws InputError for bad input (exit 2); returns the exit code otherwise.
struct Verb {
  std::string name;
  CLI::App* command = nullptr;
  std::function<int(const Context&)> run;
};

// argv[0] without its directories, so a user's program built on run_main speaks as itself;
// "geomint" when argv[0] is missing or empty.
std::string program_name(int argc, char** argv);

// Every argument shell-quoted, so the line pastes into a shell as it ran and merge can split it
// back into words (shell_words).
std::string joined_command_line(int argc, char** argv);

// False (message printed) when argv[1] is missing, or is neither an option nor one of `commands`:
// CLI11 alone would say "A subcommand is required" without naming the verbs.
bool check_command(const std::string& program, const std::vector<std::string>& commands, int argc,
                   char** argv);

// CLI11's message plus what the named option takes (or the options of the verb) and its --help.
std::string parse_error_advice(const CLI::App& app, const std::vector<std::string>& commands,
                               const std::string& program, int argc, char** argv,
                               const CLI::ParseError& error);

// The range check of a real-valued option (and its environment variable): refuses NaN and ±inf,
// which compare false and pass CLI::Range, and values outside [min, max]. Every range-checked
// real option uses it.
CLI::Validator finite_range(double min, double max);
// The same for an integer option: an empty value, a non-integer and one outside [min, max] are
// each named as such (CLI::Range would say "Value  not in range" for an empty one).
CLI::Validator integer_range(long min, long max);

// What every option of `command` gets (harness/cli/app.cpp): an empty value is refused (CLI11
// would read '' as 0, so `--wall-budget "$UNSET"` would remove the budget); a real-valued option
// refuses NaN (only what its help allows: `inf` where documented); and its default is appended
// to its help as "(default: X)" unless the help already says it.
void harden_options(CLI::App& command);

// Option help shared by run and order.
std::string diverge_factor_help();
extern const char* const kInitialStateHelp;

// Appends initial=FILE to a problem spec (run and order's --initial); InputError for a comma,
// which would end the spec item.
void add_initial_state(std::string& problem_spec, const std::string& initial_path);

}  // namespace geomint::cli
