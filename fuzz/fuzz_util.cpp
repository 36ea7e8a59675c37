// Temporary files for the file-based fuzz targets (fuzz_util.hpp).
#include "fuzz/fuzz_util.hpp"

#include <cctype>
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

bool requests_large_problem(const std::string& text) {
  auto is_word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  double product = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '=') continue;
    size_t key_end = i;
    while (key_end > 0 && text[key_end - 1] == ' ') --key_end;
    size_t key_begin = key_end;
    while (key_begin > 0 && is_word(text[key_begin - 1])) --key_begin;
    const std::string key = text.substr(key_begin, key_end - key_begin);
    if (key != "n" && key != "m" && key != "nx" && key != "ny" && key != "nz") continue;
    size_t j = i + 1;
    while (j < text.size() && (text[j] == ' ' || text[j] == '+')) ++j;
    double value = 0;
    for (; j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])); ++j) {
      value = 10 * value + (text[j] - '0');
    }
    if (value > 1) product *= value;
  }
  return product > kMaxFuzzProblemSize;
}

}  // namespace geomint::fuzz
