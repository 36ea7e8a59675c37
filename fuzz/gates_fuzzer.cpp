// libFuzzer target: the gates-file reader (harness/gate.*, load_gates) on arbitrary bytes.
// Contract: gates or InputError; any other exception, crash, UB report, leak or hang is a
// finding. The bytes go to a file in the fuzzer's private temporary directory.
#include <cstdint>
#include <string>

#include "fuzz/fuzz_util.hpp"
#include "harness/gate.hpp"
#include "problems/spec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 16384) return -1;
  const std::string path = geomint::fuzz::write_temp_file("gates.toml", data, size);
  try {
    geomint::load_gates(path);
  } catch (const geomint::InputError&) {
  }
  return 0;
}
