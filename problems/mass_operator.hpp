// The kinetic part of a problem as an operator (docs/DESIGN.md §2): what a method may ask of the
// mass M(q) — apply it, solve with it, the kinetic energy — whatever the problem stores (a
// constant diagonal, a dense M(q), later a sparse or recursive O(n) one).
#pragma once

#include <Eigen/Core>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {

// A cheap value (two pointers) taken once per step or run: MassOperator mass(problem). On a
// kSeparable problem it reads the constant diagonal the problem stores, inline, with no virtual
// call (the fast path docs/PERF.md measures); on a kLagrangian one it asks the problem's
// LagrangianSystem (apply_mass, solve_mass: dense Cholesky by default, the problem's own when it
// overrides them). The problem must outlive the operator. A kFirstOrder problem has no mass: the
// constructor throws std::logic_error naming it.
class MassOperator {
 public:
  explicit MassOperator(const Problem& problem);

  // Whether M is a constant diagonal (the kSeparable kind). The two accessors below hold only
  // then (std::logic_error otherwise): for methods that assume it (Verlet, symplectic Euler,
  // Newmark, RATTLE, ...; applicable() refuses them elsewhere) and for their vectorised and
  // fixed-size loops, which take the diagonal itself.
  bool is_constant_diagonal() const { return diagonal_ != nullptr; }
  const Vec& constant_diagonal() const {
    if (diagonal_ == nullptr) not_diagonal();
    return *diagonal_;
  }
  const Vec& constant_inverse_diagonal() const {
    if (diagonal_ == nullptr) not_diagonal();
    return *inverse_diagonal_;
  }

  // Mv = M(q)v.
  void apply(const Vec& q, const Vec& v, Vec& Mv) const {
    if (diagonal_ != nullptr) {
      Mv = diagonal_->cwiseProduct(v);
    } else {
      system_->apply_mass(q, v, Mv);
    }
  }
  Vec apply(const Vec& q, const Vec& v) const {
    Vec Mv;
    apply(q, v, Mv);
    return Mv;
  }
  // v = M(q)⁻¹p (on the kSeparable kind: the velocity of momentum p).
  void solve(const Vec& q, const Vec& p, Vec& v) const {
    if (diagonal_ != nullptr) {
      v = inverse_diagonal_->cwiseProduct(p);
    } else {
      system_->solve_mass(q, p, v);
    }
  }
  Vec solve(const Vec& q, const Vec& p) const {
    Vec v;
    solve(q, p, v);
    return v;
  }
  // X ← M(q)X and X ← M(q)⁻¹X column by column (tangent blocks, Newton matrices).
  void apply_columns(const Vec& q, Eigen::MatrixXd& X) const;
  void solve_columns(const Vec& q, Eigen::MatrixXd& X) const;
  // M(q) as a dense matrix (the M + h²K of an implicit step's Newton matrix).
  void dense(const Vec& q, Eigen::MatrixXd& M) const;
  // The largest diagonal entry of M(q): a mass scale (penalty and projection weights).
  double max_diagonal(const Vec& q) const;
  // ½pᵀM(q)⁻¹p.
  double kinetic(const Vec& q, const Vec& p) const {
    if (diagonal_ != nullptr) return 0.5 * p.dot(inverse_diagonal_->cwiseProduct(p));
    return kinetic_general(q, p);
  }

 private:
  [[noreturn]] void not_diagonal() const;
  double kinetic_general(const Vec& q, const Vec& p) const;
  const Problem* problem_;
  const Vec* diagonal_ = nullptr;
  const Vec* inverse_diagonal_ = nullptr;
  const LagrangianSystem* system_ = nullptr;  // the kLagrangian kind's
};

}  // namespace geomint
