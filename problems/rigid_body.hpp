// The free rigid body shared by rigid_body (attitude Q ∈ SO(3) as 9 constrained coordinates,
// MECHANICS.md §6) and rigid_body_euler (Euler's equations Π̇ = Π × J⁻¹Π): parameter reading and
// the exact body angular momentum Π(t) by Jacobi elliptic functions (Landau–Lifshitz §37).
#pragma once

#include <Eigen/Core>
#include <string>

#include "problems/problem.hpp"

namespace geomint {

// Principal moments (I1, I2, I3) and the initial body angular velocity Ω, read and validated the
// same way by both problems: every I_k > 0 and the strict triangle inequality I_k < I_i + I_j
// (the masses d_k = ½(I1 + I2 + I3) − I_k of the 9-coordinate form must be positive).
struct RigidBodyParameters {
  Eigen::Vector3d moments;
  Eigen::Vector3d omega;
};
RigidBodyParameters read_rigid_body_parameters(Params& params, const std::string& problem);

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

// Body angular momentum Π = Qᵀ Σ_k (Q e_k) × p_k of a rigid_body state q = vec(Q) (column by
// column), p: on the manifold QᵀQ = I this is J Ω.
Eigen::Vector3d rigid_body_body_momentum(const Vec& q, const Vec& p);

}  // namespace geomint
