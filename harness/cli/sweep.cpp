// `geomint sweep SCENE`: a scene file's runs, order studies and stability searches into its
// tables (harness/sweep.hpp), whole, as one shard (i/N) or as its timing passes alone; failed
// runs are rows, so a finished sweep exits 0 (docs/CLI.md "sweep").
#include "harness/sweep.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "harness/cli/verbs.hpp"
#include "harness/paths.hpp"
#include "harness/scene.hpp"
#include "harness/shard.hpp"
#include "harness/table.hpp"

namespace geomint::cli {
namespace {

struct SweepCliOptions {
  std::string scene_path, out;
  std::string format = "csv";
  int jobs = 1;
  bool quick = false, markdown_only = false, no_timing = false, timing_only = false;
  std::string shard_text;
  bool shard_from_env = false;
  int shard_count = 0;
  double progress_interval = 10;
};

// The scene tables --format json writes beside their CSVs.
constexpr const char* kJsonTables[] = {"summary", "order", "order_points", "stability"};

// summary.json, order.json, ... beside each of those CSVs in `out_dir`, each the CSV as written
// read back (so both hold the same cells) and each written atomically; series files stay CSV.
void write_json_tables(const std::string& out_dir) {
  for (const char* table : kJsonTables) {
    const auto csv = std::filesystem::path(out_dir) / (std::string(table) + ".csv");
    if (!std::filesystem::is_regular_file(csv)) continue;
    const auto json = std::filesystem::path(out_dir) / (std::string(table) + ".json");
    write_file_atomic(json.string(), to_json(read_csv_file(csv.string())));
  }
}

}  // namespace

// A CSV rewritten without --format json leaves an earlier run's JSON beside it holding other
// numbers: remove it, so that a folder's JSON tables are always its CSVs'.
void remove_stale_json_tables(const std::string& out_dir, const Context& context) {
  for (const char* table : kJsonTables) {
    const auto json = std::filesystem::path(out_dir) / (std::string(table) + ".json");
    if (!std::filesystem::is_regular_file(json)) continue;
    std::filesystem::remove(json);
    inform(context, fmt::format("{}: removed {}: its CSV was rewritten without --format json",
                                context.program, json.string()));
  }
}

namespace {

int run_sweep_verb(const SweepCliOptions& cli, const Context& context) {
  const bool json = parse_table_format(cli.format, "--format") == TableFormat::kJson;
  const bool sharded = !cli.shard_text.empty() || cli.shard_from_env;
  if (json && sharded) {
    throw InputError(
        "--format json: a shard's tables stay CSV for `geomint merge`; after the merge, "
        "`geomint sweep SCENE --markdown-only --format json` writes the JSON tables");
  }
  const Scene scene = load_scene(cli.scene_path, cli.quick);
  SweepOptions options;
  options.jobs = cli.jobs;
  options.progress_interval = cli.progress_interval;
  options.progress = !context.quiet;
  options.command_line = context.command_line;
  const auto folder = std::filesystem::path(cli.scene_path).parent_path();
  options.out_dir = !cli.out.empty() ? cli.out
                    : cli.quick      ? (folder / "quick").string()
                                     : folder.string();
  // Gates select tables by scene and variant (harness/gate.hpp): the scene is the folder that
  // holds scene.toml, whatever --out says.
  options.scene_name = std::filesystem::absolute(cli.scene_path).parent_path().filename().string();
  options.variant = cli.quick ? "quick" : "full";
  // table.md's "How to cite" block names it; a shard's provenance carries it for merge.
  options.scene_hash = scene_content_hash(cli.scene_path, cli.quick);
  const std::string out_option = cli.out.empty() ? "output folder" : "--out";
  check_output_dir(options.out_dir, out_option);
  const auto out_file = [&](const char* name) {
    return (std::filesystem::path(options.out_dir) / name).string();
  };
  if (cli.markdown_only || cli.timing_only) check_output_file(out_file("table.md"), out_option);
  if (cli.timing_only) check_output_file(out_file("summary.csv"), out_option);
  if (json) {
    for (const char* table : kJsonTables) {
      check_output_file(out_file((std::string(table) + ".json").c_str()), out_option);
    }
  }
  if (cli.markdown_only) {
    rewrite_scene_markdown(scene, options);
    if (json) write_json_tables(options.out_dir);
    return kExitOk;
  }
  if (cli.timing_only) {
    if (cli.no_timing || sharded) {
      throw InputError(
          "--timing-only runs only the timing passes: leave out --no-timing, "
          "--shard and --shard-from-env");
    }
    run_timing_only(scene, options);
    if (json) {
      write_json_tables(options.out_dir);
    } else {
      remove_stale_json_tables(options.out_dir, context);
    }
    inform(context, fmt::format("{}: timing passes of '{}' written into {}", context.program,
                                scene.title, options.out_dir));
    return kExitOk;
  }
  options.timing = !cli.no_timing;
  if (sharded) {
    if (!cli.shard_text.empty() && cli.shard_from_env) {
      throw InputError("give either --shard i/N or --shard-from-env, not both");
    }
    const ShardId id =
        cli.shard_from_env ? shard_from_env(cli.shard_count) : parse_shard(cli.shard_text);
    options.shard_index = id.index;
    options.shard_count = id.count;
    const SceneUnits units = scene_units(scene);
    if (static_cast<size_t>(id.count) > units.total()) {
      // Merge refuses such a set: shards past the last unit would hold nothing.
      throw InputError(
          fmt::format("--shard {}/{}: the scene has {} unit(s) (runs, order studies, stability "
                      "searches); use at most that many shards",
                      id.index, id.count, units.total()));
    }
    const auto tables = shard_tables(units.runs, units.orders, units.stability);
    if (shard_complete(options.out_dir, tables, id, options.scene_hash)) {
      inform(context, fmt::format("{}: shard {}/{} of '{}' is complete on disk; skipped",
                                  context.program, id.index, id.count, scene.title));
      return kExitOk;
    }
    if (shard_fails_on_purpose(id)) {
      fmt::print(stderr, "{}: GEOMINT_FAIL_SHARD={}: shard {}/{} fails on purpose\n",
                 context.program, id.index, id.index, id.count);
      return kExitFailed;
    }
  } else if (cli.shard_count) {
    throw InputError("--shards N goes with --shard-from-env");
  }
  const int failed = run_sweep(scene, options);
  if (json) {
    write_json_tables(options.out_dir);
  } else if (!sharded) {
    remove_stale_json_tables(options.out_dir, context);
  }
  inform(context, fmt::format("{}: sweep '{}' done: {} failed run(s) reported as rows in {}",
                              context.program, scene.title, failed, options.out_dir));
  return kExitOk;
}

}  // namespace

Verb add_sweep(CLI::App& app) {
  auto options = std::make_shared<SweepCliOptions>();
  auto* command = app.add_subcommand("sweep", "Run a scene file and write its tables");
  command->add_option("scene", options->scene_path, "results/<scene>/scene.toml")->required();
  command->add_option("--jobs", options->jobs, "parallel accuracy runs")
      ->check(integer_range(1, 256));
  command->add_flag("--quick", options->quick, "apply the scene's quick_* settings (CI-sized)");
  command->add_flag("--markdown-only", options->markdown_only,
                    "run nothing: rewrite table.md from the CSVs already in the output folder");
  command->add_option("--out", options->out,
                      "output folder (default: the scene's folder; with --quick: <folder>/quick)");
  command->add_option("--format", options->format,
                      "csv (default) or json: json also writes summary.json, order.json, "
                      "order_points.json and stability.json beside the CSVs (the same cells; "
                      "docs/schema/table.schema.json); series files stay CSV");
  command->add_flag("--no-timing", options->no_timing,
                    "accuracy runs only: no timing passes, no wall_s");
  command->add_option("--shard", options->shard_text,
                      "i/N: only the units k (runs, order studies, stability searches in scene "
                      "order) with k mod N == i, written to <out>/shards/ for `geomint merge`; "
                      "implies --no-timing; a complete shard on disk is skipped");
  command->add_flag("--shard-from-env", options->shard_from_env,
                    "take i/N from SLURM_ARRAY_TASK_ID and --shards, or from "
                    "OMPI_COMM_WORLD_RANK/_SIZE or PMI_RANK/PMI_SIZE");
  command
      ->add_option("--shards", options->shard_count,
                   "N for --shard-from-env (default: none, the environment's size)")
      ->check(integer_range(1, kMaxShards));
  command->add_flag("--timing-only", options->timing_only,
                    "run only the timing passes, one at a time, into the merged tables of the "
                    "output folder (after `geomint merge`), with this node's CPU in provenance");
  command
      ->add_option("--progress-interval", options->progress_interval,
                   "seconds between the heartbeat lines printed when stderr is not a terminal "
                   "(a log): done/total runs and an ETA weighted by expected steps; default 10, or "
                   "$GEOMINT_PROGRESS_INTERVAL")
      ->envname("GEOMINT_PROGRESS_INTERVAL")
      ->check(finite_range(0.01, 86400.0));
  return {"sweep", command,
          [options](const Context& context) { return run_sweep_verb(*options, context); }};
}

}  // namespace geomint::cli
