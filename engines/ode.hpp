// A planar hinge chain as ODE 0.16 bodies and hinge joints (maximal coordinates): the engine side
// of the `ode` method, exposed for the fidelity tests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engines/planar_chain.hpp"
#include "engines/rotor.hpp"
#include "integrators/integrator.hpp"

struct dxWorld;
struct dxBody;
struct dxJoint;
struct dxThreadingImplementation;

namespace geomint::engines {

struct OdeOptions {
  std::string step = "world";     // world: dWorldStep; quick: dWorldQuickStep
  bool shipped_defaults = false;  // false: CFM = ERP = 0, no damping, sleeping or clamp
};

// ODE's steppers, as the `step=` option names them.
const std::vector<std::string>& ode_steps();

class OdeChain {
 public:
  OdeChain(const PlanarChain& chain, const OdeOptions& options);
  ~OdeChain();
  OdeChain(const OdeChain&) = delete;
  OdeChain& operator=(const OdeChain&) = delete;

  // The problem's absolute angles and rates into the bodies' positions, orientations and
  // velocities, and back (the angle on the branch nearest the last one set or read).
  void set_state(const Vec& theta, const Vec& theta_dot);
  void get_state(Vec& theta, Vec& theta_dot);
  // Σ ½m|v|² + ½ωᵀIω and Σ m g z of the bodies (zero at the pivot's height).
  double kinetic() const;
  double potential() const;
  StepStatus step(double h);

 private:
  struct Link {
    dxBody* body = nullptr;
    dxJoint* joint = nullptr;
    double length = 0, near = 0, far = 0;
  };
  OdeOptions options_;
  int links_ = 0;
  dxWorld* world_ = nullptr;
  // The world's own job list: ODE's default one is shared by every world of the process and has
  // no locks, so worlds stepped on two threads at once would corrupt it.
  dxThreadingImplementation* threading_ = nullptr;
  std::vector<Link> links_data_;
  Vec angles_;
};

// One rigid body about a fixed point (engines/rotor.hpp) as an ODE body (its origin at the centre
// of mass, as ODE requires) on a ball joint at the origin; the free body has no joint. The state is
// the body's rotation and angular velocity (the pivot's drift, a joint error, is not read back).
class OdeRotor {
 public:
  OdeRotor(const Rotor& rotor, const OdeOptions& options);
  ~OdeRotor();
  OdeRotor(const OdeRotor&) = delete;
  OdeRotor& operator=(const OdeRotor&) = delete;

  void set_state(const RotorState& principal);
  RotorState get_state() const;
  // ½m|v|² + ½ωᵀRIRᵀω and m g z of the body, from ODE's own mass, pose and velocities.
  double kinetic() const;
  double potential() const;
  StepStatus step(double h);

 private:
  OdeOptions options_;
  Eigen::Vector3d centre_;  // principal frame
  dxWorld* world_ = nullptr;
  dxThreadingImplementation* threading_ = nullptr;  // the world's own job list (as OdeChain)
  dxBody* body_ = nullptr;
  dxJoint* joint_ = nullptr;
};

}  // namespace geomint::engines
