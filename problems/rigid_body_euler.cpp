// Euler's equations of the free rigid body Π̇ = Π × J⁻¹Π (Landau–Lifshitz §36–37) as a first-order
// problem for the ODE solvers, with the exact Π(t) of problems/rigid_body.hpp, its period 4K(k)/λ,
// and the Casimir |Π|² that a general-purpose solver does not keep (MECHANICS.md §6).
#include <Eigen/Geometry>
#include <cmath>

#include "problems/first_order.hpp"
#include "problems/rigid_body.hpp"

namespace geomint {
namespace {

class RigidBodyEuler final : public FirstOrderProblem, public FreeRigidBodyStructure {
 public:
  const void* structure(const StructureKey& key) const override {
    if (const void* offered = offer<FreeRigidBodyStructure>(key, this)) return offered;
    return FirstOrderProblem::structure(key);
  }
  RigidBodyEuler(const RigidBodyParameters& parameters, const Eigen::Vector3d& pi0,
                 const FreeBodyMotion& motion)
      : FirstOrderProblem(Vec(pi0), Capabilities(motion)),
        moments_(parameters.moments),
        inverse_moments_(parameters.moments.cwiseInverse()),
        motion_(motion) {
    const double rate = parameters.omega.norm();
    const double unit = rate > 0 ? 1 / rate : 1.0;
    set_defaults(0.01 * unit, 100 * unit);
  }

  void rhs(double, const Vec& y, Vec& ydot) const override {
    const Eigen::Vector3d pi = y;
    ydot = pi.cross(inverse_moments_.cwiseProduct(pi));
  }
  // ∂(Π × w)/∂Π with w = J⁻¹Π: −ŵ + Π̂J⁻¹ (ŵ the cross-product matrix).
  void rhs_jacobian(double, const Vec& y, SparseMatrix& J) const override {
    const Eigen::Vector3d pi = y;
    const Eigen::Vector3d w = inverse_moments_.cwiseProduct(pi);
    const Eigen::Matrix3d dense = -hat(w) + hat(pi) * inverse_moments_.asDiagonal().toDenseMatrix();
    J = dense.sparseView(0.0, 0.0);
    J.makeCompressed();
  }
  State exact(double t) const override { return {t, Vec(motion_.at(t)), Vec()}; }
  double period() const override { return motion_.period(); }
  // The component that changes sign once per period (the cn one, about the axis the orbit does
  // not circulate around); Π of the circulation axis never crosses 0.
  double period_observable(const Vec& q, const Vec&) const override {
    return q[motion_.sign_changing_axis()];
  }
  double casimir(const Vec& q, const Vec&) const override { return q.squaredNorm(); }

  // The state is Π alone: no attitude to read (the identity) or to write.
  Eigen::Vector3d principal_moments() const override { return moments_; }
  void read_body(const Vec& q, const Vec&, Eigen::Matrix3d& attitude,
                 Eigen::Vector3d& body_momentum) const override {
    attitude.setIdentity();
    body_momentum = q;
  }
  void write_body(const Eigen::Matrix3d&, const Eigen::Vector3d& body_momentum, Vec& q,
                  Vec&) const override {
    q = body_momentum;
  }

 private:
  static unsigned Capabilities(const FreeBodyMotion& motion) {
    if (!motion.exact()) return kCasimir;
    return std::isfinite(motion.period()) ? kCasimir | kExact | kPeriod : kCasimir | kExact;
  }
  static Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
    Eigen::Matrix3d m;
    m << 0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0;
    return m;
  }

  Eigen::Vector3d moments_;
  Eigen::Vector3d inverse_moments_;
  FreeBodyMotion motion_;
};

}  // namespace

std::unique_ptr<Problem> make_rigid_body_euler(Params& params) {
  const RigidBodyParameters P = read_rigid_body_parameters(params);
  const Eigen::Vector3d pi0 = P.moments.cwiseProduct(P.omega);
  return std::make_unique<RigidBodyEuler>(P, pi0, FreeBodyMotion(P.moments, pi0));
}

}  // namespace geomint
