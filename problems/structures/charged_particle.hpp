// A charged particle's structure (../shared/MECHANICS.md §5), a structure interface
// (problems/structure.hpp) offered by charged_particle: what the Boris pusher
// (integrators/boris.cpp; Boris 1970) and the magnetic-moment metric read.
#pragma once

#include <Eigen/Core>

#include "problems/structure.hpp"

namespace geomint {

// m, q, E(x), B(x) and the vector potential A(x) that maps the canonical p = m v + qA(x) to the
// velocity and back. The Boris pusher reads and writes the state through it, and applicable()
// admits the pusher exactly where Problem::as<ChargedParticleStructure>() finds it.
class ChargedParticleStructure {
 public:
  static constexpr StructureKey kStructureKey{
      "charged_particle", "charged particles",
      "charged_particle, which offers its mass, charge, fields and vector potential"};
  virtual ~ChargedParticleStructure() = default;
  virtual double particle_mass() const = 0;
  virtual double particle_charge() const = 0;
  // The electric and magnetic fields at x.
  virtual void fields(const Eigen::Vector3d& x, Eigen::Vector3d& E, Eigen::Vector3d& B) const = 0;
  // The vector potential A(x), curl A = B: p = m v + q A(x).
  virtual Eigen::Vector3d vector_potential(const Eigen::Vector3d& x) const = 0;
};

}  // namespace geomint
