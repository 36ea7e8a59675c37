// The BLAS that CHOLMOD's dense supernodes run on (docs/METHODS.md "Scale"; docs/DESIGN.md §5
// provenance): Debian selects libblas.so.3 through update-alternatives, so the CSV provenance
// records where that link resolves, and warns when it is the reference BLAS (10× slower
// factorisations).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace geomint {

struct BlasInUse {
  std::string description;  // "openblas (/usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3)"
  bool reference = false;   // Debian's unoptimised reference BLAS (package libblas3)
};

// The libblas.so.3 this process loaded (else the Debian alternatives link it would load).
BlasInUse blas_in_use();

// Appends `blas: <description>` to CSV provenance lines, and a `warning:` line when only the
// reference BLAS is present.
void add_blas_provenance(std::vector<std::pair<std::string, std::string>>& lines);

}  // namespace geomint
