// The charged particle's structure, kept as a header of its own for the code that includes it:
// the interface is problems/structures/charged_particle.hpp.
#pragma once

#include "problems/problem.hpp"
#include "problems/structures/charged_particle.hpp"

namespace geomint {

// The structure `problem` offers, or nullptr (every other problem); a charged particle started
// from an `initial=` file keeps it. Compatibility shim for Problem::as<ChargedParticleStructure>().
inline const ChargedParticleStructure* charged_particle_structure(const Problem& problem) {
  return problem.as<ChargedParticleStructure>();
}

}  // namespace geomint
