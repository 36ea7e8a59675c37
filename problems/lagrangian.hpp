// The general Lagrangian kind (docs/MECHANICS_GENERAL.md; Marsden & West 2001 §1–2):
// L(q, v) = ½vᵀM(q)v + a(q)ᵀv − V(q), p = L_v = M(q)v + a(q), H(q, p) = ½(p − a)ᵀM⁻¹(p − a) + V.
// A Problem offers it by deriving from LagrangianSystem too; constant-mass problems get an adapter.
#pragma once

#include <Eigen/Core>
#include <memory>

#include "problems/problem.hpp"

namespace geomint {

using DenseMatrix = Eigen::MatrixXd;

// Contract: q and v have the problem's dof n; every matrix is n × n and resized by the callee;
// M(q) is symmetric positive definite wherever the problem is defined. The primitives are the
// pieces of T = ½vᵀM(q)v, of the gyroscopic term aᵀv and of V; the L_* blocks the integrators use
// (docs/MECHANICS_GENERAL.md §2–3) are assembled from them once, below, so a problem never writes
// the same derivative twice. Every primitive is tested against finite differences
// (problems/lagrangian_test.cpp) at non-unit parameters.
class LagrangianSystem {
 public:
  virtual ~LagrangianSystem() = default;

  // ---- Primitives a problem writes ----
  // M(q), symmetric positive definite.
  virtual void mass_matrix(const Vec& q, DenseMatrix& M) const = 0;
  // ∂T/∂q for T = ½vᵀM(q)v.
  virtual void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const = 0;
  // ∂(M(q)v)/∂q: D_ij = Σ_k (∂M_ik/∂q_j) v_k (the kinetic part of L_vq).
  virtual void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const = 0;
  // ∂²T/∂q∂q (symmetric).
  virtual void kinetic_hessian(const Vec& q, const Vec& v, DenseMatrix& T_qq) const = 0;
  // The gyroscopic (magnetic) term: a(q), A = ∂a/∂q (A_ij = ∂a_i/∂q_j), and ∂²(a(q)ᵀv)/∂q∂q.
  // Defaults: a = 0 (every problem so far).
  virtual void gyroscopic(const Vec& q, Vec& a) const;
  virtual void gyroscopic_jacobian(const Vec& q, DenseMatrix& A) const;
  virtual void gyroscopic_hessian(const Vec& q, const Vec& v, DenseMatrix& a_qq) const;
  // L_q += ∂(a(q)ᵀv)/∂q = Aᵀv (lagrangian_q's gyroscopic part). Default: through the dense
  // gyroscopic_jacobian; a problem with a = 0 and many dof overrides it with nothing, so that the
  // explicit methods' route (first_order_rhs) builds no n × n matrix.
  virtual void add_gyroscopic_force(const Vec& q, const Vec& v, Vec& L_q) const;
  // V(q), ∇V(q) and ∇²V(q). The first two have Problem's signatures, so a problem deriving from
  // both Problem and LagrangianSystem writes them once.
  virtual double potential(const Vec& q) const = 0;
  virtual void gradient(const Vec& q, Vec& g) const = 0;
  virtual void potential_hessian(const Vec& q, DenseMatrix& K) const = 0;
  // The mass as an operator (problems/mass_operator.hpp, what methods call): Mv = M(q)v and
  // v = M(q)⁻¹p. Defaults: mass_matrix and a dense Cholesky solve. A problem whose M(q) has
  // structure (sparse, or an O(n) recursion) overrides them and need never form M.
  virtual void apply_mass(const Vec& q, const Vec& v, Vec& Mv) const;
  virtual void solve_mass(const Vec& q, const Vec& p, Vec& v) const;
  // Whether apply_mass, solve_mass, kinetic_gradient, gradient and the gyroscopic force are O(n)
  // recursions, so that a method is to avoid every dense n × n member: del and hp then solve
  // their step matrix-free by default (integrators/operator_del_solve.hpp). Default: false.
  virtual bool mass_is_recursive() const { return false; }
  // x = (M(q) + c K₊(q))⁻¹ r, c ≥ 0, with K₊ a non-negative diagonal part of ∇²V(q) that the mass
  // solve can take at no extra cost: the matrix-free DEL/HP preconditioner, which with
  // c = h²α(1−α) is the step's Jacobian without its velocity terms, so that stiff potential
  // modes (hω ≫ 1 on a long chain) do not slow the iteration. Default: solve_mass (K₊ = 0).
  virtual void solve_mass_with_stiffness(const Vec& q, double /*c*/, const Vec& r, Vec& x) const {
    solve_mass(q, r, x);
  }

