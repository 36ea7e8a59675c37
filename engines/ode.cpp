// The `ode` method: the Open Dynamics Engine's own world step (dWorldStep, or dWorldQuickStep's
// iterative solver) on the planar chain a problem is, in maximal coordinates: one rigid body per
// rod, hinge joints, the state read back from the bodies as the problem's (θ, p = M(θ)θ̇).
#include "engines/ode.hpp"

#include <fmt/format.h>
#include <ode/ode.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdarg>
#include <mutex>
#include <numbers>

#include "engines/engine_method.hpp"

namespace geomint::engines {
namespace {

// ODE reports errors and debug messages through global handlers whose default aborts the
// process; the handlers keep the text (per thread) and the step turns it into a failed status.
thread_local std::string last_ode_message;
void record_ode_message(int errnum, const char* format, va_list arguments) {
  char text[512];
  std::vsnprintf(text, sizeof text, format, arguments);
  last_ode_message = fmt::format("ODE message {}: {}", errnum, text);
}

// ODE is initialised once per process and its per-thread data once per thread (sweeps build
// chains on worker threads).
void init_ode_for_this_thread() {
  static std::once_flag once;
  std::call_once(once, [] {
    dInitODE2(0);
    dSetMessageHandler(&record_ode_message);
    dSetErrorHandler(&record_ode_message);
    dSetDebugHandler(&record_ode_message);
  });
  thread_local const bool allocated = dAllocateODEDataForThread(dAllocateMaskAll) != 0;
  (void)allocated;
}

// dWorldQuickStep visits the joints in an order drawn from ODE's one global random generator, so
// two runs of the same spec would differ in the last bits. Each quick step reseeds it first, under
// a lock that keeps concurrent runs from sharing the sequence: a run is then a function of its
// spec (a row re-run from its method spec reproduces it).
std::mutex quick_step_mutex;
constexpr unsigned long kQuickStepSeed = 0;

// A world with gravity g along −z; clean: hard joints (CFM = 0) without the Baumgarte correction
// (ERP = 0), which feeds position errors back as velocity; no damping, sleeping or speed clamp
// (their defaults, written out). The world steps on its own job list (`threading`, freed with
// it by destroy_world): ODE's default one is shared by every world of the process and has no
// locks, so worlds stepped on two threads at once (a sweep's workers) would corrupt it.
dxWorld* make_world(double gravity, const OdeOptions& options,
                    dxThreadingImplementation*& threading) {
  init_ode_for_this_thread();
  dxWorld* world = dWorldCreate();
  threading = dThreadingAllocateSelfThreadedImplementation();
  dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(threading),
                                       threading);
  dWorldSetGravity(world, 0, 0, -gravity);
  if (!options.shipped_defaults) {
    dWorldSetCFM(world, 0);
    dWorldSetERP(world, 0);
    dWorldSetAutoDisableFlag(world, 0);
    dWorldSetLinearDamping(world, 0);
    dWorldSetAngularDamping(world, 0);
    dWorldSetMaxAngularSpeed(world, dInfinity);
  }
  return world;
}

void destroy_world(dxWorld* world, dxThreadingImplementation* threading) {
  if (world != nullptr) dWorldDestroy(world);
  if (threading != nullptr) dThreadingFreeImplementation(threading);
}

StepStatus step_world(dxWorld* world, const OdeOptions& options, double h) {
  last_ode_message.clear();
  int ok = 0;
  if (options.step == "quick") {
    const std::lock_guard<std::mutex> lock(quick_step_mutex);
    dRandSetSeed(kQuickStepSeed);
    ok = dWorldQuickStep(world, h);
  } else {
    ok = dWorldStep(world, h);
  }
  if (!ok || !last_ode_message.empty()) {
    return StepStatus::failure("ode_step", last_ode_message.empty()
                                               ? std::string("ODE's step returned failure")
                                               : last_ode_message);
  }
  return StepStatus::success();
}

// ODE's dMatrix3 is row-major with a stride of 4.
Eigen::Matrix3d from_ode(const dReal* R) {
  Eigen::Matrix3d out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out(i, j) = R[4 * i + j];
  return out;
}

}  // namespace

const std::vector<std::string>& ode_steps() {
  static const std::vector<std::string> names = {"world", "quick"};
  return names;
}

