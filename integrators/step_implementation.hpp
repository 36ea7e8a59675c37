// Which step implementation ran last on this thread: a method with one step for every kind it
// runs marks that step, and the registry test (integrators/one_step_test.cpp) checks that a
// separable and a general Lagrangian problem reach the same one.
#pragma once

#include <source_location>

namespace geomint {

// The source location of the last marked step on this thread; line 0 before any.
inline thread_local std::source_location last_step_implementation{};

// Called at the top of a method's one step implementation (a store per step, no allocation).
inline void mark_step_implementation(std::source_location where = std::source_location::current()) {
  last_step_implementation = where;
}

}  // namespace geomint
