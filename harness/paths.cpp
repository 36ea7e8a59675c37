// File-system helpers (see paths.hpp).
#include "harness/paths.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cctype>
#include <filesystem>

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

// The nearest existing ancestor of `path` (the path itself when it exists) must be a writable,
// searchable folder; every missing component below it is created later.
void check_creatable_below(const std::filesystem::path& path, const std::string& option,
                           const std::string& shown) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::path existing = path.empty() ? fs::path(".") : path;
  while (!fs::exists(existing, error)) {
    if (!existing.has_parent_path() || existing.parent_path() == existing) {
      existing = ".";
      break;
    }
    existing = existing.parent_path();
  }
  if (!fs::is_directory(existing, error)) {
    throw InputError(
        fmt::format("{} '{}': '{}' is not a directory", option, shown, existing.string()));
  }
  if (::access(existing.c_str(), W_OK | X_OK) != 0) {
    throw InputError(
        fmt::format("{} '{}': folder '{}' is not writable", option, shown, existing.string()));
  }
}

}  // namespace

void check_output_file(const std::string& path, const std::string& option) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError(fmt::format("{}: empty file name", option));
  const fs::path target(path);
  std::error_code error;
  if (fs::is_directory(target, error)) {
    throw InputError(fmt::format("{} '{}' is a directory, not a file", option, path));
  }
  // Outputs are replaced by rename(2): a device or pipe (/dev/null) would be replaced, not
  // written to.
  if (fs::exists(target, error) && !fs::is_regular_file(target, error)) {
    throw InputError(fmt::format("{} '{}' is not a regular file", option, path));
  }
  check_creatable_below(target.has_parent_path() ? target.parent_path() : fs::path("."), option,
                        path);
}

void check_output_dir(const std::string& path, const std::string& option) {
  check_creatable_below(std::filesystem::path(path.empty() ? "." : path), option, path);
}

bool same_file_path(const std::string& a, const std::string& b) {
  std::error_code error;
  const auto canonical_a = std::filesystem::weakly_canonical(a, error);
  if (error) return a == b;
  const auto canonical_b = std::filesystem::weakly_canonical(b, error);
  if (error) return a == b;
  return canonical_a == canonical_b;
}

}  // namespace geomint
