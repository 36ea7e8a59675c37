// A planar hinge chain as a Bullet 3.24 btMultiBody (Featherstone, reduced coordinates, double
// precision): the engine side of the `bullet` method, exposed for the fidelity tests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engines/planar_chain.hpp"
#include "integrators/integrator.hpp"

namespace geomint::engines {

struct BulletOptions {
  std::string integrator = "euler";  // euler: Bullet's default; rk4: useRK4Integration
  bool shipped_defaults = false;     // false: no damping, sleeping or velocity clamp
};

const std::vector<std::string>& bullet_integrators();

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

}  // namespace geomint::engines
