// Temporary files for the file-based fuzz targets (fuzz_util.hpp).
#include "fuzz/fuzz_util.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace geomint::fuzz {
namespace {

// Never destroyed: the exit handler that removes the directory needs the path after static
// destructors have run.
const std::string& temp_dir() {
  static const std::string* dir = [] {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base && *base ? base : "/tmp") + "/geomint-fuzz-XXXXXX";
    if (!::mkdtemp(pattern.data())) {
      std::perror("geomint fuzz: mkdtemp");
      std::abort();
    }
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(temp_dir(), ignored);
    });
    return new std::string(pattern);
  }();
  return *dir;
}

}  // namespace

std::string write_temp_file(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = temp_dir() + "/" + name;
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file || (size > 0 && std::fwrite(data, 1, size, file) != size) || std::fclose(file) != 0) {
    std::perror("geomint fuzz: writing the input file");
    std::abort();
  }
  return path;
}

}  // namespace geomint::fuzz
