// `geomint report`: the static results site (harness/report.hpp, docs/REPORT.md): every scene's
// tables, figures and gate verdicts, written into a folder it replaces whole.
#include "harness/report.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "harness/cli/verbs.hpp"

namespace geomint::cli {

Verb add_report(CLI::App& app) {
  auto options = std::make_shared<ReportOptions>();
  auto* command = app.add_subcommand(
      "report", "Write the results site (HTML: every scene's tables, figures, gate verdicts)");
  command->add_option("--results", options->results_dir,
                      "folder of <scene>/scene.toml scenes (default: results)");
  command->add_option("--gates", options->gates_path,
                      "gates file checked on each scene (default: <results>/gates.toml and each "
                      "<scene>/gates.toml)");
  command->add_option("--claims", options->claims_path,
                      "Markdown whose claim | measured | scene table gives the index's claims "
                      "(default: <results>/../README.md)");
  command->add_option("--out", options->out_dir, "site folder, replaced whole (default: site)");
  command->add_flag("--quick", options->quick,
                    "the CI-sized tables of <scene>/quick/ (make gate-quick writes them)");
  return {"report", command, [options](const Context& context) {
            options->command_line = context.command_line;
            const ReportSummary summary = write_report(*options);
            for (const auto& note : summary.notes) inform(context, note);
            // 0 once written: the gate verdicts are in the pages (`geomint gate` is what fails).
            inform(context,
                   fmt::format(
                       "report: {} scenes, {} tables, gates {} passed, {} failed{}{}; open {}",
                       summary.scenes, summary.tables, summary.gates_passed, summary.gates_failed,
                       summary.stale_scenes == 0
                           ? std::string()
                           : fmt::format(", {} scenes with stale tables (marked STALE)",
                                         summary.stale_scenes),
                       summary.uncaptioned_figures == 0
                           ? std::string()
                           : fmt::format(", {} figures without a caption in their figures.toml",
                                         summary.uncaptioned_figures),
                       (std::filesystem::path(options->out_dir) / "index.html").string()));
            return kExitOk;
          }};
}

}  // namespace geomint::cli
