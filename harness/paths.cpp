// File-system helpers (see paths.hpp).
#include "harness/paths.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "problems/spec.hpp"

namespace geomint {

std::string sanitize_for_path(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-';
    if (keep) {
      out += c;
    } else if (out.empty() || out.back() != '_') {
      out += '_';
    }
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out;
}

namespace {

namespace fs = std::filesystem;

// What the atomic writer appends to a file name for its temporary, ".<pid>.<n>.h<tag>.tmp"
// (harness/table.cpp), at its longest: a name is only writable when that one fits too.
constexpr std::size_t kTemporarySuffix = 42;

// A path for a message: a 100 kB path is not printed whole, but its start and its end (the
// file name the message is about) are, so a deep working folder (a CI runner's TMPDIR) does not
// cut the name off.
std::string shown_path(const std::string& path) {
  constexpr std::size_t kHead = 120, kTail = 120;
  if (path.size() <= kHead + kTail) return path;
  return fmt::format("{}...{} ({} bytes)", path.substr(0, kHead), path.substr(path.size() - kTail),
                     path.size());
}

// Creates and removes a file in `folder`: the one test that answers "can a file be written
// here" for /proc, /sys, read-only mounts and root alike (access(2) says yes to root on a
// read-only folder and asks nothing of /proc).
void probe_folder(const fs::path& folder, const std::string& option, const std::string& shown) {
  static std::atomic<unsigned long> counter{0};
  const fs::path probe = folder / fmt::format(".geomint-probe.{}.{}.tmp", ::getpid(), counter++);
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    const int error = errno;
    throw InputError(fmt::format("{} '{}': no file can be created in folder '{}' ({})", option,
                                 shown_path(shown), shown_path(folder.string()),
                                 std::strerror(error)));
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

// The nearest existing ancestor of `folder` (the folder itself when it exists) must be a folder
// in which a file can be created, and every missing component below it, and `leaf` (a file to
// be written there; may be empty), a name its file system allows; the missing folders are
// created later. A path longer than PATH_MAX is refused in one pass over its bytes before any
// component is looked at (walking up a long path one parent_path() at a time is quadratic in
// its length); below that bound the components are walked once, from the start.
void check_creatable_below(const fs::path& folder, const std::string& leaf,
                           const std::string& option, const std::string& shown) {
  if (shown.size() + kTemporarySuffix >= PATH_MAX) {
    throw InputError(fmt::format("{} '{}': the path is {} bytes long; at most {} are allowed",
                                 option, shown_path(shown), shown.size(),
                                 PATH_MAX - 1 - kTemporarySuffix));
  }
  std::error_code error;
  fs::path existing = folder.is_absolute() ? folder.root_path() : fs::path();
  std::vector<std::string> missing;
  for (const auto& component : folder.relative_path()) {
    if (missing.empty() && fs::exists(existing / component, error)) {
      existing /= component;
    } else {
      missing.push_back(component.string());
    }
  }
  if (existing.empty()) existing = ".";
  if (!fs::is_directory(existing, error)) {
    throw InputError(fmt::format("{} '{}': '{}' is not a directory", option, shown_path(shown),
                                 shown_path(existing.string())));
  }
  long name_max = ::pathconf(existing.c_str(), _PC_NAME_MAX);
  if (name_max <= 0) name_max = NAME_MAX;
  const auto check_name = [&](const std::string& name, std::size_t extra) {
    if (name.size() + extra > static_cast<std::size_t>(name_max)) {
      throw InputError(fmt::format(
          "{} '{}': the name '{}' is {} bytes long; this file system allows {}{}", option,
          shown_path(shown), shown_path(name), name.size(), name_max,
          extra ? fmt::format(", less {} for the temporary file written first", extra) : ""));
    }
  };
  for (const auto& name : missing) check_name(name, 0);
  // An existing file is replaced by a new one written next to it: its name needs the room too.
  if (!leaf.empty()) check_name(leaf, kTemporarySuffix);
  probe_folder(existing, option, shown);
}

}  // namespace

void check_output_file(const std::string& path, const std::string& option) {
  if (path.empty()) throw InputError(fmt::format("{}: empty file name", option));
  const fs::path target(path);
  std::error_code error;
  if (fs::is_directory(target, error)) {
    throw InputError(fmt::format("{} '{}' is a directory, not a file", option, shown_path(path)));
  }
  // Outputs are replaced by rename(2): a device or pipe (/dev/null) would be replaced, not
  // written to.
  if (fs::exists(target, error) && !fs::is_regular_file(target, error)) {
    throw InputError(fmt::format("{} '{}' is not a regular file", option, shown_path(path)));
  }
  if (target.filename().empty()) {
    throw InputError(fmt::format("{} '{}' names a folder, not a file", option, shown_path(path)));
  }
  check_creatable_below(target.parent_path(), target.filename().string(), option, path);
}

void check_output_dir(const std::string& path, const std::string& option) {
  check_creatable_below(fs::path(path.empty() ? "." : path), "", option, path);
}

bool same_file_path(const std::string& a, const std::string& b) {
  std::error_code error;
  // Both exist: the same inode is the same file, whatever the spelling (a symbolic link, a hard
  // link, "..").
  if (fs::exists(a, error) && fs::exists(b, error)) {
    const bool same = fs::equivalent(a, b, error);
    if (!error) return same;
  }
  // Otherwise the file each would become: "s.csv" and "./s.csv" name the same one, which
  // weakly_canonical sees only from absolute paths.
  const auto canonical_a = fs::weakly_canonical(fs::absolute(a, error), error);
  if (error) return a == b;
  const auto canonical_b = fs::weakly_canonical(fs::absolute(b, error), error);
  if (error) return a == b;
  return canonical_a == canonical_b;
}

}  // namespace geomint
