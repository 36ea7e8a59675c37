// Reference solutions for problems without an exact solution (docs/METHOD.md): where
// the files live, the loader, and the observer that measures a run's error against them. The
// files are written by harness/reference_generator.hpp.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "harness/observers.hpp"
#include "problems/problem.hpp"

namespace geomint {

// Where the harness looks for references, relative to the working directory (the repository
// root for the CLI and scripts/reproduce.sh).
inline constexpr const char* kReferenceDir = "results/references";

// <dir>/<sanitized canonical problem spec>.csv
std::string reference_path(const std::string& dir, const Problem& problem);

// A loaded reference: rows (t, q, p) at the output times.
struct ReferenceSolution {
  std::string path;
  std::string problem_spec;
  double estimated_error = 0;  // estimated_error_max from the file
  std::vector<double> times;
  std::vector<Vec> q, p;
  // Index of the row at time t (within 1e-9 relative), or -1.
  int row_at(double t) const;
};

// Parses a reference file for `problem` (canonical spec must match, columns t, q_i, p_i, finite
// numbers, increasing times). Missing or malformed files throw InputError naming the file.
std::shared_ptr<const ReferenceSolution> load_reference(const std::string& path,
                                                        const Problem& problem);

// error_max, error_final: ‖(q_k − q_ref, p_k − p_ref)‖₂ at the step points that land on a
// reference row (within 1e-9 relative in t). error_final is the error at t_end, which the caller
// ensures is a reference row; error_max is the maximum over the matched step points only.
std::unique_ptr<Observer> make_reference_observer(
    std::shared_ptr<const ReferenceSolution> reference);

}  // namespace geomint
