// What the example adds to geomint's registries (docs/VERIFY.md "Verify your own integrator"): call
// both before geomint::run_main or the verify checks.
#pragma once

namespace user {
void register_methods();   // user_position_verlet, user_stale_verlet, user_general_midpoint
void register_problems();  // user_quartic (quartic_oscillator.cpp)
inline void register_all() {
  register_methods();
  register_problems();
}
}  // namespace user
