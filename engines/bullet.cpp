// The `bullet` method: Bullet's own btMultiBody step (Featherstone's articulated-body algorithm in
// joint coordinates) on the planar chain a problem is, its state read back as (θ, p = M(θ)θ̇).
#include "engines/bullet.hpp"

#include <BulletCollision/CollisionShapes/btEmptyShape.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <utility>

#include "engines/engine_method.hpp"

namespace geomint::engines {

struct BulletChain::World {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btMultiBodyConstraintSolver solver;
  btMultiBodyDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
  std::unique_ptr<btMultiBody> body;
  std::vector<double> mass;
  double gravity = 0;
  ~World() {
    if (body) world.removeMultiBody(body.get());
  }
};

const std::vector<std::string>& bullet_integrators() {
  static const std::vector<std::string> names = {"euler", "rk4"};
  return names;
}

const std::vector<std::string>& bullet_gyroscopic_modes() {
  static const std::vector<std::string> names = {"none", "explicit", "implicit_body",
                                                 "implicit_world"};
  return names;
}

BulletChain::BulletChain(const PlanarChain& chain, const BulletOptions& options)
    : world_(std::make_unique<World>()) {
  const int n = chain.links();
  world_->mass = chain.mass;
  world_->gravity = chain.gravity;
  world_->world.setGravity(btVector3(0, 0, -chain.gravity));
  // A fixed base at the pivot; link i is a point mass (zero rotational inertia, which the
  // articulated-body algorithm accepts: the hinge sees m l²) at distance lᵢ below its joint, and
  // its joint sits at the parent's point mass (node i − 1), so the parent-to-pivot offset is 0.
  world_->body = std::make_unique<btMultiBody>(n, 1.0, btVector3(1, 1, 1), true, false);
  for (int i = 0; i < n; ++i) {
    world_->body->setupRevolute(i, chain.mass[i], btVector3(0, 0, 0), i - 1,
                                btQuaternion::getIdentity(), btVector3(0, -1, 0),
                                btVector3(0, 0, 0), btVector3(0, 0, -chain.length[i]), true);
  }
  world_->body->finalizeMultiDof();
  if (!options.shipped_defaults) {
    // Bullet's multibody defaults damp both velocities by 0.04 and clamp joint rates at 100.
    world_->body->setLinearDamping(0);
    world_->body->setAngularDamping(0);
    world_->body->setMaxCoordinateVelocity(std::numeric_limits<double>::max());
    world_->body->setCanSleep(false);
  }
  world_->body->useRK4Integration(options.integrator == "rk4");
  world_->world.addMultiBody(world_->body.get());
}

BulletChain::~BulletChain() = default;

void BulletChain::set_state(const Vec& theta, const Vec& theta_dot) {
  absolute_to_relative(theta, relative_);
  absolute_to_relative(theta_dot, relative_rate_);
  for (int i = 0; i < world_->body->getNumLinks(); ++i) {
    world_->body->setJointPos(i, relative_[i]);
    world_->body->setJointVel(i, relative_rate_[i]);
  }
}

void BulletChain::get_state(Vec& theta, Vec& theta_dot) const {
  const int n = world_->body->getNumLinks();
  Vec relative(n), rate(n);
  for (int i = 0; i < n; ++i) {
    relative[i] = world_->body->getJointPos(i);
    rate[i] = world_->body->getJointVel(i);
  }
  relative_to_absolute(relative, theta);
  relative_to_absolute(rate, theta_dot);
}

double BulletChain::potential() const {
  double energy = 0;
  for (int i = 0; i < world_->body->getNumLinks(); ++i) {
    energy += world_->mass[i] * world_->gravity *
              world_->body->localPosToWorld(i, btVector3(0, 0, 0)).z();
  }
  return energy;
}

double BulletChain::kinetic() {
  // Fourth-order central difference of the centres of mass along the rates (δ = 1e-4: truncation
  // ~δ⁴, round-off ~ε/δ, both far below the 1e-9 the tests ask).
  const int n = world_->body->getNumLinks();
  const Vec position = relative_, rate = relative_rate_;
  const double delta = 1e-4;
  std::vector<btVector3> velocity(n, btVector3(0, 0, 0));
  for (const auto& [step, weight] : {std::pair{1.0, 8.0}, {-1.0, -8.0}, {2.0, -1.0}, {-2.0, 1.0}}) {
    for (int i = 0; i < n; ++i) world_->body->setJointPos(i, position[i] + step * delta * rate[i]);
    for (int i = 0; i < n; ++i) {
      velocity[i] += weight / (12 * delta) * world_->body->localPosToWorld(i, btVector3(0, 0, 0));
    }
  }
  for (int i = 0; i < n; ++i) world_->body->setJointPos(i, position[i]);
  double energy = 0;
  for (int i = 0; i < n; ++i) energy += 0.5 * world_->mass[i] * velocity[i].length2();
  return energy;
}

StepStatus BulletChain::step(double h) {
  // maxSubSteps = 0: one internal step of exactly h (no fixed-step accumulator, no interpolation).
  world_->world.stepSimulation(h, 0, h);
  return StepStatus::success();
}

struct BulletRotor::World {
  // The free body: a btRigidBody (its collision shape empty: nothing to collide with).
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver rigid_solver;
  btEmptyShape shape;
  std::unique_ptr<btDiscreteDynamicsWorld> rigid_world;
  std::unique_ptr<btRigidBody> rigid_body;
  // A body about a fixed point: a btMultiBody.
  btMultiBodyConstraintSolver multibody_solver;
  std::unique_ptr<btMultiBodyDynamicsWorld> multibody_world;
  std::unique_ptr<btMultiBody> multibody;
  double gravity = 0;
  ~World() {
    if (multibody) multibody_world->removeMultiBody(multibody.get());
    if (rigid_body) rigid_world->removeRigidBody(rigid_body.get());
  }
};

namespace {

btMatrix3x3 to_bullet(const Eigen::Matrix3d& m) {
  return btMatrix3x3(m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1),
                     m(2, 2));
}
Eigen::Matrix3d from_bullet(const btMatrix3x3& m) {
  Eigen::Matrix3d out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out(i, j) = m[i][j];
  return out;
}
Eigen::Vector3d from_bullet(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

int gyroscopic_flags(const std::string& mode) {
  if (mode == "explicit") return BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT;
  if (mode == "implicit_body") return BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY;
  if (mode == "implicit_world") return BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_WORLD;
  return 0;
}

}  // namespace

BulletRotor::BulletRotor(const Rotor& rotor, const BulletOptions& options)
    : world_(std::make_unique<World>()) {
  World& w = *world_;
  w.gravity = rotor.gravity;
  const Eigen::Vector3d& I = rotor.principal_moments;
  const Eigen::Vector3d& c = rotor.principal_centre;
  if (rotor.free()) {
    w.rigid_world = std::make_unique<btDiscreteDynamicsWorld>(&w.dispatcher, &w.broadphase,
                                                              &w.rigid_solver, &w.configuration);
    w.rigid_world->setGravity(btVector3(0, 0, 0));
    btRigidBody::btRigidBodyConstructionInfo info(rotor.mass, nullptr, &w.shape,
                                                  btVector3(I[0], I[1], I[2]));
    info.m_linearDamping = 0;
    info.m_angularDamping = 0;
    w.rigid_body = std::make_unique<btRigidBody>(info);
    w.rigid_body->setFlags(gyroscopic_flags(options.gyro));
    // Sleeping is Bullet's default (a body below its speed thresholds for 2 s stops).
    if (!options.shipped_defaults) w.rigid_body->setActivationState(DISABLE_DEACTIVATION);
    w.rigid_world->addRigidBody(w.rigid_body.get());
    w.rigid_body->setGravity(btVector3(0, 0, 0));
  } else {
    w.multibody_world = std::make_unique<btMultiBodyDynamicsWorld>(
        &w.dispatcher, &w.broadphase, &w.multibody_solver, &w.configuration);
    w.multibody_world->setGravity(btVector3(0, 0, -rotor.gravity));
    // A fixed base at the origin (its centre), the link's pivot there and its centre of mass at
    // c in its own (principal) frame.
    w.multibody = std::make_unique<btMultiBody>(1, 1.0, btVector3(1, 1, 1), true, false);
    w.multibody->setupSpherical(0, rotor.mass, btVector3(I[0], I[1], I[2]), -1,
                                btQuaternion::getIdentity(), btVector3(0, 0, 0),
                                btVector3(c[0], c[1], c[2]), true);
    w.multibody->finalizeMultiDof();
    if (!options.shipped_defaults) {
      w.multibody->setLinearDamping(0);
      w.multibody->setAngularDamping(0);
      w.multibody->setMaxCoordinateVelocity(std::numeric_limits<double>::max());
      w.multibody->setCanSleep(false);
    }
    w.multibody->useRK4Integration(options.integrator == "rk4");
    w.multibody_world->addMultiBody(w.multibody.get());
  }
  set_state(RotorState{});
}

BulletRotor::~BulletRotor() = default;

void BulletRotor::set_state(const RotorState& principal) {
  World& w = *world_;
  if (w.rigid_body) {
    btTransform transform;
    transform.setIdentity();
    transform.setBasis(to_bullet(principal.attitude));
    w.rigid_body->setCenterOfMassTransform(transform);  // also updates the world inertia
    const Eigen::Vector3d omega = principal.attitude * principal.omega;  // spatial
    w.rigid_body->setAngularVelocity(btVector3(omega[0], omega[1], omega[2]));
    w.rigid_body->setLinearVelocity(btVector3(0, 0, 0));
    return;
  }
  // The spherical joint's position is the quaternion (x, y, z, w) of the link's attitude (the
  // rotation from the link to the fixed base: btMultibodyLink::updateCacheMultiDof conjugates it
  // into the parent-to-link rotation); its velocity is the angular velocity in the link's frame.
  const Eigen::Quaterniond q(principal.attitude);
  const double position[4] = {q.x(), q.y(), q.z(), q.w()};
  const double velocity[3] = {principal.omega[0], principal.omega[1], principal.omega[2]};
  w.multibody->setJointPosMultiDof(0, position);
  w.multibody->setJointVelMultiDof(0, velocity);
}

RotorState BulletRotor::get_state() const {
  const World& w = *world_;
  RotorState state;
  if (w.rigid_body) {
    state.attitude = from_bullet(w.rigid_body->getCenterOfMassTransform().getBasis());
    state.omega = state.attitude.transpose() * from_bullet(w.rigid_body->getAngularVelocity());
    return state;
  }
  const btScalar* position = w.multibody->getJointPosMultiDof(0);
  const btScalar* velocity = w.multibody->getJointVelMultiDof(0);
  state.attitude =
      Eigen::Quaterniond(position[3], position[0], position[1], position[2]).toRotationMatrix();
  state.omega = Eigen::Vector3d(velocity[0], velocity[1], velocity[2]);
  return state;
}

double BulletRotor::kinetic() const {
  const World& w = *world_;
  if (w.rigid_body) {
    const Eigen::Vector3d omega = from_bullet(w.rigid_body->getAngularVelocity());
    const Eigen::Matrix3d inertia = from_bullet(w.rigid_body->getInvInertiaTensorWorld()).inverse();
    return 0.5 * omega.dot(inertia * omega) +
           0.5 * w.rigid_body->getLinearVelocity().length2() / w.rigid_body->getInvMass();
  }
  // About the pivot: the link's inertia about its centre plus m(|c|²1 − ccᵀ), c = getRVector
  // (from the base's centre, the pivot, to the link's centre in the link's frame).
  const Eigen::Vector3d c = from_bullet(w.multibody->getRVector(0));
  const double m = w.multibody->getLinkMass(0);
  const Eigen::Matrix3d J =
      Eigen::Matrix3d(from_bullet(w.multibody->getLinkInertia(0)).asDiagonal()) +
      m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  const btScalar* velocity = w.multibody->getJointVelMultiDof(0);
  const Eigen::Vector3d omega(velocity[0], velocity[1], velocity[2]);
  return 0.5 * omega.dot(J * omega);
}

double BulletRotor::potential() const {
  const World& w = *world_;
  if (w.rigid_body) return 0;  // no gravity on the free body
  return w.multibody->getLinkMass(0) * w.gravity *
         w.multibody->localPosToWorld(0, btVector3(0, 0, 0)).z();
}

StepStatus BulletRotor::step(double h) {
  // maxSubSteps = 0: one internal step of exactly h (no fixed-step accumulator, no interpolation).
  if (world_->rigid_world) {
    world_->rigid_world->stepSimulation(h, 0, h);
  } else {
    world_->multibody_world->stepSimulation(h, 0, h);
  }
  return StepStatus::success();
}

namespace {

class BulletMethod final : public EngineMethod<BulletChain, BulletRotor, BulletOptions> {
 public:
  explicit BulletMethod(BulletOptions options) : EngineMethod(std::move(options), "Bullet") {}

