// `geomint slurm SCENE`: sweep.sbatch (an array of shards), merge.sbatch and timing.sbatch next
// to the scene (harness/shard.hpp), optionally submitted as a dependency chain (docs/CLI.md
// "slurm").
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "harness/cli/verbs.hpp"
#include "harness/paths.hpp"
#include "harness/scene.hpp"
#include "harness/shard.hpp"
#include "harness/sweep.hpp"

namespace geomint::cli {
namespace {

struct SlurmCliOptions {
  std::string scene, partition, time, out;
  int shards = 0, max_parallel = 0;
  bool submit = false, quick = false;
};

// True when an executable `name` is in one of $PATH's folders: what the shell's lookup finds.
bool on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::string folders = path ? path : "";
  for (std::size_t start = 0; start <= folders.size();) {
    const std::size_t colon = std::min(folders.find(':', start), folders.size());
    const std::string folder = colon == start ? "." : folders.substr(start, colon - start);
    if (::access((folder + "/" + name).c_str(), X_OK) == 0) return true;
    start = colon + 1;
  }
  return false;
}

int run_slurm(const SlurmCliOptions& cli, const Context& context) {
  // --submit without sbatch would leave the scripts written and then fail: refuse before writing.
  if (cli.submit && !on_path("sbatch")) {
    throw InputError(
        "--submit: sbatch is not on PATH (run on a Slurm login node, or leave out --submit to "
        "only write the scripts)");
  }
  const Scene scene = load_scene(cli.scene, cli.quick);
  SlurmOptions options;
  options.scene_path = cli.scene;
  options.quick = cli.quick;
  const size_t units = scene_units(scene).total();
  if (static_cast<size_t>(cli.shards) > units) {
    throw InputError(fmt::format(
        "--shards {}: the scene has {} unit(s); use at most that many shards", cli.shards, units));
  }
  options.shards = cli.shards ? cli.shards : static_cast<int>(std::clamp<size_t>(units, 1, 1000));
  options.max_parallel = cli.max_parallel;
  options.partition = cli.partition;
  options.time_limit = cli.time;
  options.geomint_path = std::filesystem::canonical("/proc/self/exe").string();
  options.out_dir = cli.out;
  if (cli.out.empty()) {
    check_output_dir(std::filesystem::absolute(cli.scene).parent_path().string(), "scene folder");
  } else {
    check_output_dir(cli.out, "--out");
  }
  const auto scripts = write_slurm_scripts(options);
  for (const auto& path : scripts) fmt::print("{}\n", path);
  if (cli.submit) {
    std::string dependency;
    for (const auto& path : scripts) {
      const std::string id = submit_sbatch(path, dependency);
      inform(context, fmt::format("{}: submitted {} as job {}", context.program, path, id));
      dependency = id;
    }
  }
  return kExitOk;
}

}  // namespace

Verb add_slurm(CLI::App& app) {
  auto options = std::make_shared<SlurmCliOptions>();
  auto* command = app.add_subcommand(
      "slurm",
      "Write sweep.sbatch, merge.sbatch and timing.sbatch next to the scene (and submit them)");
  command->add_option("scene", options->scene, "results/<scene>/scene.toml")->required();
  command->add_option("--shards", options->shards, "array size N (default: min(units, 1000))")
      ->check(integer_range(1, kMaxShards));
  command
      ->add_option("--max-parallel", options->max_parallel,
                   "at most K array tasks at once (default: no limit)")
      ->check(integer_range(1, 1000000));
  command->add_option("--partition", options->partition, "Slurm partition");
  command->add_option("--time", options->time,
                      "time limit of each job (Slurm format, e.g. 1:00:00)");
  command->add_option("--out", options->out,
                      "folder of the scripts, shards, logs and merged tables (default: scripts "
                      "next to the scene, results in its folder or <folder>/quick)");
  command->add_flag("--quick", options->quick,
                    "the scene's CI-sized variant (into <folder>/quick)");
  command->add_flag("--submit", options->submit,
                    "submit the three scripts with sbatch, chained by --dependency=afterok");
  return {"slurm", command,
          [options](const Context& context) { return run_slurm(*options, context); }};
}

}  // namespace geomint::cli
