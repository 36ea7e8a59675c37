// Rigid rods as holonomic length constraints g = |x_b − x_a| − L between two nodes (or a node and
// a fixed pivot), shared by spherical_pendulum and rod_chain (docs/METHOD.md §3, docs/METHODS.md
// "Holonomic constraints"): the residual, its Jacobian row, curvature term and the Hessian block of
// λ·g.
#pragma once

#include <Eigen/SparseCore>
#include <utility>
#include <vector>

#include "problems/problem.hpp"

namespace geomint::rods {

// One rod from node a to node b; a = kPivot is the fixed origin. Node k occupies the `dim`
// coordinates starting at k·dim.
//
// The length form |d| − L rather than the squared one ½(|d|² − L²): g is then a length error in
// the problem's units (what constraint_err_max reports) and the multiplier λ is the rod's tension
// in force units (the multiplier series), at the price of a square root and a curvature with
// 1/|d| — harmless, since a rod never shrinks to zero length.
inline constexpr int kPivot = -1;
struct Rod {
  int a = kPivot;
  int b = 0;
  double length = 1.0;
};

// d = x_b − x_a (x_pivot = 0).
inline Vec separation(const Vec& x, const Rod& rod, int dim) {
  Vec d = x.segment(rod.b * dim, dim);
  if (rod.a != kPivot) d -= x.segment(rod.a * dim, dim);
  return d;
}

inline void residuals(const std::vector<Rod>& rods, int dim, const Vec& q, Vec& g) {
  g.resize(static_cast<int>(rods.size()));
  for (size_t i = 0; i < rods.size(); ++i)
    g[i] = separation(q, rods[i], dim).norm() - rods[i].length;
}

// Row i: ∂g_i/∂x_b = uᵀ, ∂g_i/∂x_a = −uᵀ with u = d/|d|.
inline void jacobian(const std::vector<Rod>& rods, int dim, const Vec& q, SparseMatrix& G) {
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t i = 0; i < rods.size(); ++i) {
    const Vec d = separation(q, rods[i], dim);
    const Vec u = d / d.norm();
    for (int j = 0; j < dim; ++j) {
      entries.emplace_back(static_cast<int>(i), rods[i].b * dim + j, u[j]);
      if (rods[i].a != kPivot)
        entries.emplace_back(static_cast<int>(i), rods[i].a * dim + j, -u[j]);
    }
  }
  G.resize(static_cast<int>(rods.size()), q.size());
  G.setFromTriplets(entries.begin(), entries.end());
  G.makeCompressed();
}

// c_i = wᵀ∇²g_i w = (|w|² − (u·w)²)/|d| with w = v_b − v_a: the centripetal term of d²g/dt².
inline void curvature(const std::vector<Rod>& rods, int dim, const Vec& q, const Vec& v, Vec& c) {
  c.resize(static_cast<int>(rods.size()));
  for (size_t i = 0; i < rods.size(); ++i) {
    const Vec d = separation(q, rods[i], dim);
    const Vec w = separation(v, rods[i], dim);
    const double r = d.norm();
    const double along = d.dot(w) / r;
    c[i] = (w.squaredNorm() - along * along) / r;
  }
}

// Σ λ_i ∇²g_i: per rod the block λ(I − uuᵀ)/|d| on (b, b) and (a, a), its negative on (a, b)
// and (b, a).
inline void hessian(const std::vector<Rod>& rods, int dim, const Vec& q, const Vec& lambda,
                    SparseMatrix& K) {
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t i = 0; i < rods.size(); ++i) {
    const Vec d = separation(q, rods[i], dim);
    const double r = d.norm();
    const Vec u = d / r;
    const Eigen::MatrixXd block =
        lambda[static_cast<int>(i)] / r * (Eigen::MatrixXd::Identity(dim, dim) - u * u.transpose());
    const int b = rods[i].b * dim;
    const int a = rods[i].a * dim;
    for (int j = 0; j < dim; ++j) {
      for (int k = 0; k < dim; ++k) {
        entries.emplace_back(b + j, b + k, block(j, k));
        if (rods[i].a == kPivot) continue;
        entries.emplace_back(a + j, a + k, block(j, k));
        entries.emplace_back(a + j, b + k, -block(j, k));
        entries.emplace_back(b + j, a + k, -block(j, k));
      }
    }
  }
  K.resize(q.size(), q.size());
  K.setFromTriplets(entries.begin(), entries.end());
  K.makeCompressed();
}

// A problem whose constraints are rods between its nodes (dim coordinates each): the constraint
// interface from the functions above, once for every rod problem.
class RodProblem : public Problem, public HolonomicConstraints {
 public:
  const HolonomicConstraints* as_constrained() const override { return this; }
  int constraint_count() const override { return static_cast<int>(rods_.size()); }
  void constraint(const Vec& q, Vec& g) const override { rods::residuals(rods_, dim_, q, g); }
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override {
    rods::jacobian(rods_, dim_, q, G);
  }
  void constraint_curvature(const Vec& q, const Vec& v, Vec& c) const override {
    rods::curvature(rods_, dim_, q, v, c);
  }
  void constraint_hessian(const Vec& q, const Vec& lambda, SparseMatrix& K) const override {
    rods::hessian(rods_, dim_, q, lambda, K);
  }

 protected:
  RodProblem(std::vector<Rod> rods, int dim) : rods_(std::move(rods)), dim_(dim) {}
  const std::vector<Rod>& rods() const { return rods_; }

 private:
  std::vector<Rod> rods_;
  int dim_;
};

}  // namespace geomint::rods
