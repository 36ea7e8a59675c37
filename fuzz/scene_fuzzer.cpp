// libFuzzer target: the scene-file reader (harness/scene.*, load_scene) on arbitrary bytes, with
// and without the quick_* keys applied. Contract: a scene or InputError; any other exception,
// crash, UB report, leak or hang is a finding. Only parsing and validation run (never
// run_sweep); the bytes go to a file in the fuzzer's private temporary directory.
#include <cstdint>
#include <string>

#include "fuzz/fuzz_util.hpp"
#include "harness/scene.hpp"
#include "problems/spec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 16384) return -1;
  if (geomint::fuzz::requests_large_problem(
          std::string(reinterpret_cast<const char*>(data), size))) {
    return -1;  // a legal but large problem: over the fuzz time budget (fuzz_util.hpp)
  }
  const std::string path = geomint::fuzz::write_temp_file("scene.toml", data, size);
  for (bool quick : {false, true}) {
    try {
      geomint::load_scene(path, quick);
    } catch (const geomint::InputError&) {
    }
  }
  return 0;
}
