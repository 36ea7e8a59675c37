// The `dart` method: DART 6.12's own step (World::step, or one of its dart::integration classes
// driving the skeleton's forward dynamics) on the chain or rigid body a problem is, the state read
// back as the problem's. The one translation unit that includes DART's headers (engines/dart.hpp).
#include "engines/dart.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <dart/dynamics/BallJoint.hpp>
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/FreeJoint.hpp>
#include <dart/dynamics/RevoluteJoint.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/integration/EulerIntegrator.hpp>
#include <dart/integration/RK4Integrator.hpp>
#include <dart/integration/SemiImplicitEulerIntegrator.hpp>
#include <dart/simulation/World.hpp>
#include <stdexcept>
#include <utility>

#include "engines/engine_method.hpp"

namespace geomint::engines {

namespace dd = dart::dynamics;
namespace di = dart::integration;

namespace {

// DART 6.12 ships dart::integration's integrators but nothing that hands a Skeleton to them (its
// World steps on its own): this is the IntegrableSystem a Skeleton would be, its accelerations
// from the skeleton's own forward dynamics (the articulated-body algorithm) and its positions
// advanced by the skeleton's own joint update (q + hv on a hinge, R exp(hΩ̂) on a ball joint).
// A joint coordinate or rate beyond this magnitude means the run has blown up: far above any
// state of a run that has not (a hinge angle of 10¹⁵ rad resolves only to 1/8 rad) and far below
// the 1.3·10¹⁵⁴ at which the squared norm inside DART's joint transform overflows. DART 6.12
// asserts that transform (RevoluteJoint::updateRelativeTransform's verifyTransform: finite, unit
// determinant), and its assertion aborts the process, so no state beyond this goes into DART.
constexpr double kDartStateBound = 1e15;

// "" when every joint position and velocity of the skeleton is finite and within the bound, else
// what is not.
std::string blown_up_state(const dd::Skeleton& skeleton) {
  for (const auto& [name, values] : {std::pair{"position", skeleton.getPositions()},
                                     std::pair{"velocity", skeleton.getVelocities()}}) {
    for (Eigen::Index i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i]) || std::abs(values[i]) > kDartStateBound) {
        return fmt::format(
            "joint {} {} = {:g}, beyond {:g}: the run has blown up, and DART 6.12 would abort "
            "the process on it (the assertion on its joint transform)",
            name, i, values[i], kDartStateBound);
      }
    }
  }
  return "";
}

// Thrown from inside a dart::integration step, between its stages, and caught in the step.
struct BlownUp : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class SkeletonSystem final : public di::IntegrableSystem {
 public:
  explicit SkeletonSystem(dd::Skeleton& skeleton) : skeleton_(skeleton) {}
  void setConfigs(const Eigen::VectorXd& q) override { skeleton_.setPositions(q); }
  void setGenVels(const Eigen::VectorXd& v) override { skeleton_.setVelocities(v); }
  Eigen::VectorXd getConfigs() const override { return skeleton_.getPositions(); }
  Eigen::VectorXd getGenVels() const override { return skeleton_.getVelocities(); }
  // Every stage evaluates the dynamics here, at a configuration the integrator has just moved:
  // a blown-up one stops the step before DART computes a transform from it.
  Eigen::VectorXd evalGenAccs() override {
    if (std::string why = blown_up_state(skeleton_); !why.empty()) throw BlownUp(why);
    skeleton_.computeForwardDynamics();
    return skeleton_.getAccelerations();
  }
  // Skeleton::integratePositions moves along the velocities the skeleton holds: the ones given
  // go in for the update, and the skeleton's own come back after it.
  void integrateConfigs(const Eigen::VectorXd& v, double h) override {
    const Eigen::VectorXd held = skeleton_.getVelocities();
    skeleton_.setVelocities(v);
    skeleton_.integratePositions(h);
    skeleton_.setVelocities(held);
  }
  void integrateGenVels(const Eigen::VectorXd& a, double h) override {
    skeleton_.setVelocities(skeleton_.getVelocities() + h * a);
  }

 private:
  dd::Skeleton& skeleton_;
};

// DART 6.12's RK4Integrator defines integrate() only and leaves Integrator's pure integratePos and
// integrateVel undeclared, so the class cannot be instantiated as shipped: these complete it as
// its siblings define them (integrate(), the step used, calls neither).
class CompleteRk4Integrator final : public di::RK4Integrator {
 public:
  void integratePos(di::IntegrableSystem* system, double h) override {
    system->integrateConfigs(system->getGenVels(), h);
  }
  void integrateVel(di::IntegrableSystem* system, double h) override {
    system->integrateGenVels(system->evalGenAccs(), h);
  }
};