// Rod i carries the point masses of the chain as two end masses: `near` at node i − 1 and `far`
// at node i. Node i's mass is split half and half between the rods that meet there (the last
// node's is all on the last rod); the pivot end of rod 1 gets a mass too, which moves nothing and
// gives rod 1 a positive rotational inertia. Each body's kinetic and potential energy is then
// exactly that of its share of the point masses: the chain is the problem's, not an
// approximation (tested).
OdeChain::OdeChain(const PlanarChain& chain, const OdeOptions& options)
    : options_(options), links_(chain.links()) {
  world_ = make_world(chain.gravity, options, threading_);
  for (int i = 0; i < links_; ++i) {
    Link link;
    link.length = chain.length[i];
    link.far = i + 1 < links_ ? chain.mass[i] / 2 : chain.mass[i];
    link.near = i == 0 ? link.far : chain.mass[i - 1] / 2;
    const double total = link.near + link.far;
    // About the centre of mass: near·far/total·l² perpendicular to the rod; the rod axis gets the
    // same (a hinge chain never turns about it).
    const double inertia = link.near * link.far / total * link.length * link.length;
    dMass mass;
    dMassSetParameters(&mass, total, 0, 0, 0, inertia, inertia, inertia, 0, 0, 0);
    link.body = dBodyCreate(world_);
    dBodySetMass(link.body, &mass);
    link.joint = dJointCreateHinge(world_, nullptr);
    dJointAttach(link.joint, link.body, i == 0 ? nullptr : links_data_.back().body);
    links_data_.push_back(link);
  }
  set_state(Vec::Zero(links_), Vec::Zero(links_));
}

OdeChain::~OdeChain() { destroy_world(world_, threading_); }

void OdeChain::set_state(const Vec& theta, const Vec& theta_dot) {
  double node_x = 0, node_z = 0, node_vx = 0, node_vz = 0;
  for (int i = 0; i < links_; ++i) {
    Link& link = links_data_[i];
    const double s = std::sin(theta[i]), c = std::cos(theta[i]);
    const double to_centre = link.far / (link.near + link.far) * link.length;
    dMatrix3 rotation;
    dRFromAxisAndAngle(rotation, 0, -1, 0, theta[i]);
    dBodySetRotation(link.body, rotation);
    dBodySetPosition(link.body, node_x + to_centre * s, 0, node_z - to_centre * c);
    dBodySetLinearVel(link.body, node_vx + to_centre * theta_dot[i] * c, 0,
                      node_vz + to_centre * theta_dot[i] * s);
    dBodySetAngularVel(link.body, 0, -theta_dot[i], 0);
    // The joint sits at node i − 1; its axis −y turns the rod towards +x for θ > 0.
    dJointSetHingeAnchor(link.joint, node_x, 0, node_z);
    dJointSetHingeAxis(link.joint, 0, -1, 0);
    node_x += link.length * s;
    node_z -= link.length * c;
    node_vx += link.length * theta_dot[i] * c;
    node_vz += link.length * theta_dot[i] * s;
  }
  angles_ = theta;
}

void OdeChain::get_state(Vec& theta, Vec& theta_dot) {
  theta.resize(links_);
  theta_dot.resize(links_);
  dVector3 previous{0, 0, 0, 0}, previous_velocity{0, 0, 0, 0};
  for (int i = 0; i < links_; ++i) {
    const Link& link = links_data_[i];
    const double to_far = -link.near / (link.near + link.far) * link.length;
    dVector3 node, velocity;
    dBodyGetRelPointPos(link.body, 0, 0, to_far, node);
    dBodyGetRelPointVel(link.body, 0, 0, to_far, velocity);
    const double rx = node[0] - previous[0], rz = node[2] - previous[2];
    const double vx = velocity[0] - previous_velocity[0], vz = velocity[2] - previous_velocity[2];
    // The angle of the rod as it moved: the branch of atan2 nearest the previous angle, so whole
    // turns are kept.
    const double raw = std::atan2(rx, -rz);
    theta[i] = raw + 2 * std::numbers::pi * std::round((angles_[i] - raw) / (2 * std::numbers::pi));
    const double c = std::cos(theta[i]), s = std::sin(theta[i]);
    theta_dot[i] = (vx * c + vz * s) / std::hypot(rx, rz);
    for (int k = 0; k < 3; ++k) previous[k] = node[k], previous_velocity[k] = velocity[k];
  }
  angles_ = theta;
}

double OdeChain::kinetic() const {
  double energy = 0;
  for (const Link& link : links_data_) {
    dMass mass;
    dBodyGetMass(link.body, &mass);
    const dReal* v = dBodyGetLinearVel(link.body);
    const dReal* w = dBodyGetAngularVel(link.body);
    // The inertia is isotropic, so ωᵀIω needs no rotation to the world frame.
    energy += 0.5 * mass.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
              0.5 * mass.I[0] * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  }
  return energy;
}

double OdeChain::potential() const {
  dVector3 gravity;
  dWorldGetGravity(world_, gravity);
  double energy = 0;
  for (const Link& link : links_data_) {
    dMass mass;
    dBodyGetMass(link.body, &mass);
    energy -= mass.mass * gravity[2] * dBodyGetPosition(link.body)[2];
  }
  return energy;
}

StepStatus OdeChain::step(double h) { return step_world(world_, options_, h); }