  // ---- The Lagrangian and its derivatives, assembled from the primitives ----
  double lagrangian(const Vec& q, const Vec& v) const;
  // L_q = T_q + Aᵀv − ∇V.
  void lagrangian_q(const Vec& q, const Vec& v, Vec& L_q) const;
  // L_v = p = M(q)v + a(q).
  Vec momentum(const Vec& q, const Vec& v) const;
  // The same through apply_mass, O(n) on a recursive mass (momentum() forms M: its rounding is
  // that of the committed dense results): the matrix-free del and hp residual.
  Vec momentum_by_operator(const Vec& q, const Vec& v) const;
  // v = M(q)⁻¹(p − a(q)): the inverse Legendre map (a Cholesky solve).
  Vec velocity(const Vec& q, const Vec& p) const;
  // L_vq = ∂L_v/∂q = D + A (not symmetric in general; L_qv = L_vqᵀ).
  void lagrangian_vq(const Vec& q, const Vec& v, DenseMatrix& L_vq) const;
  // L_qq = T_qq + ∂²(aᵀv)/∂q² − ∇²V.
  void lagrangian_qq(const Vec& q, const Vec& v, DenseMatrix& L_qq) const;

  // ---- The Hamiltonian view ----
  // H(q, p) = ½(p − a)ᵀM⁻¹(p − a) + V(q).
  double hamiltonian(const Vec& q, const Vec& p) const;
  // H_q = −L_q(q, v(q, p)) and H_p = v(q, p) (the Legendre identities).
  void hamiltonian_gradient(const Vec& q, const Vec& p, Vec& H_q, Vec& H_p) const;
  // The Jacobian of Hamilton's vector field (q̇, ṗ) = (H_p, −H_q) in z = (q, p), 2n × 2n:
  // ∂v/∂q = −M⁻¹L_vq, ∂v/∂p = M⁻¹, ∂L_q/∂q = L_qq + L_qv ∂v/∂q, ∂L_q/∂p = L_qv M⁻¹.
  void hamiltonian_vector_field_jacobian(const Vec& q, const Vec& p, DenseMatrix& J) const;
};

// The constant diagonal mass Problem as a LagrangianSystem (M = diag(mass), a = 0, T_q = 0):
// how the general integrators run on every existing problem, for the agreement tests. The
// potential Hessian needs the problem's kHessian (otherwise std::logic_error).
class SeparableLagrangian final : public LagrangianSystem {
 public:
  explicit SeparableLagrangian(const Problem& problem) : problem_(problem) {}
  void mass_matrix(const Vec& q, DenseMatrix& M) const override;
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override;
  void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const override;
  void kinetic_hessian(const Vec& q, const Vec& v, DenseMatrix& T_qq) const override;
  double potential(const Vec& q) const override { return problem_.potential(q); }
  void gradient(const Vec& q, Vec& g) const override { problem_.gradient(q, g); }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override;
  void apply_mass(const Vec& q, const Vec& v, Vec& Mv) const override;
  void solve_mass(const Vec& q, const Vec& p, Vec& v) const override;

 private:
  const Problem& problem_;
};

// Compatibility shims for Problem::as_lagrangian() and Problem::kind() (problems/problem.hpp),
// kept for code written against them.
inline const LagrangianSystem* general_lagrangian(const Problem& problem) {
  return problem.as_lagrangian();
}
inline bool is_non_separable(const Problem& problem) {
  return problem.kind() == ProblemKind::kLagrangian;
}

// Whether Problem::first_order_jacobian is analytic: a Hessian or a first-order rhs_jacobian
// (Problem::has_first_order_jacobian), or — on a non-separable problem — the Hamiltonian vector
// field's Jacobian of §1 of docs/MECHANICS_GENERAL.md, which every LagrangianSystem has (its
// second-derivative blocks). The solvers that cannot run without a Jacobian (GSL msbdf/rk4imp,
// odeint rosenbrock4, CVODE's KLU path) and IDA ask this, not has_first_order_jacobian().
inline bool has_analytic_first_order_jacobian(const Problem& problem) {
  return problem.has_first_order_jacobian() || problem.kind() == ProblemKind::kLagrangian;
}

// The problem's own LagrangianSystem when it is non-separable, otherwise the SeparableLagrangian
// adapter (the problem must outlive the view).
std::shared_ptr<const LagrangianSystem> lagrangian_view(const Problem& problem);

}  // namespace geomint
