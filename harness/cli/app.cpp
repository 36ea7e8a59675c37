// The whole command line: the exit-code footer of `geomint --help` and every verb in its order,
// each with --quiet and the checks every option gets (harden_options) (run_main dispatches to
// them).
#include "harness/cli/verbs.hpp"

namespace geomint::cli {

std::vector<Verb> add_verbs(CLI::App& app, bool& quiet) {
  // The order of `geomint --help`.
  std::vector<Verb> verbs = {
#define GEOMINT_VERB(verb) add_##verb(app),
#include "harness/cli/verbs.def"
#undef GEOMINT_VERB
  };
  // Set after the verbs: CLI11 copies a footer into subcommands made later, and the exit codes
  // belong to `geomint --help` once, not to every verb's help.
  app.footer(
      "Exit codes: 0 ok; 1 a run failed (run), no order could be fitted (order), a gate failed "
      "(gate) or a benchmark got slower (perf-compare); 2 bad input: the message names the "
      "offending option, key or value, and nothing is "
      "written (checked before any computing, outputs included); 3 internal error (\"geomint: "
      "internal error: ...\"): a defect, or an I/O failure after those checks such as a full "
      "disk. A numerical failure is a row whose status says what happened; a sweep exits 0 with "
      "its failures as rows.");
  for (const Verb& verb : verbs) {
    harden_options(*verb.command);
    verb.command->footer("Exit codes: see geomint --help.");
    verb.command->add_flag("--quiet", quiet,
                           "no progress and no informational lines on stderr (errors are still "
                           "printed; exit codes unchanged)");
  }
  return verbs;
}

}  // namespace geomint::cli