OdeRotor::OdeRotor(const Rotor& rotor, const OdeOptions& options)
    : options_(options), centre_(rotor.principal_centre) {
  world_ = make_world(rotor.gravity, options, threading_);
  Eigen::Vector3d I = rotor.principal_moments;
  double total = rotor.mass;
  const bool point_mass =
      rotor.kind == Rotor::Kind::kSpherical || rotor.kind == Rotor::Kind::kSphericalAngles;
  if (point_mass) {
    // As for the chains: the bob's rod carries a second mass m at the pivot, which never moves, so
    // the body (2m at the rod's middle, inertia (m/2)L² about it) has exactly the bob's energies
    // and a rotational inertia of the bob's order: a near-zero one (the other engines' 1e-14·mL²)
    // leaves dWorldQuickStep's iteration without convergence. The same inertia about the rod's own
    // axis is never excited: no force or torque turns a symmetric body about it.
    centre_ = rotor.principal_centre / 2;
    total = 2 * rotor.mass;
    I.setConstant(rotor.mass / 2 * rotor.principal_centre.squaredNorm());
  }
  dMass mass;
  dMassSetParameters(&mass, total, 0, 0, 0, I[0], I[1], I[2], 0, 0, 0);
  body_ = dBodyCreate(world_);
  dBodySetMass(body_, &mass);
  if (!rotor.free()) {
    joint_ = dJointCreateBall(world_, nullptr);
    dJointAttach(joint_, body_, nullptr);
  }
  set_state(RotorState{});
}

OdeRotor::~OdeRotor() { destroy_world(world_, threading_); }

void OdeRotor::set_state(const RotorState& principal) {
  const Eigen::Matrix3d& Q = principal.attitude;
  const Eigen::Vector3d omega = Q * principal.omega;  // ODE's angular velocity is spatial
  const Eigen::Vector3d position = Q * centre_;
  const Eigen::Vector3d velocity = omega.cross(position);
  dMatrix3 rotation;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) rotation[4 * i + j] = Q(i, j);
    rotation[4 * i + 3] = 0;
  }
  dBodySetRotation(body_, rotation);
  dBodySetPosition(body_, position[0], position[1], position[2]);
  dBodySetLinearVel(body_, velocity[0], velocity[1], velocity[2]);
  dBodySetAngularVel(body_, omega[0], omega[1], omega[2]);
  if (joint_ != nullptr) dJointSetBallAnchor(joint_, 0, 0, 0);
}

RotorState OdeRotor::get_state() const {
  RotorState state;
  state.attitude = from_ode(dBodyGetRotation(body_));
  const dReal* w = dBodyGetAngularVel(body_);
  state.omega = state.attitude.transpose() * Eigen::Vector3d(w[0], w[1], w[2]);
  return state;
}

double OdeRotor::kinetic() const {
  dMass mass;
  dBodyGetMass(body_, &mass);
  const Eigen::Matrix3d R = from_ode(dBodyGetRotation(body_));
  const Eigen::Matrix3d I_body = from_ode(mass.I);
  const dReal* v = dBodyGetLinearVel(body_);
  const dReal* w = dBodyGetAngularVel(body_);
  const Eigen::Vector3d omega(w[0], w[1], w[2]);
  return 0.5 * mass.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
         0.5 * omega.dot(R * I_body * R.transpose() * omega);
}

double OdeRotor::potential() const {
  dVector3 gravity;
  dWorldGetGravity(world_, gravity);
  dMass mass;
  dBodyGetMass(body_, &mass);
  return -mass.mass * gravity[2] * dBodyGetPosition(body_)[2];
}

StepStatus OdeRotor::step(double h) { return step_world(world_, options_, h); }

namespace {

class OdeMethod final : public EngineMethod<OdeChain, OdeRotor, OdeOptions> {
 public:
  explicit OdeMethod(OdeOptions options) : EngineMethod(std::move(options), "ODE") {}

  MethodInfo info() const override {
    return {"ode", 1, kImplicit | kGeneralLagrangian,
            options_.step == "quick" ? "ODE 0.16 dWorldQuickStep (projected Gauss–Seidel)"
                                     : "ODE 0.16 dWorldStep (dense LCP)"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "a maximal-coordinate step with a constraint solve: no linear theory in the problem's "
        "coordinates");
  }
};

}  // namespace
}  // namespace geomint::engines

namespace geomint {

std::unique_ptr<Integrator> make_ode(Params& params) {
  engines::OdeOptions options;
  options.step = params.choice("step", "world", engines::ode_steps(),
                               "world: dWorldStep (dense LCP); quick: dWorldQuickStep (iterative)");
  options.shipped_defaults =
      params.choice("defaults", "clean", {"clean", "shipped"},
                    "clean: CFM = ERP = 0, no damping or sleeping; shipped: ODE's own defaults "
                    "(ERP 0.2, CFM 1e-10)") == "shipped";
  return std::make_unique<engines::OdeMethod>(std::move(options));
}

}  // namespace geomint
