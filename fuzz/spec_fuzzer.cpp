// libFuzzer target: spec strings (problems/spec.*, docs/DESIGN.md §2) through the problem and
// method registries, make_problem and make_integrator. Contract: arbitrary text either yields an
// object or throws InputError; any other exception, crash, UB report, leak or hang is a finding.
// For accepted specs the canonical spec must be a fixed point (re-parsing it gives the same text),
// and the problem's initial state must have dof() entries; nothing is integrated. Problems
// larger than the fuzz budget are not built (fuzz_util.hpp, requests_large_problem).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_util.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"

namespace {

[[noreturn]] void fail(const char* what, const std::string& a, const std::string& b) {
  std::fprintf(stderr, "spec_fuzzer: %s\n  first:  %s\n  second: %s\n", what, a.c_str(), b.c_str());
  std::abort();
}

void check_problem(const std::string& text) {
  std::unique_ptr<geomint::Problem> problem;
  try {
    problem = geomint::make_problem(text);
  } catch (const geomint::InputError&) {
    return;
  }
  const std::string canonical = problem->spec();
  const std::string again = geomint::make_problem(canonical)->spec();
  if (again != canonical) fail("problem canonical spec is not a fixed point", canonical, again);
  const geomint::State state = problem->initial_state();
  if (state.q.size() != problem->dof() || state.p.size() != problem->dof()) {
    fail("initial state size differs from dof()", canonical, std::to_string(problem->dof()));
  }
}

void check_integrator(const std::string& text) {
  std::unique_ptr<geomint::Integrator> integrator;
  try {
    integrator = geomint::make_integrator(text);
  } catch (const geomint::InputError&) {
    return;
  }
  const std::string canonical = integrator->spec();
  const std::string again = geomint::make_integrator(canonical)->spec();
  if (again != canonical) fail("method canonical spec is not a fixed point", canonical, again);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 4096) return -1;  // specs are short; longer inputs only slow the search down
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (!geomint::fuzz::requests_large_problem(text)) check_problem(text);
  check_integrator(text);
  return 0;
}
