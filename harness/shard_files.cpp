// Shard ids, file names and the shard table writer (see shard_files.hpp).
#include "harness/shard_files.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>

namespace geomint {

namespace {

std::string host_name() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "unknown";
  return name;
}

}  // namespace

std::string shard_text(ShardId id) { return fmt::format("{}/{}", id.index, id.count); }

std::string shard_file(const std::string& out_dir, const std::string& table, ShardId id) {
  return (std::filesystem::path(out_dir) / "shards" /
          fmt::format("{}.{}-of-{}.csv", table, id.index, id.count))
      .string();
}

void write_shard_table(const std::string& out_dir, const std::string& table, ShardId id,
                       const std::string& scene_hash, std::vector<Row> rows,
                       const std::vector<size_t>& indices, std::vector<std::string> columns,
                       std::vector<std::pair<std::string, std::string>> lines) {
  for (size_t r = 0; r < rows.size(); ++r) {
    rows[r][kCanonicalIndexColumn] = std::to_string(indices[r]);
  }
  columns.insert(columns.begin(), kCanonicalIndexColumn);
  lines.emplace_back("host", host_name());
  lines.emplace_back("scene_hash", scene_hash);
  lines.emplace_back("shard", shard_text(id));
  write_file_atomic(shard_file(out_dir, table, id), to_csv(rows, columns, lines));
}

std::vector<std::string> shard_tables(size_t runs, size_t orders, size_t stability) {
  std::vector<std::string> tables;
  if (runs) tables.push_back("summary");
  if (orders) tables.insert(tables.end(), {"order", "order_points"});
  if (stability) tables.push_back("stability");
  return tables;
}

}  // namespace geomint
