// Output folder lock and scene check (see output_folder.hpp).
#include "harness/output_folder.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "harness/paths.hpp"
#include "problems/spec.hpp"

namespace geomint {

namespace fs = std::filesystem;

namespace {

std::string host_name() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "unknown";
  return name;
}

// The `# scene:` provenance line of a table, or "" (no such line, not readable). Only the
// leading comment lines are read: a table of a large sweep is not read whole.
std::string table_scene(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line.rfind("# ", 0) == 0) {
    if (line.rfind("# scene: ", 0) == 0) return line.substr(9);
  }
  return "";
}

// The scene of a series file: the folder holding the scene file its `# command:` line ran
// (`geomint sweep results/x/scene.toml ...` → x), or "".
std::string series_scene(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line.rfind("# ", 0) == 0) {
    if (line.rfind("# command: ", 0) != 0) continue;
    try {
      // The first *.toml word after `sweep`; a scene named without its folder says nothing.
      const auto words = shell_words(line.substr(11));
      const auto sweep = std::find(words.begin(), words.end(), "sweep");
      for (auto word = sweep; word != words.end(); ++word) {
        const fs::path scene = fs::path(*word).lexically_normal();
        if (scene.extension() != ".toml") continue;
        const fs::path folder = scene.parent_path().filename();
        return folder.empty() || folder == "." || folder == ".." ? "" : folder.string();
      }
    } catch (const InputError&) {
    }
    return "";
  }
  return "";
}

}  // namespace

OutputFolderLock::OutputFolderLock(const std::string& folder, Mode mode, const std::string& what)
    : path_((fs::path(folder) / ".geomint.lock").string()), mode_(mode) {
  fs::create_directories(folder);
  const int operation = (mode == Mode::kExclusive ? LOCK_EX : LOCK_SH) | LOCK_NB;
  // A holder that leaves unlinks the file: a lock taken on an unlinked file locks nothing, so
  // the file locked must still be the one under the name.
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
      throw InputError(fmt::format("output folder '{}': cannot create its lock file '{}' ({})",
                                   folder, path_, std::strerror(errno)));
    }
    if (::flock(fd, operation) != 0) {
      const int error = errno;
      if (error == ENOLCK || error == ENOSYS || error == EINVAL) {
        ::close(fd);
        return;  // no flock on this file system: written unlocked, as before locks existed
      }
      std::string holder;
      {
        std::ifstream in(path_);
        std::getline(in, holder);
      }
      ::close(fd);
      throw InputError(fmt::format(
          "output folder '{}' is in use by {} (lock file '{}'): two sweeps or merges into one "
          "folder would mix their tables; wait for it to end or use another folder (--out)",
          folder, holder.empty() ? "another geomint" : holder, path_));
    }
    struct stat locked {
    }, named{};
    if (::fstat(fd, &locked) != 0 || ::stat(path_.c_str(), &named) != 0 ||
        locked.st_ino != named.st_ino || locked.st_dev != named.st_dev) {
      ::close(fd);
      continue;
    }
    const std::string holder =
        fmt::format("{} (pid {} on host {})\n", what, ::getpid(), host_name());
    if (::ftruncate(fd, 0) != 0 ||
        ::pwrite(fd, holder.data(), holder.size(), 0) != static_cast<ssize_t>(holder.size())) {
      // The name of the holder is a courtesy for the message above; the lock holds without it.
    }
    fd_ = fd;
    return;
  }
  throw InputError(
      fmt::format("output folder '{}': its lock file '{}' keeps being replaced", folder, path_));
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ < 0) return;
  // The file goes with its last holder: a shard that cannot take it exclusively leaves it to
  // the others still sharing it (a left file is harmless: the lock is the flock, not the file).
  if (mode_ == Mode::kExclusive || ::flock(fd_, LOCK_EX | LOCK_NB) == 0) ::unlink(path_.c_str());
  ::close(fd_);
}

void check_folder_scene(const std::string& folder, const std::string& scene_name) {
  if (scene_name.empty()) return;
  std::error_code error;
  if (!fs::is_directory(folder, error)) return;
  const auto refuse = [&](const fs::path& path, const std::string& other) {
    throw InputError(fmt::format(
        "output folder '{}' holds results of scene '{}' ({}); this is scene '{}': its tables "
        "would be written over the other scene's results. Give each scene its own folder "
        "(--out) or remove the other scene's files first",
        folder, other, path.string(), scene_name));
  };
  const auto check_table = [&](const fs::path& path) {
    if (!fs::is_regular_file(path, error)) return;
    const std::string other = table_scene(path);
    if (!other.empty() && other != scene_name) refuse(path, other);
  };
  for (const char* table : {"summary.csv", "order.csv", "order_points.csv", "stability.csv"}) {
    check_table(fs::path(folder) / table);
  }
  const fs::path shards = fs::path(folder) / "shards";
  if (fs::is_directory(shards, error)) {
    for (fs::directory_iterator it(shards, error), end; !error && it != end; it.increment(error)) {
      if (it->path().extension() == ".csv") check_table(it->path());
    }
  }
  // Series: one file per series folder tells whose they are (a sweep writes a folder whole).
  const fs::path series = fs::path(folder) / "series";
  if (!fs::is_directory(series, error)) return;
  for (fs::directory_iterator block(series, error), end; !error && block != end;
       block.increment(error)) {
    if (!block->is_directory(error)) continue;
    std::error_code inner;
    for (fs::directory_iterator it(block->path(), inner), stop; !inner && it != stop;
         it.increment(inner)) {
      if (it->path().extension() != ".csv" || !it->is_regular_file(inner)) continue;
      const std::string other = series_scene(it->path());
      if (!other.empty() && other != scene_name) refuse(it->path(), other);
      break;
    }
  }
}

}  // namespace geomint
