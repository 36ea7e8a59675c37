// Which BLAS is in use (see blas.hpp).
#include "harness/blas.hpp"

#include <link.h>

#include <filesystem>
#include <string_view>

namespace geomint {
namespace {

constexpr const char* kAlternativesLink = "/etc/alternatives/libblas.so.3-x86_64-linux-gnu";

int find_loaded_blas(struct dl_phdr_info* info, std::size_t, void* out) {
  const std::string_view name = info->dlpi_name != nullptr ? info->dlpi_name : "";
  if (name.find("libblas.so") == std::string_view::npos &&
      name.find("libopenblas") == std::string_view::npos) {
    return 0;
  }
  *static_cast<std::string*>(out) = std::string(name);
  return 1;
}

}  // namespace

BlasInUse blas_in_use() {
  std::string path;
  dl_iterate_phdr(find_loaded_blas, &path);
  if (path.empty()) path = kAlternativesLink;
  std::error_code error;
  const std::filesystem::path resolved = std::filesystem::canonical(path, error);
  const std::string where = error ? path : resolved.string();
  BlasInUse blas;
  std::string family = "unknown";
  if (where.find("openblas") != std::string::npos) {
    family = "openblas";
  } else if (where.find("blis") != std::string::npos) {
    family = "blis";
  } else if (where.find("atlas") != std::string::npos) {
    family = "atlas";
  } else if (where.find("mkl") != std::string::npos) {
    family = "mkl";
  } else if (where.find("/blas/") != std::string::npos) {
    family = "reference";
    blas.reference = true;
  }
  blas.description = family + " (" + where + ")";
  return blas;
}

void add_blas_provenance(std::vector<std::pair<std::string, std::string>>& lines) {
  const BlasInUse blas = blas_in_use();
  lines.emplace_back("blas", blas.description);
  if (blas.reference) {
    lines.emplace_back("warning",
                       "reference BLAS: linear_solver=cholmod factorises about 10x slower; install "
                       "libopenblas-dev (scripts/install-deps.sh)");
  }
}

}  // namespace geomint
