// Shared helpers of the libFuzzer targets (README "Sanitizers and fuzzing"): a private temporary
// directory for the file-based readers, removed at exit, so a fuzzer never writes elsewhere.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace geomint::fuzz {

// Writes `size` bytes to `name` inside this process's temporary directory (created on first use
// under $TMPDIR or /tmp, removed at exit) and returns the file's path. Aborts when the directory
// cannot be created or the file cannot be written: that is an environment error, not a finding.
std::string write_temp_file(const std::string& name, const uint8_t* data, size_t size);

}  // namespace geomint::fuzz
