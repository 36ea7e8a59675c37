// geomint command line (docs/DESIGN.md §4): list, run, order, sweep, merge, slurm, reference, gate
// (merge and slurm: README "Running on a cluster"). Exit codes:
// 0 ok, 1 a run or gate failed, 2 bad input (the message names the offending option, key or
// value; checked before any computing, outputs included), 3 an internal error (a defect, or an
// I/O failure after the up-front checks, e.g. a full disk).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "harness/gate.hpp"
#include "harness/order.hpp"
#include "harness/paths.hpp"
#include "harness/reference_generator.hpp"
#include "harness/run.hpp"
#include "harness/shard.hpp"
#include "harness/sweep.hpp"

using namespace geomint;

namespace {

constexpr int kExitFailed = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitInternal = 3;

const std::vector<std::string> kCommands = {"list",  "run",   "order",     "sweep",
                                            "merge", "slurm", "reference", "gate"};

// CLI11 says "A subcommand is required" for a missing or unknown verb; say which verbs exist.
// Returns false (message printed) when argv[1] is not an option and not a command.
bool check_command(int argc, char** argv) {
  const std::string commands = fmt::format("{}", fmt::join(kCommands, ", "));
  if (argc < 2) {
    fmt::print(stderr, "geomint: error: a command is required ({}); see geomint --help\n",
               commands);
    return false;
  }
  const std::string first = argv[1];
  if (first.empty() || first[0] != '-') {
    if (std::find(kCommands.begin(), kCommands.end(), first) == kCommands.end()) {
      fmt::print(stderr,
                 "geomint: error: unknown command '{}' (commands: {}); see geomint --help\n", first,
                 commands);
      return false;
    }
  }
  return true;
}

std::string joined_command_line(int argc, char** argv) {
  std::string out = "geomint";
  for (int i = 1; i < argc; ++i) out += std::string(" ") + argv[i];
  return out;
}

std::string parameter_list(const Params& params) {
  std::vector<std::string> parameters;
  for (const auto& doc : params.docs()) {
    parameters.push_back(fmt::format("{}={}", doc.key, doc.default_value));
  }
  return fmt::format("{}", fmt::join(parameters, ","));
}

// A Markdown table cell: '|' would end the cell.
std::string markdown_cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

// The default configuration's order, then the other orders among the variants the tests cover
// (integrators/registry.def): "2 (variants: 1)" for hp.
std::string order_column(const IntegratorEntry& entry, int default_order) {
  std::vector<int> others;
  for (const auto& variant : entry.variants) {
    const int order = make_integrator(entry.name + ":" + variant)->info().order;
    if (order != default_order && std::find(others.begin(), others.end(), order) == others.end()) {
      others.push_back(order);
    }
  }
  if (others.empty()) return std::to_string(default_order);
  std::sort(others.begin(), others.end());
  return fmt::format("{} (variants: {})", default_order, fmt::join(others, ", "));
}

// `markdown`: the README's table (README.md, between <!-- methods:begin/end -->), one row per
// registry entry; otherwise aligned columns with every parameter and its default.
void print_methods(bool markdown) {
  if (markdown) {
    fmt::print("| method | order | flags | what it is |\n|---|---|---|---|\n");
  } else {
    fmt::print("{:<22} {:>5}  {:<48} {}\n", "method", "order", "flags", "parameters (default)");
  }
  for (const auto& entry : integrator_registry()) {
    Params params(Spec{entry.name, {}}, entry.name);
    const auto integrator = entry.factory(params);
    const MethodInfo info = integrator->info();
    const std::string flags = fmt::format("{}", fmt::join(flag_names(info.flags), ", "));
    if (markdown) {
      fmt::print("| `{}` | {} | {} | {} |\n", entry.name, order_column(entry, info.order), flags,
                 markdown_cell(entry.summary));
    } else {
      fmt::print("{:<22} {:>5}  {:<48} {}\n", entry.name, info.order,
                 fmt::format("{}", fmt::join(flag_names(info.flags), ",")), parameter_list(params));
    }
  }
}

void print_problems(bool markdown) {
  if (markdown) {
    fmt::print("| problem | dof | capabilities | what it is |\n|---|---|---|---|\n");
  } else {
    fmt::print("{:<20} {:>5}  {:<58} {}\n", "problem", "dof", "capabilities (defaults)",
               "parameters (default)");
  }
  for (const auto& entry : problem_registry()) {
    Params params(Spec{entry.name, {}}, entry.name);
    const auto problem = entry.factory(params);
    const auto capabilities = capability_names(problem->capabilities());
    if (markdown) {
      fmt::print("| `{}` | {} | {} | {} |\n", entry.name, problem->dof(),
                 fmt::format("{}", fmt::join(capabilities, ", ")), markdown_cell(entry.summary));
    } else {
      fmt::print("{:<20} {:>5}  {:<58} {}\n", entry.name, problem->dof(),
                 fmt::format("{}", fmt::join(capabilities, ",")), parameter_list(params));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"geomint: verification and benchmark suite for geometric time integrators"};
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 ok; 1 a run failed (run), no order could be fitted (order) or a gate failed "
      "(gate); 2 bad input: the message names the offending option, key or value, and nothing is "
      "written (checked before any computing, outputs included); 3 internal error (\"geomint: "
      "internal error: ...\"): a defect, or an I/O failure after those checks such as a full "
      "disk. A numerical failure is a row whose status says what happened; a sweep exits 0 with "
      "its failures as rows.");

  auto* list = app.add_subcommand("list", "List registered methods and/or problems");
  std::string list_what = "all";
  list->add_option("what", list_what, "methods | problems | all")
      ->check(CLI::IsMember({"methods", "problems", "all"}));
  bool list_markdown = false;
  list->add_flag("--markdown", list_markdown,
                 "print the README's Markdown tables (methods: order, flags, summary; problems: "
                 "dof, capabilities of the defaults, summary); `make readme-tables` pastes them");

  std::string problem_spec, method_spec, out_path, series_path;
  double dt = 0, t_end = 0;
  long every = 1;
  long timing_repeats = 3;
  double diverge_factor = kDefaultDivergeFactor;
  bool series_state = false;
  const std::string diverge_help = fmt::format(
      "stop a conservative run as 'diverged' when its relative energy error exceeds this "
      "(default {:g}; 0 or inf: never)",
      kDefaultDivergeFactor);
  auto* run = app.add_subcommand("run", "Run one problem with one method and print a CSV row");
  run->add_option("--problem", problem_spec, "problem spec, e.g. pendulum:theta0=1.5")->required();
  run->add_option("--method", method_spec, "method spec, e.g. stormer_verlet")->required();
  run->add_option("--dt", dt, "step size (> 0); default: the problem's");
  run->add_option("--t-end", t_end, "horizon (> 0); default: the problem's");
  run->add_option("--out", out_path, "write the summary CSV here instead of stdout");
  run->add_option("--series", series_path, "write a time series CSV here");
  run->add_option("--every", every, "series: every N-th step point (the last is always written)");
  run->add_flag("--state", series_state, "series: include q and p even for > 64 dof");
  run->add_option("--timing-repeats", timing_repeats,
                  fmt::format("timing pass repeats (0 = none, at most {})", kMaxTimingRepeats));
  run->add_option("--diverge-factor", diverge_factor, diverge_help);
  std::vector<std::string> extra_metrics;
  run->add_option("--metric", extra_metrics,
                  "also compute an optional metric (repeatable): symplecticity_defect, "
                  "period_measured (with period_err_rel), energy_growth_exponent");
  std::string initial_path;
  const std::string initial_help =
      "start from the state in this CSV (rows q,p, or q,v under a 'q,v' header; one per dof): "
      "the problem spec key initial=FILE";
  run->add_option("--initial", initial_path, initial_help);

  double dt0 = 0;
  long levels = 6;
  auto* order = app.add_subcommand("order", "Fit the convergence order over a dt ladder");
  order->add_option("--problem", problem_spec, "problem spec")->required();
  order->add_option("--method", method_spec, "method spec")->required();
  order->add_option("--dt", dt0, "largest step dt0 (ladder dt0*2^-k)")->required();
  order->add_option(
      "--levels", levels,
      fmt::format("number of ladder levels ({}..{})", kMinOrderLevels, kMaxOrderLevels));
  order->add_option("--t-end", t_end, "horizon")->required();
  order->add_option("--out", out_path, "write the ladder runs as CSV");
  order->add_option("--diverge-factor", diverge_factor, diverge_help);
  order->add_option("--initial", initial_path, initial_help);

  std::string scene_path, sweep_out;
  int jobs = 1;
  bool quick = false;
  auto* sweep = app.add_subcommand("sweep", "Run a scene file and write its tables");
  sweep->add_option("scene", scene_path, "results/<scene>/scene.toml")->required();
  sweep->add_option("--jobs", jobs, "parallel accuracy runs")->check(CLI::Range(1, 256));
  sweep->add_flag("--quick", quick, "apply the scene's quick_* settings (CI-sized)");
  bool markdown_only = false;
  sweep->add_flag("--markdown-only", markdown_only,
                  "run nothing: rewrite table.md from the CSVs already in the output folder");
  sweep->add_option("--out", sweep_out,
                    "output folder (default: the scene's folder; with --quick: <folder>/quick)");
  bool no_timing = false, timing_only = false, shard_env = false;
  std::string shard_text;
  int shard_count = 0;
  sweep->add_flag("--no-timing", no_timing, "accuracy runs only: no timing passes, no wall_s");
  sweep->add_option("--shard", shard_text,
                    "i/N: only the units k (runs, order studies, stability searches in scene "
                    "order) with k mod N == i, written to <out>/shards/ for `geomint merge`; "
                    "implies --no-timing; a complete shard on disk is skipped");
  sweep->add_flag("--shard-from-env", shard_env,
                  "take i/N from SLURM_ARRAY_TASK_ID and --shards, or from "
                  "OMPI_COMM_WORLD_RANK/_SIZE or PMI_RANK/PMI_SIZE");
  sweep->add_option("--shards", shard_count, "N for --shard-from-env")
      ->check(CLI::Range(1, 1000000));
  sweep->add_flag("--timing-only", timing_only,
                  "run only the timing passes, one at a time, into the merged tables of the "
                  "output folder (after `geomint merge`), with this node's CPU in provenance");

  std::string merge_dir, merge_scene;
  auto* merge = app.add_subcommand(
      "merge",
      "Merge the shards in SCENE_DIR/shards into the scene's tables (exit 1, naming the missing "
      "or mismatched shards and the resubmission command, when the set is incomplete)");
  merge->add_option("scene_dir", merge_dir, "the folder a sweep writes to (results/<scene>)")
      ->required();
  merge->add_option("--scene", merge_scene,
                    "the scene file (default: SCENE_DIR/scene.toml, or ../scene.toml for quick)");

  std::string slurm_scene, slurm_partition, slurm_time;
  int slurm_shards = 0, slurm_max_parallel = 0;
  bool slurm_submit = false, slurm_quick = false;
  auto* slurm = app.add_subcommand(
      "slurm",
      "Write sweep.sbatch, merge.sbatch and timing.sbatch next to the scene (and submit them)");
  slurm->add_option("scene", slurm_scene, "results/<scene>/scene.toml")->required();
  slurm->add_option("--shards", slurm_shards, "array size N (default: min(units, 1000))")
      ->check(CLI::Range(1, 1000000));
  slurm->add_option("--max-parallel", slurm_max_parallel, "at most K array tasks at once")
      ->check(CLI::Range(1, 1000000));
  slurm->add_option("--partition", slurm_partition, "Slurm partition");
  slurm->add_option("--time", slurm_time, "time limit of each job (Slurm format, e.g. 1:00:00)");
  slurm->add_flag("--quick", slurm_quick, "the scene's CI-sized variant (into <folder>/quick)");
  slurm->add_flag("--submit", slurm_submit,
                  "submit the three scripts with sbatch, chained by --dependency=afterok");

  double reference_every = 0;
  auto* reference = app.add_subcommand(
      "reference",
      "Write a reference solution (Gauss s=3 in long double, checked at 2*dt) to "
      "results/references/<problem>.csv");
  reference->add_option("--problem", problem_spec, "problem spec")->required();
  reference->add_option("--t-end", t_end, "horizon (> 0)")->required();
  reference->add_option("--dt", dt, "step (default: the problem's default dt / 8)");
  reference->add_option("--every", reference_every,
                        "spacing of the written rows (> 0; default: t-end/100; must divide t-end)");
  reference->add_option("--out", out_path, "output file (default: results/references/...)");

  std::string gates_path;
  std::vector<std::string> gate_results;
  auto* gate = app.add_subcommand(
      "gate", "Check result CSVs against the thresholds of a gates file (exit 1 on failure)");
  gate->add_option("gates", gates_path, "GATES.toml with [[gate]] blocks")->required();
  bool gate_verbose = false;
  gate->add_flag("--verbose", gate_verbose, "print every checked row, not only the failing ones");
  gate->add_option("results", gate_results,
                   "result CSV files (summary.csv, order.csv, ...) or scene folders "
                   "(results/<scene>, results/<scene>/quick)")
      ->required();

  if (!check_command(argc, argv)) return kExitBadInput;
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForAllHelp& help) {
    return app.exit(help);
  } catch (const CLI::ParseError& error) {
    app.exit(error);
    return kExitBadInput;
  }

