// A planar hinge chain as a Bullet 3.24 btMultiBody (Featherstone, reduced coordinates, double
// precision): the engine side of the `bullet` method, exposed for the fidelity tests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engines/planar_chain.hpp"
#include "engines/rotor.hpp"
#include "integrators/integrator.hpp"

namespace geomint::engines {

struct BulletOptions {
  std::string integrator = "euler";  // euler: Bullet's default; rk4: useRK4Integration
  bool shipped_defaults = false;     // false: no damping, sleeping or velocity clamp
  // The btRigidBody's gyroscopic term (the free body only): none, explicit, implicit_body
  // (Bullet's default), implicit_world.
  std::string gyro = "implicit_body";
  // Whether the spec wrote gyro= (a btMultiBody refuses it even at the default value: it has no
  // such term).
  bool gyro_given = false;
};

const std::vector<std::string>& bullet_integrators();
const std::vector<std::string>& bullet_gyroscopic_modes();

class BulletChain {
 public:
  BulletChain(const PlanarChain& chain, const BulletOptions& options);
  ~BulletChain();
  BulletChain(const BulletChain&) = delete;
  BulletChain& operator=(const BulletChain&) = delete;

  void set_state(const Vec& theta, const Vec& theta_dot);
  void get_state(Vec& theta, Vec& theta_dot) const;
  // Σ m g z of the links' centres of mass from Bullet's own kinematics (zero at the pivot).
  double potential() const;
  // Σ ½m|v|² with each link's centre-of-mass velocity from Bullet's kinematics (a central
  // difference of localPosToWorld along the joint rates: btMultiBody has no energy getter).
  double kinetic();
  StepStatus step(double h);

 private:
  struct World;
  std::unique_ptr<World> world_;
  Vec relative_, relative_rate_;
};

// One rigid body about a fixed point (engines/rotor.hpp): a btMultiBody with a fixed base at the
// origin and one spherical link (spherical_pendulum, heavy_top), or, for the free body, a
// btRigidBody in a btDiscreteDynamicsWorld with the chosen gyroscopic term and no gravity.
class BulletRotor {
 public:
  BulletRotor(const Rotor& rotor, const BulletOptions& options);
  ~BulletRotor();
  BulletRotor(const BulletRotor&) = delete;
  BulletRotor& operator=(const BulletRotor&) = delete;

  void set_state(const RotorState& principal);
  RotorState get_state() const;
  // ½ΩᵀJΩ from Bullet's own link mass, inertia and centre (btMultiBody) or ½ωᵀI_world ω from its
  // world inertia tensor (btRigidBody); m g z of the centre of mass from Bullet's kinematics.
  double kinetic() const;
  double potential() const;
  StepStatus step(double h);

 private:
  struct World;
  std::unique_ptr<World> world_;
};

}  // namespace geomint::engines
