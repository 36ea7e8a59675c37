// Shared helpers of the libFuzzer targets (docs/TESTING.md "Sanitizers and fuzzing"): a private
// temporary directory for the file-based readers, removed at exit, so a fuzzer never writes
// elsewhere.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace geomint::fuzz {

// Writes `size` bytes to `name` inside this process's temporary directory (created on first use
// under $TMPDIR or /tmp, removed at exit) and returns the file's path. Aborts when the directory
// cannot be created or the file cannot be written: that is an environment error, not a finding.
std::string write_temp_file(const std::string& name, const uint8_t* data, size_t size);

// True when `text` asks for a problem larger than the fuzz budget: the product of every integer
// written as a size parameter (`n=`, `m=`, `nx=`, `ny=`, `nz=`, spaces allowed around `=`)
// exceeds kMaxFuzzProblemSize (unwritten defaults, e.g. elastic_bar ny = nz = 2, add a factor of
// a few). Building a problem is O(size) and sizes up to 10^7 degrees of
// freedom are legal (a spring_net with 9·10^6 dof takes over 10 s to build under ASan), so the
// fuzzers skip such inputs instead of reporting a timeout; their range checks are plain
// Params::integer bounds, which smaller values exercise.
inline constexpr double kMaxFuzzProblemSize = 1000;
bool requests_large_problem(const std::string& text);

}  // namespace geomint::fuzz