std::unique_ptr<di::Integrator> make_dart_integrator(const std::string& name) {
  if (name == "semi_implicit_euler") return std::make_unique<di::SemiImplicitEulerIntegrator>();
  if (name == "euler") return std::make_unique<di::EulerIntegrator>();
  if (name == "rk4") return std::make_unique<CompleteRk4Integrator>();
  return nullptr;  // world: World::step
}

// Everything the problems lack, written out on each degree of freedom of a clean model (DART's
// defaults are the same values: `defaults=shipped` leaves them unset). DART 6.12 joints have no
// armature; limits are enforced only when asked, through the constraint solver.
void switch_off_what_the_problem_lacks(dd::Joint& joint) {
  for (std::size_t i = 0; i < joint.getNumDofs(); ++i) {
    joint.setDampingCoefficient(i, 0);
    joint.setSpringStiffness(i, 0);
    joint.setCoulombFriction(i, 0);
  }
  joint.setLimitEnforcement(false);
  joint.setActuatorType(dd::Joint::FORCE);  // no servo or motor; its commands stay zero
}

}  // namespace

struct DartModel {
  dd::SkeletonPtr skeleton;
  dart::simulation::WorldPtr world;  // integrator=world: the skeleton steps in it
  std::unique_ptr<di::Integrator> integrator;
  std::unique_ptr<SkeletonSystem> system;
  double time_step = 0;

  // The skeleton with gravity g along −z, stepped by `options.integrator`.
  DartModel(dd::SkeletonPtr built, double gravity, const DartOptions& options)
      : skeleton(std::move(built)), integrator(make_dart_integrator(options.integrator)) {
    const Eigen::Vector3d g(0, 0, -gravity);
    skeleton->setGravity(g);
    if (!options.shipped_defaults) {
      skeleton->setSelfCollisionCheck(false);
      skeleton->setMobile(true);
      for (std::size_t i = 0; i < skeleton->getNumJoints(); ++i) {
        switch_off_what_the_problem_lacks(*skeleton->getJoint(i));
      }
    }
    if (integrator) {
      system = std::make_unique<SkeletonSystem>(*skeleton);
    } else {
      // The world has no collision shapes to detect (the bodies have none), so its constraint
      // solver finds nothing to solve.
      world = dart::simulation::World::create("geomint");
      world->setGravity(g);
      world->addSkeleton(skeleton);
    }
  }

  // One step of length h; what DART throws, or a non-finite joint state, is a failed status. A
  // blown-up state (blown_up_state) never goes into DART: it is a failed status too.
  StepStatus step(double h) {
    if (std::string why = blown_up_state(*skeleton); !why.empty()) {
      return StepStatus::failure("dart_blowup", "DART's step stopped before it ran: " + why);
    }
    try {
      if (h != time_step) {
        // The step enters DART's forward dynamics through the joints' implicit damping and
        // springs (zero here), which read it from the skeleton.
        if (world) world->setTimeStep(h);
        skeleton->setTimeStep(h);
        time_step = h;
      }
      if (world) {
        world->step();
      } else {
        integrator->integrate(system.get(), h);
      }
    } catch (const BlownUp& error) {
      return StepStatus::failure(
          "dart_blowup", fmt::format("DART's step stopped between stages: {}", error.what()));
    } catch (const std::exception& error) {
      return StepStatus::failure("dart_error",
                                 fmt::format("DART threw in its step: {}", error.what()));
    }
    if (!skeleton->getPositions().allFinite() || !skeleton->getVelocities().allFinite()) {
      return StepStatus::failure("dart_nan",
                                 "DART's step left a non-finite joint position or velocity");
    }
    return StepStatus::success();
  }
};

const std::vector<std::string>& dart_integrators() {
  static const std::vector<std::string> names = {"world", "semi_implicit_euler", "euler", "rk4"};
  return names;
}

