// A Kepler two-body orbit's relative motion, a structure interface (problems/structure.hpp)
// offered by kepler (both coordinates) and the two-body nbody, read by the lrl_err_max metric.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross

#include "problems/structure.hpp"

namespace geomint {

// The eccentricity vector e = A/(μ m) = v × (x × v)/μ − x/|x| of the relative motion x = x₂ − x₁,
// v = ẋ, μ = G(m₁ + m₂): the Laplace–Runge–Lenz vector A scaled to a pure number (|e| is the
// eccentricity, e points to the pericentre). The exact motion keeps it; only the 1/r potential
// has it, so its drift measures a method's perturbation of the orbit's shape and orientation.
class KeplerOrbitStructure {
 public:
  static constexpr StructureKey kStructureKey{
      "kepler_orbit", "Kepler orbits",
      "kepler (cartesian and polar), nbody with two bodies, which offer the relative motion"};
  virtual ~KeplerOrbitStructure() = default;
  virtual Eigen::Vector3d eccentricity_vector(const Eigen::VectorXd& q,
                                              const Eigen::VectorXd& p) const = 0;
};

// e from the relative position and velocity (3D; pad a planar one with z = 0) and μ.
inline Eigen::Vector3d eccentricity_vector(const Eigen::Vector3d& x, const Eigen::Vector3d& v,
                                           double mu) {
  return v.cross(x.cross(v)) / mu - x / x.norm();
}

}  // namespace geomint
