// Reference solutions for problems without an exact solution (issue 5): Gauss–Legendre
// collocation, s = 3 (order 6; Hairer–Lubich–Wanner, GNI §II.1.3), with a long double state and
// a Kahan-compensated update, checked against an independent run at twice the step.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "harness/observers.hpp"
#include "problems/problem.hpp"

namespace geomint {

// Rows of one reference file (all are held in memory until written).
constexpr double kMaxReferenceRows = 1e6;

struct ReferenceOptions {
  std::string problem_spec;
  double t_end = 0;          // horizon (> 0) from the problem's initial time
  double dt = 0;             // step of the written run; 0 = default_dt / 8
  double output_every = 0;   // spacing of the written rows; 0 = t_end / 100
  std::string out_path;      // empty = reference_path(kReferenceDir, problem_spec)
  std::string command_line;  // for the provenance lines
};

struct ReferenceSummary {
  std::string path;
  double dt = 0;
  long steps = 0;
  double estimated_error_final = 0;  // ‖y_dt − y_2dt‖₂ at t_end
  double estimated_error_max = 0;    // max of that over the written rows
  double seconds = 0;
};

// Where the harness looks for references, relative to the working directory (the repository
// root for the CLI and scripts/reproduce.sh).
inline constexpr const char* kReferenceDir = "results/references";

// <dir>/<sanitized canonical problem spec>.csv
std::string reference_path(const std::string& dir, const std::string& problem_spec);

// Runs the reference and its check run, writes the CSV. InputError on bad options; a run whose
// stage iteration does not converge throws InputError suggesting a smaller --dt.
ReferenceSummary generate_reference(const ReferenceOptions& options);

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
