// The free rigid body shared by rigid_body (attitude Q ∈ SO(3) as 9 constrained coordinates,
// MECHANICS.md §6) and rigid_body_euler (Euler's equations Π̇ = Π × J⁻¹Π): parameter reading and
// the exact body angular momentum Π(t) by Jacobi elliptic functions (Landau–Lifshitz §37).
#pragma once

#include <Eigen/Core>
#include <string>

#include "problems/problem.hpp"
#include "problems/structures/attitude.hpp"
#include "problems/structures/free_rigid_body.hpp"

namespace geomint {

// Principal moments (I1, I2, I3) and the initial body angular velocity Ω, read and validated the
// same way by every rigid-body problem: every I_k > 0, all Euler's equations need (so GNI §IV.1's
// body I = (2, 1, 2/3), which no mass distribution has, and a lamina I3 = I1 + I2 run there).
struct RigidBodyParameters {
  Eigen::Vector3d moments;
  Eigen::Vector3d omega;
};
RigidBodyParameters read_rigid_body_parameters(Params& params);

// The 9-coordinate form (rigid_body, heavy_top) needs the masses d_k = ½(I1 + I2 + I3) − I_k > 0,
// the strict triangle inequality I_k < I_i + I_j: a negative d_k has no mass distribution, and a
// flat body (d_k = 0) makes the mass tensor singular. Throws an InputError naming the case.
void check_attitude_masses(const RigidBodyParameters& parameters, const std::string& problem);

// Π(t) of the torque-free body from Π(0) (LL §37). With the moments sorted I_a < I_b < I_c, the
// orbit circulates about the extreme axis z (c when |Π|² > 2E I_b, else a), and with x the other
// extreme axis and y = b: Π_x = A cn u, Π_y = ε B sn u, Π_z = ε C dn u, u = ρλt + u₀, ε the sign
// of Π_z(0), ρ = ±1 the orientation of (a, b, c) (an odd relabelling reverses time). The motion
// of Π has period 4K(k)/λ. Not offered on the separatrix |Π|² = 2E I_b, for equal moments (a
// symmetric body, left out), or for Π(0) = 0.
class FreeBodyMotion {
 public:
  FreeBodyMotion(const Eigen::Vector3d& moments, const Eigen::Vector3d& pi0);
  // Whether at() and period() are available; why_not() says why not.
  bool exact() const { return why_not_.empty(); }
  const std::string& why_not() const { return why_not_; }
  Eigen::Vector3d at(double t) const;
  double period() const { return period_; }  // 4K(k)/λ (infinite for a steady rotation)
  double modulus() const { return k_; }
  double rate() const { return lambda_; }  // λ
  // The axis x whose Π_x = A cn u changes sign once per period (upwards once).
  int sign_changing_axis() const { return x_; }

 private:
  Eigen::Vector3d pi0_;
  std::string why_not_;
  bool steady_ = false;  // Π(0) along a principal axis: Π constant
  int x_ = 0, y_ = 1, z_ = 2;
  double amplitude_x_ = 0, amplitude_y_ = 0, amplitude_z_ = 0;
  double epsilon_ = 1, rho_ = 1, lambda_ = 0, k_ = 0, quarter_ = 0, u0_ = 0;
  double period_ = 0;
};

// A rigid body with a fixed point and the attitude Q as 9 coordinates (its entries, column by
// column) under the 6 constraints QᵀQ = I, masses d_k = ½(I1 + I2 + I3) − I_k (MECHANICS.md §6):
// the constraints, the initial state Q̇ = QΩ̂ and the spatial angular momentum Σ_k c_k × p_k shared
// by rigid_body (V = 0) and heavy_top (gravity); each adds its potential and invariants.
class AttitudeProblem : public Problem, public HolonomicConstraints, public AttitudeStructure {
 public:
  AttitudeProblem(const RigidBodyParameters& parameters, const Eigen::Matrix3d& attitude,
                  unsigned capabilities);
  State initial_state() const override;
  const void* structure(const StructureKey& key) const override {
    if (const void* offered = offer<AttitudeStructure>(key, this)) return offered;
    return Problem::structure(key);
  }
  // Q from its columns.
  Eigen::Matrix3d attitude(const Vec& q) const override;
  // Σ_k c_k × p_k = Q J Ω, the spatial angular momentum.
  Vec angular_momentum(const Vec& q, const Vec& p) const override;
  const HolonomicConstraints* as_constrained() const override { return this; }
  int constraint_count() const override { return 6; }
  void constraint(const Vec& q, Vec& g) const override;
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override;
  void constraint_curvature(const Vec& q, const Vec& v, Vec& c) const override;
  void constraint_hessian(const Vec& q, const Vec& lambda, SparseMatrix& K) const override;
  std::vector<std::string> multiplier_names() const override;
  // The body angular momentum Pi1..3, for series (the tennis-racket flip shows in Π of the
  // intermediate axis).
  std::vector<std::string> series_names() const override;
  void series_values(const Vec& q, const Vec& p, std::vector<double>& values) const override;

 protected:
  const RigidBodyParameters& parameters() const { return parameters_; }

 private:
  RigidBodyParameters parameters_;
  Eigen::Matrix3d attitude_;
};

// (Compatibility shims for Problem::as<FreeRigidBodyStructure>() and as<AttitudeStructure>().)
// The structure a problem offers, or nullptr (every other problem, and a rigid body started from
// an `initial=` file, whose given state drops the problem's own pieces).
inline const FreeRigidBodyStructure* free_rigid_body(const Problem& problem) {
  return problem.as<FreeRigidBodyStructure>();
}
// The attitude Q of rigid_body and heavy_top, or nullptr: the orthogonality_err_max metric reads
// Q through it.
inline const AttitudeStructure* attitude_problem(const Problem& problem) {
  return problem.as<AttitudeStructure>();
}

// The initial attitude from the spec keys axis1..3 and angle (identity by default), read the same
// way by rigid_body and heavy_top.
Eigen::Matrix3d read_initial_attitude(Params& params, const std::string& problem);

// Body angular momentum Π = Qᵀ Σ_k (Q e_k) × p_k of a rigid_body state q = vec(Q) (column by
// column), p: on the manifold QᵀQ = I this is J Ω.
Eigen::Vector3d rigid_body_body_momentum(const Vec& q, const Vec& p);

}  // namespace geomint