namespace {

// DART 6.12's BodyNode::computePotentialEnergy is −m g·(the body frame's origin), not of its
// centre of mass (its compiled code reads the frame's world translation): so every body frame
// below has its origin at the body's centre of mass, and the joints sit off it
// (mT_ChildBodyToJoint), which makes DART's potential the problem's. Dynamics and the mass matrix
// do not depend on where the frame is; DART's potential with the centre of mass off the origin
// was wrong by the rods' whole potential (tested).
//
// Rod i hangs along −z from its hinge (at the parent's point mass), about −y so that a positive
// angle swings it towards +x (the problems' x = Σ lᵢ sin θᵢ): the body frame sits at the point
// mass at its end, the hinge lᵢ above it. DART warns of (and mishandles) a zero moment of inertia,
// so the point gets kPointMassInertia·m·l² about each axis, as MuJoCo's does. Unique names spare
// DART's renaming of duplicates.
dd::SkeletonPtr chain_skeleton(const PlanarChain& chain) {
  dd::SkeletonPtr skeleton = dd::Skeleton::create("geomint_chain");
  dd::BodyNode* parent = nullptr;
  for (int i = 0; i < chain.links(); ++i) {
    const double l = chain.length[i], m = chain.mass[i];
    dd::RevoluteJoint::Properties joint;
    joint.mName = fmt::format("hinge{}", i);
    joint.mAxis = Eigen::Vector3d(0, -1, 0);
    // The hinge at the parent's frame origin (its point mass, or the world's origin).
    joint.mT_ChildBodyToJoint.translation() = Eigen::Vector3d(0, 0, l);
    dd::BodyNode::Properties body;
    body.mName = fmt::format("rod{}", i);
    body.mInertia = dd::Inertia(m, Eigen::Vector3d::Zero(),
                                kPointMassInertia * m * l * l * Eigen::Matrix3d::Identity());
    parent = skeleton->createJointAndBodyNodePair<dd::RevoluteJoint>(parent, joint, body).second;
  }
  return skeleton;
}

// One body in the rotor's principal frame, its origin at the centre of mass (see above): on a
// ball joint at the fixed point (the world's origin, at −principal_centre in the body frame), or
// on a free joint.
dd::SkeletonPtr rotor_skeleton(const Rotor& rotor) {
  dd::SkeletonPtr skeleton = dd::Skeleton::create("geomint_rotor");
  dd::BodyNode::Properties body;
  body.mName = "body";
  body.mInertia = dd::Inertia(rotor.mass, Eigen::Vector3d::Zero(),
                              Eigen::Matrix3d(rotor.principal_moments.asDiagonal()));
  if (rotor.free()) {
    dd::FreeJoint::Properties joint;
    joint.mName = "free";
    joint.mT_ChildBodyToJoint.translation() = -rotor.principal_centre;
    skeleton->createJointAndBodyNodePair<dd::FreeJoint>(nullptr, joint, body);
  } else {
    dd::BallJoint::Properties joint;
    joint.mName = "ball";
    joint.mT_ChildBodyToJoint.translation() = -rotor.principal_centre;
    skeleton->createJointAndBodyNodePair<dd::BallJoint>(nullptr, joint, body);
  }
  return skeleton;
}

}  // namespace

DartChain::DartChain(const PlanarChain& chain, const DartOptions& options)
    : model_(std::make_unique<DartModel>(chain_skeleton(chain), chain.gravity, options)) {}

DartChain::~DartChain() = default;

void DartChain::set_state(const Vec& theta, const Vec& theta_dot) {
  absolute_to_relative(theta, relative_);
  absolute_to_relative(theta_dot, relative_rate_);
  model_->skeleton->setPositions(relative_);
  model_->skeleton->setVelocities(relative_rate_);
}

void DartChain::get_state(Vec& theta, Vec& theta_dot) const {
  relative_to_absolute(model_->skeleton->getPositions(), theta);
  relative_to_absolute(model_->skeleton->getVelocities(), theta_dot);
}

DenseMatrix DartChain::mass_matrix_absolute() const {
  const Eigen::MatrixXd& relative = model_->skeleton->getMassMatrix();
  const Eigen::Index n = relative.rows();
  // T = ½φ̇ᵀM_φφ̇ with φ̇ = Dθ̇ (D the difference matrix): M_θ = DᵀM_φD.
  DenseMatrix difference = DenseMatrix::Identity(n, n);
  for (Eigen::Index i = 1; i < n; ++i) difference(i, i - 1) = -1;
  return difference.transpose() * relative * difference;
}

double DartChain::potential() const { return model_->skeleton->computePotentialEnergy(); }
double DartChain::kinetic() const { return model_->skeleton->computeKineticEnergy(); }
StepStatus DartChain::step(double h) { return model_->step(h); }

DartRotor::DartRotor(const Rotor& rotor, const DartOptions& options)
    : model_(std::make_unique<DartModel>(rotor_skeleton(rotor), rotor.gravity, options)) {}

DartRotor::~DartRotor() = default;

