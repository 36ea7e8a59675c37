// The linearised one-step map DΦ = ∂(q⁺, p⁺)/∂(q, p) (Integrator::step_tangent; docs/USAGE.md
// "Optional structure metrics", symplecticity_defect; GNI §VI.2): tangent vectors propagated
// through explicit stages with the Hessian ∇²V, and the implicit function theorem on the converged
// equations of implicit steps.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "integrators/integrator.hpp"

namespace geomint {

// Where the exact tangents of this file hold: no non-conservative force (its Jacobians are not
// included), no constraints (the multiplier's tangent is not), and a Hessian to linearise with.
bool tangent_applies(const Problem& problem);

// ∇²V(q) as a dense matrix.
Eigen::MatrixXd dense_hessian(const Problem& problem, const Vec& q);

// A block of tangent vectors (δq, δp), one per column, pushed through the stages of an explicit
// step: starting from the identity, the block after the last stage is DΦ.
struct TangentBlock {
  Eigen::MatrixXd q, p;
  explicit TangentBlock(int n);  // δ(q, p) = I
  // The tangent of a drift q ← q + c M⁻¹p.
  void drift(const Vec& inverse_mass, double c) { q += c * (inverse_mass.asDiagonal() * p); }
  // The tangent of a kick p ← p − c ∇V(q), with the Hessian at the kick's q.
  void kick(const Eigen::MatrixXd& hessian, double c) { p -= c * (hessian * q); }
  Eigen::MatrixXd stacked() const;  // (δq; δp): DΦ
};

// A quadrature node of a discrete Lagrangian (discrete_lagrangian.cpp): q^j = q₀ + a h v with
// weight w; the α-rule of hp is the single node (α, 1), the implicit midpoint rule (½, 1).
struct QuadratureNode {
  double a, w;
};

// DΦ of the DEL map of L_d = hΣ_j w_j[½vᵀMv − V(q^j)] at its solution v (q₁ = q₀ + h v):
//   R(v; q₀, p₀) = M v − p₀ + hΣ_j w_j(1 − a_j)∇V(q^j) = 0,   p₁ = M v − hΣ_j w_j a_j ∇V(q^j),
// so with H_j = ∇²V(q^j) the implicit function theorem gives
//   (M + h²Σ_j w_j a_j(1 − a_j)H_j) δv = δp₀ − hΣ_j w_j(1 − a_j)H_j δq₀,
//   δq₁ = δq₀ + h δv,   δp₁ = M δv − hΣ_j w_j a_j H_j(δq₀ + a_j h δv).
// The nodes at a = 0 and a = 1 are taken at q₀ and q₁ exactly. For any symmetric H_j this is the
// DEL map of a quadratic discrete Lagrangian, hence symplectic to round-off whatever the Newton
// tolerance left in v.
Eigen::MatrixXd quadrature_del_tangent(const Problem& problem, const Vec& q0, const Vec& q1,
                                       const Vec& v, double h,
                                       const std::vector<QuadratureNode>& nodes);

}  // namespace geomint
