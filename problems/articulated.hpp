// A planar tree of rigid links on revolute joints (parallel hinge axes) in absolute link angles,
// and its O(n) recursions: M(θ)v, M(θ)⁻¹p (articulated-body inertia), ∂T/∂θ, energy, momenta.
// problems/articulated.cpp (articulated_chain, rope, branching) and rod_chain's joint form share
// it.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <vector>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint::articulated {

// The largest tree the problems accept (docs/PROBLEMS.md). The recursions have no limit of their
// own; the cap keeps the dense members (M(θ), the Hessians: O(n²) memory) within reach of the
// dense methods and the tests.
inline constexpr int kMaxLinks = 4096;

// Link i hangs from joint i, which sits at the tip of its parent link (parent[i] < i) or at the
// fixed pivot (parent[i] = kPivot). θ_i is its absolute angle from the downward vertical: the tip
// is joint + length_i (sin θ_i, −cos θ_i), the centre of mass joint + com_i (sin θ_i, −cos θ_i),
// the moment of inertia about the centre of mass inertia_i. Gravity acts along −y.
struct PlanarTree {
  static constexpr int kPivot = -1;
  std::vector<int> parent;
  Vec mass, length, com, inertia;
  double gravity = 1;
};

// The mechanics of one PlanarTree. With u = θ̇, the kinetic energy is
// T = ½ Σ_i (m_i |V_i|² + I_i u_i²), V_i the centre-of-mass velocity, and
// (M u)_a = I_a u_a + e′_a · (m_a c_a V_a + l_a S_a),  ∂T/∂θ_a = −u_a e_a · (m_a c_a V_a + l_a S_a)
// with e_a = (sin θ_a, −cos θ_a), e′_a = de_a/dθ_a and S_a the linear momentum of a's strict
// descendants: one pass from the pivot (V) and one back (S). Every recursive member counts its
// passes (passes(): a work counter, relaxed atomic so that parallel runs may share a problem).
class PlanarTreeDynamics {
 public:
  // Checks the tree (std::invalid_argument: a factory validates its parameters first).
  explicit PlanarTreeDynamics(PlanarTree tree);

  int size() const { return static_cast<int>(tree_.parent.size()); }
  const PlanarTree& tree() const { return tree_; }

  // ---- O(n) recursions ----
  void apply_mass(const Vec& theta, const Vec& u, Vec& Mu) const;
  // Featherstone's articulated-body recursion in the plane: a pass from the leaves builds each
  // subtree's joint-velocity-to-momentum map P_a = K_a U_a + k_a (K_a 2 × 2), a pass from the
  // pivot reads off u_a and the joint velocities. With `inertia_shift`, (M + diag(shift))⁻¹p: in
  // absolute angles a diagonal added to M is extra rotational inertia of each link, so the same
  // recursion solves it (shift ≥ 0).
  void solve_mass(const Vec& theta, const Vec& p, Vec& u, const Vec* inertia_shift = nullptr) const;
  void kinetic_gradient(const Vec& theta, const Vec& u, Vec& T_q) const;
  double kinetic_energy(const Vec& theta, const Vec& u) const;
  // V = Σ m_i g y_i = −Σ_a w_a cos θ_a, ∇V_a = w_a sin θ_a, w_a = g (m_a c_a + l_a W_a) with
  // W_a the mass of a's strict descendants.
  double potential(const Vec& theta) const;
  void potential_gradient(const Vec& theta, Vec& g) const;
  // The Noether momentum of rotating every link about the pivot, Σ_a p_a: the total angular
  // momentum about the pivot (conserved when gravity = 0).
  static double angular_momentum(const Vec& p) { return p.sum(); }

