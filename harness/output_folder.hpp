// One writer and one scene per output folder (docs/CLUSTER.md "Shared file systems"): a sweep,
// shard or merge locks the folder it writes and refuses a folder holding another scene's results.
#pragma once

#include <string>

namespace geomint {

// An flock(2) on <folder>/.geomint.lock for the lifetime of the object. A sweep, a merge and a
// timing pass hold it exclusively; the shards of one sharded sweep share it (they write disjoint
// files), so a sweep or merge cannot run into a folder while shards write there, nor the
// reverse. Taking it never waits: a folder in use is an InputError naming the holder (PID, host
// and verb, as the holder wrote them into the file). The last holder removes the file. A file
// system without flock support (ENOLCK, ENOSYS) is written unlocked.
class OutputFolderLock {
 public:
  enum class Mode { kExclusive, kShared };
  // `what` names the holder in the file ("sweep", "shard 3/8", "merge").
  OutputFolderLock(const std::string& folder, Mode mode, const std::string& what);
  ~OutputFolderLock();
  OutputFolderLock(const OutputFolderLock&) = delete;
  OutputFolderLock& operator=(const OutputFolderLock&) = delete;

 private:
  std::string path_;
  Mode mode_;
  int fd_ = -1;
};

// InputError naming both scenes when <folder> holds tables (summary.csv, order.csv,
// order_points.csv, stability.csv, shards/*.csv: their `# scene:` line) or series (series/**.csv:
// the scene file of their `# command:` line) of a scene other than `scene_name`. An empty
// scene_name (a library caller that names none) checks nothing.
void check_folder_scene(const std::string& folder, const std::string& scene_name);

}  // namespace geomint
