// One shard of a sharded sweep (docs/CLUSTER.md "Running on a cluster", docs/DESIGN.md §5): its id,
// the names of its files and the table a shard writes. The sweep writes shards through this module
// and `geomint merge` (harness/shard.*) reads them, so the dependency runs shard → sweep →
// shard_files and never back.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "harness/table.hpp"

namespace geomint {

struct ShardId {
  int index = 0, count = 0;  // shard index of count shards: units k with k mod count == index
};

// The largest shard count anything accepts (--shard i/N, --shards, geomint slurm, the file names
// merge reads): one cap, so no N can reach merge that a sweep would not have run.
inline constexpr int kMaxShards = 1000000;

// "i/N", as shard files' `# shard:` lines and messages write it.
std::string shard_text(ShardId id);

// <out_dir>/shards/<table>.<i>-of-<N>.csv
std::string shard_file(const std::string& out_dir, const std::string& table, ShardId id);

// The column that carries a row's unit index k in the canonical expansion order.
inline const char* const kCanonicalIndexColumn = "canonical_index";

// The tables a shard of a scene with these unit counts writes (summary; order and order_points;
// stability), whether or not the shard holds a unit of them, so completeness is file presence.
std::vector<std::string> shard_tables(size_t runs, size_t orders, size_t stability);

// Writes one shard table atomically: `lines` plus host, scene hash and `shard: i/N`, then the
// rows with their canonical index first.
void write_shard_table(const std::string& out_dir, const std::string& table, ShardId id,
                       const std::string& scene_hash, std::vector<Row> rows,
                       const std::vector<size_t>& indices, std::vector<std::string> columns,
                       std::vector<std::pair<std::string, std::string>> lines);

}  // namespace geomint