  const std::string command_line = joined_command_line(argc, argv);
  try {
    if (*list) {
      if (list_what != "problems") print_methods(list_markdown);
      if (list_what == "all") fmt::print("\n");
      if (list_what != "methods") print_problems(list_markdown);
      return 0;
    }
    if (!initial_path.empty()) {
      // A comma would end the spec item; the spec (and so every CSV row) records the file.
      if (initial_path.find(',') != std::string::npos) {
        throw InputError(
            fmt::format("--initial: the path '{}' may not contain a comma", initial_path));
      }
      problem_spec += (problem_spec.find(':') == std::string::npos ? ":" : ",") +
                      std::string(kInitialStateKey) + "=" + initial_path;
    }
    if (*run) {
      const auto problem = make_problem(problem_spec);
      if (timing_repeats < 0 || timing_repeats > kMaxTimingRepeats) {
        throw InputError(fmt::format("--timing-repeats must be in 0..{} (got {})",
                                     kMaxTimingRepeats, timing_repeats));
      }
      RunConfig config;
      config.dt = run->count("--dt") ? dt : problem->default_dt();
      config.t_end = run->count("--t-end") ? t_end : problem->default_t_end();
      config.series_path = series_path;
      config.series_every = every;
      config.series_state = series_state;
      config.timing_repeats = static_cast<int>(timing_repeats);
      config.diverge_factor = diverge_factor;
      config.extra_metrics = extra_metrics;
      config.command_line = command_line;
      // Outputs are checked before anything is computed.
      if (!out_path.empty()) check_output_file(out_path, "--out");
      if (!series_path.empty() && !out_path.empty() && same_file_path(series_path, out_path)) {
        throw InputError(
            fmt::format("--series and --out name the same file '{}' (the summary would overwrite "
                        "the series)",
                        out_path));
      }
      const RunResult result = run_one(problem_spec, method_spec, config);
      const std::string csv = records_to_csv({result.record}, provenance(command_line));
      if (out_path.empty()) {
        std::cout << csv;
      } else {
        write_file_atomic(out_path, csv);
      }
      if (!result.ok) {
        fmt::print(stderr, "geomint: run failed: {}: {}\n", result.record.status,
                   result.record.message.value_or(""));
      }
      return result.ok ? 0 : kExitFailed;
    }
    if (*order) {
      validate_order_study(problem_spec, method_spec, dt0, levels, t_end);
      if (!out_path.empty()) check_output_file(out_path, "--out");
      const OrderStudy study = order_study(problem_spec, method_spec, dt0, static_cast<int>(levels),
                                           t_end, diverge_factor);
      for (const auto& run_result : study.runs) {
        const Row row = to_row(run_result.record);
        fmt::print(stderr, "dt={:<12} status={:<8} error_final={}\n", row.at("dt"),
                   row.at("status"), row.count("error_final") ? row.at("error_final") : "-");
      }
      if (!out_path.empty()) {
        std::vector<RunRecord> records;
        for (const auto& run_result : study.runs) records.push_back(run_result.record);
        write_file_atomic(out_path, records_to_csv(records, provenance(command_line)));
      }
      if (!std::isfinite(study.fit.order)) {
        fmt::print(stderr, "geomint: no order fit: {}\n", study.fit.note);
        return kExitFailed;
      }
      fmt::print("{:.3f}\n", study.fit.order);
      fmt::print(stderr, "order {:.3f} (declared {}) from dt = {}{}\n", study.fit.order,
                 study.record.declared_order, to_row(study.record).at("points_used"),
                 study.fit.note.empty() ? "" : "; " + study.fit.note);
      return 0;
    }
    if (*reference) {
      if (reference->count("--every") && !(reference_every > 0)) {
        throw InputError(fmt::format("--every must be > 0 (got {}); leave it out for t-end/100",
                                     reference_every));
      }
      if (reference->count("--dt") && !(dt > 0)) {
        throw InputError(
            fmt::format("--dt must be > 0 (got {}); leave it out for the default", dt));
      }
      ReferenceOptions options;
      options.problem_spec = problem_spec;
      options.t_end = t_end;
      options.dt = dt;
      options.output_every = reference_every;
      options.out_path = out_path;
      options.command_line = command_line;
      const ReferenceSummary summary = generate_reference(options);
      fmt::print("{}\n", summary.path);
      fmt::print(stderr,
                 "reference: dt={:.6g}, {} steps, estimated error final {:.3g}, max {:.3g} "
                 "(difference to the 2*dt run), {:.1f} s\n",
                 summary.dt, summary.steps, summary.estimated_error_final,
                 summary.estimated_error_max, summary.seconds);
      return 0;
    }
    if (*gate) {
      const std::vector<Gate> gates = load_gates(gates_path);
      const auto outcomes = check_gates(gates, load_result_files(gate_results));
      int failed = 0, applicable = 0;
      for (const auto& outcome : outcomes) {
        if (!outcome.applicable) continue;
        ++applicable;
        failed += outcome.passed ? 0 : 1;
        fmt::print("{} {} ({} row(s))\n", outcome.passed ? "PASS" : "FAIL", outcome.gate->name,
                   outcome.rows_checked);
        if (!outcome.passed || gate_verbose) {
          for (const auto& line : outcome.lines) fmt::print("    {}\n", line);
        }
      }
      if (applicable == 0) {
        throw InputError(fmt::format(
            "gate: none of the {} gate(s) in '{}' applies to the results given (their scenes "
            "and variants differ); nothing was checked",
            outcomes.size(), gates_path));
      }
      fmt::print("{} of {} gate(s) passed ({} not applicable to the scenes given)\n",
                 applicable - failed, applicable, outcomes.size() - applicable);
      return failed == 0 ? 0 : kExitFailed;
    }
    if (*sweep) {
      const Scene scene = load_scene(scene_path, quick);
      SweepOptions options;
      options.jobs = jobs;
      options.command_line = command_line;
      const auto folder = std::filesystem::path(scene_path).parent_path();
      options.out_dir = !sweep_out.empty() ? sweep_out
                        : quick            ? (folder / "quick").string()
                                           : folder.string();
      // Gates select tables by scene and variant (harness/gate.hpp): the scene is the folder
      // that holds scene.toml, whatever --out says.
      options.scene_name = std::filesystem::absolute(scene_path).parent_path().filename().string();
      options.variant = quick ? "quick" : "full";
      check_output_dir(options.out_dir, sweep_out.empty() ? "output folder" : "--out");
      if (markdown_only) {
        rewrite_scene_markdown(scene, options.out_dir);
        return 0;
      }
      if (timing_only) {
        if (no_timing || !shard_text.empty() || shard_env) {
          throw InputError(
              "--timing-only runs only the timing passes: leave out --no-timing, "
              "--shard and --shard-from-env");
        }
        run_timing_only(scene, options);
        fmt::print(stderr, "geomint: timing passes of '{}' written into {}\n", scene.title,
                   options.out_dir);
        return 0;
      }
      options.timing = !no_timing;
      if (!shard_text.empty() || shard_env) {
        if (!shard_text.empty() && shard_env) {
          throw InputError("give either --shard i/N or --shard-from-env, not both");
        }
        const ShardId id = shard_env ? shard_from_env(shard_count) : parse_shard(shard_text);
        options.shard_index = id.index;
        options.shard_count = id.count;
        options.scene_hash = scene_content_hash(scene_path, quick);
        const SceneUnits units = scene_units(scene);
        const auto tables = shard_tables(units.runs, units.orders, units.stability);
        if (shard_complete(options.out_dir, tables, id, options.scene_hash)) {
          fmt::print(stderr, "geomint: shard {}/{} of '{}' is complete on disk; skipped\n",
                     id.index, id.count, scene.title);
          return 0;
        }
        if (shard_fails_on_purpose(id)) {
          fmt::print(stderr, "geomint: GEOMINT_FAIL_SHARD={}: shard {}/{} fails on purpose\n",
                     id.index, id.index, id.count);
          return kExitFailed;
        }
      } else if (shard_count) {
        throw InputError("--shards N goes with --shard-from-env");
      }
      const int failed = run_sweep(scene, options);
      fmt::print(stderr, "geomint: sweep '{}' done: {} failed run(s) reported as rows in {}\n",
                 scene.title, failed, options.out_dir);
      return 0;
    }
    if (*merge) {
      MergeOptions options;
      options.out_dir = merge_dir;
      const std::string variant = shards_variant(merge_dir);
      const bool merge_quick = variant == "quick";
      options.variant = variant;
      namespace fs = std::filesystem;
      // "results/x/quick/" names the folder quick, as "results/x/quick" does.
      fs::path dir = fs::path(merge_dir).lexically_normal();
      if (dir.filename().empty()) dir = dir.parent_path();
      const fs::path folder = merge_quick ? fs::absolute(dir).parent_path() : dir;
      const std::string scene_file =
          !merge_scene.empty() ? merge_scene : (folder / "scene.toml").string();
      const Scene scene = load_scene(scene_file, merge_quick);
      options.scene_hash = scene_content_hash(scene_file, merge_quick);
      options.scene_name = fs::absolute(scene_file).parent_path().filename().string();
      options.sbatch_path = (fs::path(scene_file).parent_path() / "sweep.sbatch").string();
      check_output_dir(merge_dir, "scene_dir");
      try {
        merge_shards(scene, options);
      } catch (const MergeRefused& refused) {
        fmt::print(stderr, "geomint: merge: {}\n", refused.what());
        return kExitFailed;
      }
      fmt::print(stderr, "geomint: merged the shards of '{}' into {}\n", scene.title, merge_dir);
      return 0;
    }
    if (*slurm) {
      const Scene scene = load_scene(slurm_scene, slurm_quick);
      SlurmOptions options;
      options.scene_path = slurm_scene;
      options.quick = slurm_quick;
      options.shards =
          slurm_shards ? slurm_shards
                       : static_cast<int>(std::clamp<size_t>(scene_units(scene).total(), 1, 1000));
      options.max_parallel = slurm_max_parallel;
      options.partition = slurm_partition;
      options.time_limit = slurm_time;
      options.geomint_path = std::filesystem::canonical("/proc/self/exe").string();
      check_output_dir(std::filesystem::absolute(slurm_scene).parent_path().string(),
                       "scene folder");
      const auto scripts = write_slurm_scripts(options);
      for (const auto& path : scripts) fmt::print("{}\n", path);
      if (slurm_submit) {
        std::string dependency;
        for (const auto& path : scripts) {
          const std::string id = submit_sbatch(path, dependency);
          fmt::print(stderr, "geomint: submitted {} as job {}\n", path, id);
          dependency = id;
        }
      }
      return 0;
    }
  } catch (const InputError& error) {
    fmt::print(stderr, "geomint: error: {}\n", error.what());
    return kExitBadInput;
  } catch (const std::exception& error) {
    fmt::print(stderr, "geomint: internal error: {}\n", error.what());
    return kExitInternal;
  } catch (...) {
    fmt::print(stderr, "geomint: internal error: an exception of unknown type\n");
    return kExitInternal;
  }
  return 0;
}
