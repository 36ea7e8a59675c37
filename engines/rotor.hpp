// The one rigid body about a fixed point that `spherical_pendulum` (a point mass on a rod, both
// coordinate forms), `heavy_top` and `rigid_body` (free, no gravity) are, read from the problem's
// own spec, and the maps between the problem's state and the body's attitude and angular velocity.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace geomint::engines {

// A rigid body turning about the origin (the pivot, or the centre of mass of a free body), gravity
// along −z. Engines model it in its principal frame about the centre of mass: body axes
// `principal` (columns, in the problem's body frame), moments `principal_moments` about the centre,
// the centre at `principal_centre` in that frame.
struct Rotor {
  enum class Kind { kSpherical, kSphericalAngles, kHeavyTop, kFreeBody };
  Kind kind = Kind::kFreeBody;
  Eigen::Matrix3d inertia;  // about the origin, in the problem's body frame: T = ½ΩᵀJΩ
  double mass = 1;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // in the problem's body frame
  double gravity = 0;
  double length = 0;  // the spherical pendulum's rod (its angle form's maps)
  Eigen::Matrix3d principal = Eigen::Matrix3d::Identity();
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();
  Eigen::Vector3d principal_centre = Eigen::Vector3d::Zero();
  bool free() const { return kind == Kind::kFreeBody; }
};

// Attitude Q (body frame → world, of the problem's body frame) and body angular velocity Ω.
struct RotorState {
  Eigen::Matrix3d attitude = Eigen::Matrix3d::Identity();
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
};

// The problems a rotor engine runs ("spherical_pendulum", ...), for refusals and docs.
const std::vector<std::string>& rotor_problem_specs();

// The rotor `problem` is, or nullopt with `why` (no such body, or one that no mass distribution
// has: the moments about the centre of mass must be positive and obey the triangle inequality).
std::optional<Rotor> rotor_of(const Problem& problem, std::string& why);

// A point mass has no rotational inertia of its own; engines refuse a zero moment, so the
// spherical pendulum's bob gets this share of mL² about every axis (docs/ENGINES.md).
constexpr double kPointMassInertia = 1e-14;

// The problem's state ↔ (Q, Ω). `angles` keeps the branch of the angle form's (θ, φ) from one
// read-back to the next, so whole turns survive.
class RotorStateMap {
 public:
  explicit RotorStateMap(const Rotor& rotor) : rotor_(rotor) {}
  RotorState to_rotor(const Problem& problem, const State& state);
  void to_problem(const Problem& problem, const RotorState& rotor_state, State& state);
  // (Q, Ω) in the principal frame and back: Q_p = QR, Ω_p = RᵀΩ.
  RotorState to_principal(const RotorState& body) const;
  RotorState from_principal(const RotorState& principal) const;

 private:
  Rotor rotor_;
  Vec angles_;  // the angle form's last (θ, φ)
};

// "" when an engine models `problem` (a chain or a rotor), else why `method` of `engine` refuses
// it, with the problems that apply.
std::string engine_refusal(const Problem& problem, const std::string& method,
                           const std::string& engine);

}  // namespace geomint::engines
