// The `bullet` method: Bullet's own btMultiBody step (Featherstone's articulated-body algorithm in
// joint coordinates) on the planar chain a problem is, its state read back as (θ, p = M(θ)θ̇).
#include "engines/bullet.hpp"

#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <utility>

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

namespace {

class BulletMethod final : public ChainEngineMethod<BulletChain, BulletOptions> {
 public:
  explicit BulletMethod(BulletOptions options)
      : ChainEngineMethod(std::move(options), "builds a btMultiBody of planar hinge chains only") {}

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
  return std::make_unique<engines::BulletMethod>(std::move(options));
}

}  // namespace geomint
