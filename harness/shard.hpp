// Sweeps beyond one machine (docs/CLUSTER.md "Running on a cluster", docs/DESIGN.md §3, §5): shard
// ids from the command line or the environment, the provenance a shard carries, `geomint merge`
// (tables byte-identical to a single-machine sweep) and the Slurm scripts of `geomint slurm`.
// Shard ids, file names and the shard writer the sweep uses are in shard_files.hpp.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "harness/scene.hpp"
#include "harness/shard_files.hpp"
#include "harness/table.hpp"

namespace geomint {

// "i/N" with 0 <= i < N (InputError naming --shard otherwise).
ShardId parse_shard(const std::string& text);

// The shard of this process from the environment (`--shard-from-env`): SLURM_ARRAY_TASK_ID with
// `count` (the count written into sweep.sbatch; a resubmitted --array=3 sees a task count of 1),
// else OMPI_COMM_WORLD_RANK/OMPI_COMM_WORLD_SIZE or PMI_RANK/PMI_SIZE (mpirun, srun). `count`
// 0 means not given. InputError naming the variables when none is set or they disagree.
ShardId shard_from_env(int count);

// Hash of the scene file's bytes and the variant ("fnv1a64:<16 hex digits>"): the shards of one
// merge must come from the same scene text. InputError when the file cannot be read.
std::string scene_content_hash(const std::string& scene_path, bool quick);

// The command of the single-machine sweep a merge reproduces: the shard command without
// --shard, --shard-from-env and --shards, with --no-timing (a shard is never timed).
std::string merged_sweep_command(const std::string& shard_command);

// True when every table of the shard is on disk with this binary's version, this scene hash and
// this shard id: a rerun (a requeued array task) then has nothing to do.
bool shard_complete(const std::string& out_dir, const std::vector<std::string>& tables, ShardId id,
                    const std::string& scene_hash);

// Test hook of `make test-cluster`: a sharded sweep whose index equals GEOMINT_FAIL_SHARD exits
// 1 without writing, as a crashed node would.
bool shard_fails_on_purpose(ShardId id);

// `geomint merge`: refused (exit 1) because shards are missing, of another scene or version, or
// duplicated; what() names the files and ends with the resubmission command.
class MergeRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct MergeOptions {
  std::string out_dir;      // the folder holding shards/; receives the tables and hosts.csv
  std::string scene_hash;   // of the scene file as it is now
  std::string scene_name;   // `# scene:` line
  std::string variant;      // `# variant:` line (shards_variant())
  std::string sbatch_path;  // sweep.sbatch named by the resubmission command
  // The `geomint merge ...` command a refusal tells to run again (with --scene when the folder
  // alone does not find the scene); empty: `geomint merge <out_dir>`.
  std::string merge_command;
};

// The variant (`full`/`quick`) the shards in <out_dir>/shards were run with; InputError when
// the folder holds no shard.
std::string shards_variant(const std::string& out_dir);

// Checks that <out_dir>/shards holds exactly one complete matching set of shards of `scene`, then
// writes summary.csv, order.csv, order_points.csv, stability.csv and table.md byte-identical to
// `geomint sweep --no-timing` (date line aside) and hosts.csv (shard, host, cpu, date).
void merge_shards(const Scene& scene, const MergeOptions& options);

// `geomint slurm`: sweep.sbatch (array of `count` shards, at most max_parallel at once,
// --requeue), merge.sbatch and timing.sbatch (--exclusive, srun --cpu-bind=cores), written next
// to the scene file, or with out_dir into out_dir, which then also receives the shards, the
// tables and slurm-logs/. Returns their paths in submission order.
struct SlurmOptions {
  std::string scene_path, geomint_path;
  std::string out_dir;  // empty: scripts next to the scene, results in its folder (or quick/)
  bool quick = false;
  int shards = 0, max_parallel = 0;  // max_parallel 0: no limit
  std::string partition, time_limit;
  int jobs = 1;  // --jobs of each shard (cpus-per-task)
};
std::vector<std::string> write_slurm_scripts(const SlurmOptions& options);

// `sbatch --parsable [--dependency=afterok:<after>] <script>`; returns the job id. InputError
// when sbatch cannot be run or refuses the script (its message included).
std::string submit_sbatch(const std::string& script, const std::string& after);

}  // namespace geomint
