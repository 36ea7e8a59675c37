// The flag of methods that run on free rigid bodies only (the Lie–Poisson splitting,
// integrators/lie_poisson.cpp), the bit after MethodFlag's: applicable() admits such a method
// exactly where free_rigid_body(problem) (problems/rigid_body.hpp) finds the structure it reads,
// and the registry-driven suites leave it out of their generic test problems.
#pragma once

#include "integrators/integrator.hpp"

namespace geomint {

inline constexpr unsigned kFreeRigidBodyOnly = 1u << 12;

}  // namespace geomint
