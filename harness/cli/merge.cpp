// `geomint merge SCENE_DIR`: the shards of a sharded sweep into the scene's tables
// (harness/shard.hpp); exit 1, naming what is missing, when the set is incomplete (docs/CLI.md
// "merge").
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "harness/cli/verbs.hpp"
#include "harness/paths.hpp"
#include "harness/scene.hpp"
#include "harness/shard.hpp"
#include "harness/sweep.hpp"

namespace geomint::cli {
namespace {

struct MergeCliOptions {
  std::string dir, scene;
};

int run_merge(const MergeCliOptions& cli, const Context& context) {
  namespace fs = std::filesystem;
  MergeOptions options;
  options.out_dir = cli.dir;
  const std::string variant = shards_variant(cli.dir);
  const bool quick = variant == "quick";
  options.variant = variant;
  // "results/x/quick/" names the folder quick, as "results/x/quick" does.
  fs::path dir = fs::path(cli.dir).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();
  const fs::path folder = quick ? fs::absolute(dir).parent_path() : dir;
  const std::string scene_file = !cli.scene.empty() ? cli.scene : (folder / "scene.toml").string();
  const Scene scene = load_scene(scene_file, quick);
  options.scene_hash = scene_content_hash(scene_file, quick);
  options.scene_name = fs::absolute(scene_file).parent_path().filename().string();
  // `geomint slurm --out DIR` writes its scripts into DIR, else next to the scene.
  const fs::path sbatch_in_dir = fs::path(cli.dir) / "sweep.sbatch";
  options.sbatch_path = fs::exists(sbatch_in_dir)
                            ? sbatch_in_dir.string()
                            : (fs::path(scene_file).parent_path() / "sweep.sbatch").string();
  // The command to merge again must find the scene as this one did.
  options.merge_command = fmt::format("{} merge {}", context.program, shell_quoted(cli.dir));
  if (!cli.scene.empty()) options.merge_command += " --scene " + shell_quoted(cli.scene);
  check_output_dir(cli.dir, "scene_dir");
  const SceneUnits units = scene_units(scene);
  std::vector<std::string> merged = {"table.md", "hosts.csv"};
  for (const auto& table : shard_tables(units.runs, units.orders, units.stability)) {
    merged.push_back(table + ".csv");
  }
  for (const auto& name : merged)
    check_output_file((fs::path(cli.dir) / name).string(), "scene_dir");
  try {
    merge_shards(scene, options);
  } catch (const MergeRefused& refused) {
    fmt::print(stderr, "{}: merge: {}\n", context.program, refused.what());
    return kExitFailed;
  }
  remove_stale_json_tables(cli.dir, context);
  inform(context, fmt::format("{}: merged the shards of '{}' into {}", context.program, scene.title,
                              cli.dir));
  return kExitOk;
}

}  // namespace

Verb add_merge(CLI::App& app) {
  auto options = std::make_shared<MergeCliOptions>();
  auto* command = app.add_subcommand(
      "merge",
      "Merge the shards in SCENE_DIR/shards into the scene's tables (exit 1, naming the missing "
      "or mismatched shards and the resubmission command, when the set is incomplete)");
  command->add_option("scene_dir", options->dir, "the folder a sweep writes to (results/<scene>)")
      ->required();
  command->add_option("--scene", options->scene,
                      "the scene file (default: SCENE_DIR/scene.toml, or ../scene.toml for "
                      "quick)");
  return {"merge", command,
          [options](const Context& context) { return run_merge(*options, context); }};
}

}  // namespace geomint::cli
