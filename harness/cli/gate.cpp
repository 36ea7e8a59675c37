// `geomint gate GATES RESULTS...`: result tables checked against the thresholds of a gates file
// (harness/gate.hpp); exit 1 when a gate fails, 2 when none applies (docs/CLI.md "gate"). The
// verdicts print as text, as JUnit XML (one <testsuite> per scene, one <testcase> per gate) for
// CI systems to render, or as a JSON array of {scene, gate, passed, message}; both are valid
// whatever the gate names and paths hold (harness/text_escape.hpp).
#include "harness/gate.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include "harness/cli/verbs.hpp"
#include "harness/report.hpp"
#include "harness/text_escape.hpp"
#include "problems/spec.hpp"

namespace geomint::cli {
namespace {

namespace fs = std::filesystem;

struct GateCliOptions {
  std::string gates_path;
  std::vector<std::string> results;
  bool verbose = false;
  std::string format = "text";
};

// A gate without a scene checks every scene given.
std::string scene_of(const Gate& gate) { return gate.scene.empty() ? "*" : gate.scene; }

// The checked rows of a failing gate (every row with --verbose), one per line.
std::string outcome_message(const GateOutcome& outcome, bool verbose) {
  std::string message = fmt::format("{} row(s)", outcome.rows_checked);
  if (!outcome.passed || verbose) {
    for (const auto& line : outcome.lines) message += "\n" + line;
  }
  return message;
}

// Plain text, no colour (docs/CLI.md "Quiet and colour"); --quiet prints the failing gates alone.
void print_text(const std::vector<const GateOutcome*>& applied, bool verbose, bool quiet) {
  for (const GateOutcome* outcome : applied) {
    if (quiet && outcome->passed) continue;
    fmt::print("{} {} ({} row(s))\n", outcome->passed ? "PASS" : "FAIL", outcome->gate->name,
               outcome->rows_checked);
    if (!outcome->passed || verbose) {
      for (const auto& line : outcome->lines) fmt::print("    {}\n", line);
    }
  }
}

void print_junit(const std::vector<const GateOutcome*>& applied, bool verbose) {
  std::map<std::string, std::vector<const GateOutcome*>> by_scene;
  for (const GateOutcome* outcome : applied) by_scene[scene_of(*outcome->gate)].push_back(outcome);
  int failures = 0;
  for (const GateOutcome* outcome : applied) failures += outcome->passed ? 0 : 1;
  fmt::print("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
  fmt::print("<testsuites name=\"geomint gate\" tests=\"{}\" failures=\"{}\">\n", applied.size(),
             failures);
  for (const auto& [scene, outcomes] : by_scene) {
    int failed = 0;
    for (const GateOutcome* outcome : outcomes) failed += outcome->passed ? 0 : 1;
    fmt::print("  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\">\n", xml_escaped(scene),
               outcomes.size(), failed);
    for (const GateOutcome* outcome : outcomes) {
      const std::string name = xml_escaped(outcome->gate->name);
      const std::string message = xml_escaped(outcome_message(*outcome, verbose));
      if (outcome->passed) {
        fmt::print("    <testcase classname=\"{}\" name=\"{}\"/>\n", xml_escaped(scene), name);
      } else {
        fmt::print(
            "    <testcase classname=\"{0}\" name=\"{1}\">\n"
            "      <failure message=\"{2}\" type=\"gate\">{2}</failure>\n"
            "    </testcase>\n",
            xml_escaped(scene), name, message);
      }
    }
    fmt::print("  </testsuite>\n");
  }
  fmt::print("</testsuites>\n");
}

void print_json(const std::vector<const GateOutcome*>& applied, bool verbose) {
  fmt::print("[");
  for (std::size_t k = 0; k < applied.size(); ++k) {
    const GateOutcome& outcome = *applied[k];
    fmt::print("{}\n  {{\"scene\": \"{}\", \"gate\": \"{}\", \"passed\": {}, \"message\": \"{}\"}}",
               k == 0 ? "" : ",", json_escaped(scene_of(*outcome.gate)),
               json_escaped(outcome.gate->name), outcome.passed ? "true" : "false",
               json_escaped(outcome_message(outcome, verbose)));
  }
  fmt::print("{}]\n", applied.empty() ? "" : "\n");
}

// `geomint gate FOLDER [RESULTS...]`: a folder in the gates position stands for FOLDER/gates.toml,
// and without RESULTS for the results of FOLDER too (`geomint gate results/momentum`).
GateCliOptions resolve_folder(GateCliOptions cli) {
  std::error_code error;
  if (fs::is_directory(cli.gates_path, error)) {
    if (cli.results.empty()) cli.results.push_back(cli.gates_path);
    cli.gates_path = (fs::path(cli.gates_path) / "gates.toml").string();
    if (!fs::exists(cli.gates_path, error)) {
      throw InputError(fmt::format(
          "gate: folder given for the gates file, but '{}' does not exist (a scene's gates live "
          "in results/<scene>/gates.toml; give a gates file, then the results)",
          cli.gates_path));
    }
  } else if (cli.results.empty()) {
    throw InputError(
        fmt::format("gate: give the results to check after the gates file '{}' (scene folders "
                    "results/<scene>, results/<scene>/quick, or CSV files)",
                    cli.gates_path));
  }
  return cli;
}

// The scenes among the results that no gate applies to: said, not passed over as zero gates.
std::vector<std::string> ungated_scenes(const std::vector<ResultFile>& files,
                                        const std::vector<GateOutcome>& outcomes) {
  std::set<std::string> scenes, gated;
  for (const auto& file : files) scenes.insert(file.scene);
  for (const auto& outcome : outcomes) {
    if (!outcome.applicable) continue;
    if (outcome.gate->scene.empty()) return {};  // a gate of every scene
    gated.insert(outcome.gate->scene);
  }
  std::vector<std::string> ungated;
  for (const auto& scene : scenes) {
    if (!gated.count(scene)) ungated.push_back(scene);
  }
  return ungated;
}

int run_gate(const GateCliOptions& given, const Context& context) {
  const GateCliOptions cli = resolve_folder(given);
  const std::vector<Gate> gates = load_gates(cli.gates_path);
  const std::vector<ResultFile> files = load_result_files(cli.results);
  const auto outcomes = check_gates(gates, files);
  std::vector<const GateOutcome*> applied;
  int failed = 0;
  for (const auto& outcome : outcomes) {
    if (!outcome.applicable) continue;
    applied.push_back(&outcome);
    failed += outcome.passed ? 0 : 1;
  }
  if (applied.empty()) {
    throw InputError(fmt::format(
        "gate: none of the {} gate(s) in '{}' applies to the results given (their scenes "
        "and variants differ); nothing was checked",
        outcomes.size(), cli.gates_path));
  }
  // On stderr, so the JUnit and JSON documents on stdout stay whole.
  for (const auto& scene : ungated_scenes(files, outcomes)) {
    inform(context, fmt::format("gate: no gate of '{}' (or the files it includes) applies to "
                                "scene '{}': it has no gates file (results/{}/gates.toml)",
                                cli.gates_path, scene, scene));
  }
  if (cli.format == "junit") {
    print_junit(applied, cli.verbose);
  } else if (cli.format == "json") {
    print_json(applied, cli.verbose);
  } else {
    print_text(applied, cli.verbose, context.quiet);
    if (!context.quiet) {
      fmt::print("{} of {} gate(s) passed ({} not applicable to the scenes given)\n",
                 applied.size() - failed, applied.size(), outcomes.size() - applied.size());
    }
  }
  return failed == 0 ? kExitOk : kExitFailed;
}

}  // namespace

Verb add_gate(CLI::App& app) {
  auto options = std::make_shared<GateCliOptions>();
  auto* command = app.add_subcommand(
      "gate", "Check result CSVs against the thresholds of a gates file (exit 1 on failure)");
  command
      ->add_option("gates", options->gates_path,
                   "GATES.toml with [[gate]] blocks and/or include = [...], or a scene folder "
                   "(its gates.toml)")
      ->required();
  command->add_flag("--verbose", options->verbose,
                    "print every checked row, not only the failing ones");
  command->add_option(
      "results", options->results,
      "result CSV files (summary.csv, order.csv, ...) or scene folders "
      "(results/<scene>, results/<scene>/quick); default: the folder given as GATES");
  command
      ->add_option("--format", options->format,
                   "text (default), junit (JUnit XML: a testsuite per scene, a testcase per "
                   "gate) or json (an array of {scene, gate, passed, message})")
      ->check(CLI::IsMember({"text", "junit", "json"}));
  return {"gate", command,
          [options](const Context& context) { return run_gate(*options, context); }};
}

}  // namespace geomint::cli
