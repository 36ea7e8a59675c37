// The heavy top: the rigid body of problems/rigid_body.hpp (Q as 9 constrained coordinates) with a
// fixed point and gravity, V = m g e₃ᵀQχ (χ the centre of mass in the body frame; GNI §VII.5 ex.,
// Holm, Schmah & Stoica §6.3): it keeps the energy and the vertical spatial angular momentum.
#include <fmt/format.h>

#include <cmath>

#include "problems/rigid_body.hpp"

namespace geomint {
namespace {

class HeavyTop final : public AttitudeProblem {
 public:
  HeavyTop(const RigidBodyParameters& parameters, const Eigen::Matrix3d& attitude, double weight,
           const Eigen::Vector3d& centre)
      : AttitudeProblem(parameters, attitude, kHessian | kAngularMomentum),
        weight_(weight),
        centre_(centre) {
    // The step also resolves the pendulum frequency √(m g |χ| / I_min) of the swing.
    const double swing = std::sqrt(weight * centre.norm() / parameters.moments.minCoeff());
    const double rate = std::max(parameters.omega.norm(), swing);
    const double unit = rate > 0 ? 1 / rate : 1.0;
    set_defaults(0.01 * unit, 100 * unit);
  }

  // e₃ᵀQχ = Σ_k χ_k Q_{3k}: the third entry of each column, linear in q.
  double potential(const Vec& q) const override {
    double height = 0;
    for (int k = 0; k < 3; ++k) height += centre_[k] * q[3 * k + 2];
    return weight_ * height;
  }
  void gradient(const Vec&, Vec& g) const override {
    g = Vec::Zero(9);
    for (int k = 0; k < 3; ++k) g[3 * k + 2] = weight_ * centre_[k];
  }
  // V is linear in q: ∇²V = 0.
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(9, 9);
    H.setZero();
    H.makeCompressed();
  }
  // Gravity exerts no torque about the vertical through the fixed point: only e₃·Σ_k c_k × p_k is
  // kept, the one component reported.
  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    return AttitudeProblem::angular_momentum(q, p).tail<1>();
  }

 private:
  double weight_;  // m g
  Eigen::Vector3d centre_;
};

}  // namespace

std::unique_ptr<Problem> make_heavy_top(Params& params) {
  const RigidBodyParameters P = read_rigid_body_parameters(params);
  check_attitude_masses(P, "heavy_top");
  const Eigen::Matrix3d attitude = read_initial_attitude(params, "heavy_top");
  const double mass = params.real("m", 1.0, "mass of the body", Range::above(0));
  const double gravity =
      params.real("g", 9.81, "gravitational acceleration (along -e3)", Range::above(0));
  Eigen::Vector3d centre;
  centre[0] = params.real("chi1", 0.0, "centre of mass in the body frame, component 1");
  centre[1] = params.real("chi2", 0.0, "centre of mass in the body frame, component 2");
  centre[2] = params.real("chi3", 0.5, "centre of mass in the body frame, component 3");
  return std::make_unique<HeavyTop>(P, attitude, mass * gravity, centre);
}

}  // namespace geomint