  // ---- Dense forms (O(n²) entries, for the dense methods and the tests) ----
  // M_ab = C_ab cos(θ_a − θ_b) with C_aa = I_a + m_a c_a² + l_a² W_a, C_ab = l_a (m_b c_b + l_b
  // W_b) for a a strict ancestor of b, 0 for unrelated links (no n × n matrix is stored).
  void mass_matrix(const Vec& theta, DenseMatrix& M) const;
  void mass_velocity_jacobian(const Vec& theta, const Vec& u, DenseMatrix& D) const;
  void kinetic_hessian(const Vec& theta, const Vec& u, DenseMatrix& T_qq) const;
  void potential_hessian(const Vec& theta, DenseMatrix& K) const;
  const Vec& weight() const { return weight_; }

  long passes() const { return passes_.load(std::memory_order_relaxed); }

 private:
  // V_i, and the momentum m_a c_a V_a + l_a S_a that both T-members read (2 passes).
  void link_momenta(const Vec& theta, const Vec& u, Eigen::Matrix2Xd& lever) const;
  void count(long passes) const;

  PlanarTree tree_;
  // C_ab between b and its strict ancestor a, visiting each related pair (a, b) once.
  template <typename Visit>
  void for_each_related_pair(Visit visit) const;

  Vec weight_;  // w_a
  Vec self_;    // C_aa
  Vec moment_;  // m_b c_b + l_b W_b (C_ab = l_a moment_b)
  mutable std::atomic<long> passes_{0};
};

// Every recursive pass this thread has run on any tree, a total that only grows. The timing pass
// reads it around a run (harness/run.cpp, column recursive_passes_per_step): a per-thread count
// is not disturbed by a parallel run on the same shared problem, as passes() is.
long thread_passes();

// The general-Lagrangian face of a PlanarTree for a Problem (the problem derives from both):
// every member the explicit methods reach (apply_mass, solve_mass, kinetic_gradient, gradient,
// the gyroscopic force, the energy) is an O(n) recursion; the dense ones stay for the dense
// methods.
class PlanarTreeLagrangian : public LagrangianSystem {
 public:
  explicit PlanarTreeLagrangian(PlanarTree tree) : dynamics_(std::move(tree)) {}
  const PlanarTreeDynamics& dynamics() const { return dynamics_; }

  void mass_matrix(const Vec& q, DenseMatrix& M) const override { dynamics_.mass_matrix(q, M); }
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override {
    dynamics_.kinetic_gradient(q, v, T_q);
  }
  void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const override {
    dynamics_.mass_velocity_jacobian(q, v, D);
  }
  void kinetic_hessian(const Vec& q, const Vec& v, DenseMatrix& T_qq) const override {
    dynamics_.kinetic_hessian(q, v, T_qq);
  }
  // a = 0: nothing to add (the default would build the n × n zero matrix A).
  void add_gyroscopic_force(const Vec&, const Vec&, Vec&) const override {}
  double potential(const Vec& q) const override { return dynamics_.potential(q); }
  void gradient(const Vec& q, Vec& g) const override { dynamics_.potential_gradient(q, g); }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    dynamics_.potential_hessian(q, K);
  }
  void apply_mass(const Vec& q, const Vec& v, Vec& Mv) const override {
    dynamics_.apply_mass(q, v, Mv);
  }
  void solve_mass(const Vec& q, const Vec& p, Vec& v) const override {
    dynamics_.solve_mass(q, p, v);
  }
  bool mass_is_recursive() const override { return true; }
  // ∇²V = diag(w_a cos θ_a) is diagonal in absolute angles: its non-negative part goes into the
  // articulated-body solve as link inertia (2 passes, as solve_mass).
  void solve_mass_with_stiffness(const Vec& q, double c, const Vec& r, Vec& x) const override {
    const Vec shift = c * dynamics_.weight().cwiseProduct(q.array().cos().matrix()).cwiseMax(0.0);
    dynamics_.solve_mass(q, r, x, &shift);
  }

 private:
  PlanarTreeDynamics dynamics_;
};

}  // namespace geomint::articulated
