// Reference generator for problems without an exact solution: Gauss–Legendre
// collocation, s = 3 (order 6; Hairer–Lubich–Wanner, GNI §II.1.3), with a long double state and
// a Kahan-compensated update, checked against an independent run at twice the step.
#pragma once

#include <string>

#include "harness/reference.hpp"

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

// Runs the reference and its check run, writes the CSV. InputError on bad options; a run whose
// stage iteration does not converge throws InputError suggesting a smaller --dt.
ReferenceSummary generate_reference(const ReferenceOptions& options);

}  // namespace geomint