// A free joint's coordinates are the rotation vector then the position (kept at the origin), its
// velocities Ω then the linear velocity (zero: the centre of mass stays put); a ball joint's are
// the rotation vector and Ω.
void DartRotor::set_state(const RotorState& principal) {
  dd::Skeleton& skeleton = *model_->skeleton;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(skeleton.getNumDofs());
  Eigen::VectorXd v = Eigen::VectorXd::Zero(skeleton.getNumDofs());
  q.head<3>() = dd::BallJoint::convertToPositions(principal.attitude);
  v.head<3>() = principal.omega;
  skeleton.setPositions(q);
  skeleton.setVelocities(v);
}

RotorState DartRotor::get_state() const {
  const dd::Skeleton& skeleton = *model_->skeleton;
  RotorState state;
  state.attitude = dd::BallJoint::convertToRotation(skeleton.getPositions().head<3>());
  state.omega = skeleton.getVelocities().head<3>();
  return state;
}

Eigen::Matrix3d DartRotor::rotational_mass_matrix() const {
  return model_->skeleton->getMassMatrix().topLeftCorner<3, 3>();
}

double DartRotor::potential() const { return model_->skeleton->computePotentialEnergy(); }
double DartRotor::kinetic() const { return model_->skeleton->computeKineticEnergy(); }
StepStatus DartRotor::step(double h) { return model_->step(h); }

namespace {

class DartMethod final : public EngineMethod<DartChain, DartRotor, DartOptions> {
 public:
  explicit DartMethod(DartOptions options) : EngineMethod(std::move(options), "DART") {}

  MethodInfo info() const override {
    const std::string& integrator = options_.integrator;
    if (integrator == "rk4") {
      // As shipped, its fourth stage is evaluated at q + (h/2)v₂ + h v₃, not at q + h v₃ (the
      // configuration is not reset to q before the last stage): first order, not fourth (tested).
      return {"dart", 1, kExplicit | kGeneralLagrangian,
              "DART 6.12 dart::integration::RK4Integrator on the skeleton's forward dynamics (as "
              "shipped: fourth stage at q + (h/2)v2 + h v3, first order)"};
    }
    if (integrator == "euler") {
      // As shipped, it moves the positions with the old velocities and then the velocities with
      // the accelerations at the new positions: semi-implicit Euler, drift then kick (tested).
      return {"dart", 1, kExplicit | kGeneralLagrangian,
              "DART 6.12 dart::integration::EulerIntegrator on the skeleton's forward dynamics (as "
              "shipped: positions first, then velocities from the new positions: semi-implicit "
              "Euler, drift then kick, not explicit Euler)"};
    }
    if (integrator == "semi_implicit_euler") {
      return {"dart", 1, kExplicit | kGeneralLagrangian,
              "DART 6.12 dart::integration::SemiImplicitEulerIntegrator on the skeleton's forward "
              "dynamics"};
    }
    return {"dart", 1, kExplicit | kGeneralLagrangian,
            "DART 6.12 simulation::World::step (semi-implicit Euler: velocities, constraint "
            "impulses, then positions)"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    // World::step, SemiImplicitEulerIntegrator (kick then drift) and EulerIntegrator (drift then
    // kick) are the two symplectic Euler steps: hω < 2.
    if (options_.integrator == "rk4") {
      return StabilityPrediction::none(
          "DART's RK4Integrator as shipped is no classical Runge-Kutta scheme: no bound derived");
    }
    return StabilityPrediction::limit(2.0);
  }

 protected:
  std::string option_refusal(const Problem& problem) const override {
    std::string ignored;
    const auto chain = planar_chain_of(problem, ignored);
    if (chain && chain->links() > kDartMaxLinks) {
      return fmt::format(
          "method 'dart' builds chains of at most {} links: DART 6.12 builds a skeleton in time "
          "growing like n³ and memory like n² (measured: 1024 links 1.5 s and 0.25 GB, 2048 "
          "links 11 s and 0.86 GB), and this chain has {}",
          kDartMaxLinks, chain->links());
    }
    return "";
  }
};

}  // namespace
}  // namespace geomint::engines

namespace geomint {

std::unique_ptr<Integrator> make_dart(Params& params) {
  engines::DartOptions options;
  options.integrator = params.choice(
      "integrator", "world", engines::dart_integrators(),
      "world: World::step (DART's own semi-implicit Euler); semi_implicit_euler, euler, rk4: "
      "dart::integration's integrator of that name on the skeleton's forward dynamics (euler is "
      "semi-implicit Euler drift then kick, rk4 a first-order variant of RK4: docs/ENGINES.md)");
  options.shipped_defaults =
      params.choice("defaults", "clean", {"clean", "shipped"},
                    "clean: damping, springs, friction and limits written out as off; shipped: "
                    "DART's own defaults (the same values in DART 6.12)") == "shipped";
  return std::make_unique<engines::DartMethod>(std::move(options));
}

}  // namespace geomint
