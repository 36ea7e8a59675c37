// A planar hinge chain as a MuJoCo 2.2.2 model (MJCF generated in memory, loaded through a virtual
// file system): the engine side of the `mujoco` method, exposed for the fidelity tests.
#pragma once

#include <memory>
#include <string>

#include "engines/planar_chain.hpp"
#include "engines/rotor.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"

struct mjModel_;
struct mjData_;

namespace geomint::engines {

struct MujocoOptions {
  std::string integrator = "euler";  // mjtIntegrator: euler | rk4 | implicit
  bool shipped_defaults = false;     // false: everything the problem lacks switched off
};

// The integrators MuJoCo 2.2.2 offers (mjtIntegrator in mujoco/mjmodel.h), in its order.
const std::vector<std::string>& mujoco_integrators();

// The longest chain MuJoCo 2.2.2 loads from MJCF, measured: each link's <body> nests in its
// parent's, and its XML parser (tinyxml2) refuses a document 100 elements deep
// (XML_ELEMENT_DEPTH_EXCEEDED; 96 links nest 99 deep: <mujoco>, <worldbody>, the bodies, a joint).
// A longer chain is written as URDF, whose links and joints are siblings: MuJoCo's URDF import
// builds the same body tree (MujocoChainLength and MujocoFidelity tests).
inline constexpr int kMaxMjcfChainLinks = 96;

class MujocoChain {
 public:
  // MJCF up to kMaxMjcfChainLinks links, URDF beyond. Throws InputError when MuJoCo refuses the
  // model (its message).
  MujocoChain(const PlanarChain& chain, const MujocoOptions& options);
  ~MujocoChain();
  MujocoChain(const MujocoChain&) = delete;
  MujocoChain& operator=(const MujocoChain&) = delete;

  // The problem's absolute angles and rates in, and out.
  void set_state(const Vec& theta, const Vec& theta_dot);
  void get_state(Vec& theta, Vec& theta_dot) const;
  // At the state last set: MuJoCo's joint-space mass matrix (mj_fullM) mapped to absolute
  // angles, its potential (zero with every rod hanging down) and its kinetic energy.
  DenseMatrix mass_matrix_absolute() const;
  double potential() const;
  double kinetic() const;
  // One mj_step of length h; a warning MuJoCo raises in it (bad qacc, qpos, qvel: its
  // instability detector, which would also reset the state) is a failed status naming it.
  StepStatus step(double h);
  // p = M(θ)θ̇ in absolute angles from MuJoCo's own mass matrix at the current state, which the
  // Euler and implicit steps leave computed (they end with mj_step1 at the new state, see
  // step_model): O(nnz) and no trigonometry. False for RK4 (its mj_step leaves qM at the old
  // state): the caller then uses the problem's mass operator.
  bool momentum_absolute(Vec& p);
  // The model text MuJoCo compiled: MJCF (<mujoco ...>) or, for a long chain, URDF (<robot ...>).
  const std::string& xml() const { return xml_; }

 private:
  mjModel_* model_ = nullptr;
  mjData_* data_ = nullptr;
  std::string xml_;
  Vec relative_, relative_rate_;
  bool split_step_ = false;
};

// One rigid body about a fixed point (engines/rotor.hpp) as a MuJoCo body on a ball joint at the
// origin, or on a free joint for the free body (gravity off): qpos holds the attitude as a
// quaternion, qvel the angular velocity in the body's own (principal) frame.
class MujocoRotor {
 public:
  MujocoRotor(const Rotor& rotor, const MujocoOptions& options);
  ~MujocoRotor();
  MujocoRotor(const MujocoRotor&) = delete;
  MujocoRotor& operator=(const MujocoRotor&) = delete;

  void set_state(const RotorState& principal);
  RotorState get_state() const;
  // At the state last set: the rotational block of MuJoCo's mass matrix (mj_fullM), the inertia
  // about the origin in the principal frame; its potential and kinetic energy.
  Eigen::Matrix3d rotational_mass_matrix() const;
  double potential() const;
  double kinetic() const;
  StepStatus step(double h);
  const std::string& xml() const { return xml_; }

 private:
  mjModel_* model_ = nullptr;
  mjData_* data_ = nullptr;
  std::string xml_;
  int rotation_offset_ = 0;  // where the quaternion starts in qpos (after a free joint's position)
  int spin_offset_ = 0;      // where the angular velocity starts in qvel
};

}  // namespace geomint::engines
