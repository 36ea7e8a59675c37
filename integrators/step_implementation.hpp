// Which step implementation ran last on this thread: a method with one step for every kind it
// runs marks that step, and the registry test (integrators/one_step_test.cpp) checks that a
// separable and a general Lagrangian problem reach the same one.
#pragma once

namespace geomint {

// Where a step was marked. Not std::source_location: clang 14 (the sanitizer build's compiler)
// cannot compile libstdc++ 12's; the __builtin_FILE/LINE/FUNCTION defaults it rests on are in both
// gcc and clang.
struct StepLocation {
  const char* file_name = "";
  int line = 0;  // 0: nothing marked
  const char* function_name = "";
};

// The last marked step on this thread; line 0 before any.
inline thread_local StepLocation last_step_implementation{};

// Called at the top of a method's one step implementation (a store per step, no allocation).
inline void mark_step_implementation(const char* file_name = __builtin_FILE(),
                                     int line = __builtin_LINE(),
                                     const char* function_name = __builtin_FUNCTION()) {
  last_step_implementation = StepLocation{file_name, line, function_name};
}

}  // namespace geomint
