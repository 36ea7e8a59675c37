// The charged particle's structure (../shared/MECHANICS.md §5, charged particle): what the Boris
// pusher (integrators/boris.cpp; Boris 1970) reads — m, q, E(x), B(x) and the vector potential
// A(x) that maps the canonical p = m v + qA(x) to the velocity and back.
#pragma once

#include <Eigen/Core>

#include "problems/problem.hpp"

namespace geomint {

// Offered by charged_particle only. The Boris pusher reads and writes the state through it, and
// applicable() admits the pusher exactly where charged_particle_structure() finds it.
class ChargedParticleStructure {
 public:
  virtual ~ChargedParticleStructure() = default;
  virtual double particle_mass() const = 0;
  virtual double particle_charge() const = 0;
  // The electric and magnetic fields at x.
  virtual void fields(const Eigen::Vector3d& x, Eigen::Vector3d& E, Eigen::Vector3d& B) const = 0;
  // The vector potential A(x), curl A = B: p = m v + q A(x).
  virtual Eigen::Vector3d vector_potential(const Eigen::Vector3d& x) const = 0;
};

// The structure `problem` offers, or nullptr (every other problem); a charged particle started
// from an `initial=` file keeps it. Compatibility shim for Problem::as_charged_particle().
inline const ChargedParticleStructure* charged_particle_structure(const Problem& problem) {
  return problem.as_charged_particle();
}

}  // namespace geomint
