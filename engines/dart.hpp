// A planar hinge chain and one rigid body about a fixed point as DART 6.12 skeletons (Featherstone,
// joint coordinates): the engine side of the `dart` method, exposed for the fidelity tests. No DART
// header is included here: DART's headers are heavy, so only engines/dart.cpp compiles them.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engines/planar_chain.hpp"
#include "engines/rotor.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"

namespace geomint::engines {

struct DartOptions {
  // world: simulation::World::step; semi_implicit_euler, euler, rk4: the dart::integration class
  // of that name driving the skeleton's own forward dynamics (docs/ENGINES.md).
  std::string integrator = "world";
  bool shipped_defaults = false;  // false: damping, springs, friction, limits written out as off
};

// The steps the `integrator=` option names: World::step and the three dart::integration classes.
const std::vector<std::string>& dart_integrators();

// DART builds a skeleton in a time that grows about like n³ with its number of bodies and in
// memory like n² (each body added resizes the skeleton's n×n caches; measured in geomint on the
// 2-core machine: 0.04 s for 256 links, 1.5 s and 0.25 GB for 1024, 11 s and 0.86 GB for 2048),
// so longer chains are refused.
constexpr int kDartMaxLinks = 1024;

struct DartModel;  // the skeleton, its world and the integrator (engines/dart.cpp)

class DartChain {
 public:
  DartChain(const PlanarChain& chain, const DartOptions& options);
  ~DartChain();
  DartChain(const DartChain&) = delete;
  DartChain& operator=(const DartChain&) = delete;

  // The problem's absolute angles and rates in, and out (DART's joints are relative angles).
  void set_state(const Vec& theta, const Vec& theta_dot);
  void get_state(Vec& theta, Vec& theta_dot) const;
  // At the state last set: DART's joint-space mass matrix (Skeleton::getMassMatrix) mapped to
  // absolute angles, and its potential and kinetic energy (computePotentialEnergy,
  // computeKineticEnergy).
  DenseMatrix mass_matrix_absolute() const;
  double potential() const;
  double kinetic() const;
  // One step of length h; an exception DART throws, or a non-finite joint state, is a failed
  // status naming it.
  StepStatus step(double h);

 private:
  std::unique_ptr<DartModel> model_;
  Vec relative_, relative_rate_;
};

// One body on a ball joint at the origin, or on a free joint for the free body (gravity off): the
// joint's positions are the rotation vector of the attitude, its velocities the angular velocity
// in the body's own (principal) frame.
class DartRotor {
 public:
  DartRotor(const Rotor& rotor, const DartOptions& options);
  ~DartRotor();
  DartRotor(const DartRotor&) = delete;
  DartRotor& operator=(const DartRotor&) = delete;

  void set_state(const RotorState& principal);
  RotorState get_state() const;
  // At the state last set: the rotational block of DART's mass matrix (the inertia about the
  // origin in the principal frame), its potential and kinetic energy.
  Eigen::Matrix3d rotational_mass_matrix() const;
  double potential() const;
  double kinetic() const;
  StepStatus step(double h);

 private:
  std::unique_ptr<DartModel> model_;
};

}  // namespace geomint::engines