  MethodInfo info() const override {
    return options_.integrator == "rk4"
               ? MethodInfo{"bullet", 4, kExplicit | kGeneralLagrangian,
                            "Bullet 3.24 btMultiBody with useRK4Integration"}
               : MethodInfo{"bullet", 1, kExplicit | kGeneralLagrangian,
                            "Bullet 3.24 btMultiBody (semi-implicit Euler)"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(options_.integrator == "rk4" ? 2 * std::sqrt(2.0) : 2.0);
  }

 protected:
  // The free body is a btRigidBody, whose step has no RK4 and whose gyroscopic term is an option;
  // the btMultiBody of every other problem has the RK4 option and no gyroscopic one.
  std::string option_refusal(const Problem& problem) const override {
    const bool free_body = Spec::parse(problem.spec()).name == "rigid_body";
    if (free_body && options_.integrator == "rk4") {
      return "method 'bullet:integrator=rk4' runs btMultiBody models only; the free body "
             "(rigid_body) is a btRigidBody, whose step is Bullet's semi-implicit Euler only "
             "(use bullet or bullet:gyro=...)";
    }
    if (!free_body && options_.gyro_given) {
      return fmt::format(
          "method 'bullet:gyro={}' sets the gyroscopic term of a btRigidBody, which "
          "only the free body (rigid_body) is; problem '{}' is a btMultiBody",
          options_.gyro, problem.name());
    }
    return "";
  }
};

}  // namespace
}  // namespace geomint::engines

namespace geomint {

std::unique_ptr<Integrator> make_bullet(Params& params) {
  engines::BulletOptions options;
  options.integrator = params.choice("integrator", "euler", engines::bullet_integrators(),
                                     "euler: btMultiBody's default step; rk4: useRK4Integration");
  options.shipped_defaults =
      params.choice("defaults", "clean", {"clean", "shipped"},
                    "clean: no damping, sleeping or velocity clamp; shipped: Bullet's own "
                    "defaults (damping 0.04, joint rates clamped at 100)") == "shipped";
  options.gyro_given = params.given("gyro");
  options.gyro = params.choice(
      "gyro", "implicit_body", engines::bullet_gyroscopic_modes(),
      "the free body's (btRigidBody's) gyroscopic term: none, explicit "
      "(BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT), implicit_body (Bullet's default), implicit_world");
  // Every spec written before the option keeps its name.
  params.omit_default_from_canonical("gyro");
  return std::make_unique<engines::BulletMethod>(std::move(options));
}

}  // namespace geomint
