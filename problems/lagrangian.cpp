// The general Lagrangian kind assembled from its primitives (docs/MECHANICS_GENERAL.md §1–4;
// Marsden & West 2001 §1.2), and the constant-mass adapter.
#include "problems/lagrangian.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <stdexcept>

#include "problems/mass_operator.hpp"

namespace geomint {

void LagrangianSystem::gyroscopic(const Vec& q, Vec& a) const { a = Vec::Zero(q.size()); }
void LagrangianSystem::gyroscopic_jacobian(const Vec& q, DenseMatrix& A) const {
  A = DenseMatrix::Zero(q.size(), q.size());
}
void LagrangianSystem::gyroscopic_hessian(const Vec& q, const Vec&, DenseMatrix& a_qq) const {
  a_qq = DenseMatrix::Zero(q.size(), q.size());
}

void LagrangianSystem::apply_mass(const Vec& q, const Vec& v, Vec& Mv) const {
  DenseMatrix M;
  mass_matrix(q, M);
  Mv = M * v;
}

void LagrangianSystem::solve_mass(const Vec& q, const Vec& p, Vec& v) const {
  DenseMatrix M;
  mass_matrix(q, M);
  v = M.llt().solve(p);
}

double LagrangianSystem::lagrangian(const Vec& q, const Vec& v) const {
  DenseMatrix M;
  mass_matrix(q, M);
  Vec a;
  gyroscopic(q, a);
  return 0.5 * v.dot(M * v) + a.dot(v) - potential(q);
}

void LagrangianSystem::lagrangian_q(const Vec& q, const Vec& v, Vec& L_q) const {
  kinetic_gradient(q, v, L_q);
  Vec g;
  gradient(q, g);
  L_q -= g;
  add_gyroscopic_force(q, v, L_q);
}

void LagrangianSystem::add_gyroscopic_force(const Vec& q, const Vec& v, Vec& L_q) const {
  DenseMatrix A;
  gyroscopic_jacobian(q, A);
  L_q.noalias() += A.transpose() * v;  // ∂(a(q)ᵀv)/∂q_j = Σ_i v_i ∂a_i/∂q_j
}

Vec LagrangianSystem::momentum(const Vec& q, const Vec& v) const {
  DenseMatrix M;
  mass_matrix(q, M);
  Vec a;
  gyroscopic(q, a);
  return M * v + a;
}

Vec LagrangianSystem::momentum_by_operator(const Vec& q, const Vec& v) const {
  Vec Mv;
  apply_mass(q, v, Mv);
  Vec a;
  gyroscopic(q, a);
  return Mv + a;
}

Vec LagrangianSystem::velocity(const Vec& q, const Vec& p) const {
  Vec a;
  gyroscopic(q, a);
  Vec v;
  solve_mass(q, p - a, v);
  return v;
}

void LagrangianSystem::lagrangian_vq(const Vec& q, const Vec& v, DenseMatrix& L_vq) const {
  mass_velocity_jacobian(q, v, L_vq);
  DenseMatrix A;
  gyroscopic_jacobian(q, A);
  L_vq += A;
}

void LagrangianSystem::lagrangian_qq(const Vec& q, const Vec& v, DenseMatrix& L_qq) const {
  kinetic_hessian(q, v, L_qq);
  DenseMatrix part;
  gyroscopic_hessian(q, v, part);
  L_qq += part;
  potential_hessian(q, part);
  L_qq -= part;
}

double LagrangianSystem::hamiltonian(const Vec& q, const Vec& p) const {
  Vec a;
  gyroscopic(q, a);
  const Vec v = velocity(q, p);
  return 0.5 * (p - a).dot(v) + potential(q);
}

void LagrangianSystem::hamiltonian_gradient(const Vec& q, const Vec& p, Vec& H_q, Vec& H_p) const {
  H_p = velocity(q, p);
  lagrangian_q(q, H_p, H_q);
  H_q = -H_q;
}

void LagrangianSystem::hamiltonian_vector_field_jacobian(const Vec& q, const Vec& p,
                                                         DenseMatrix& J) const {
  const long n = q.size();
  DenseMatrix M, L_vq, L_qq;
  mass_matrix(q, M);
  const Vec v = velocity(q, p);
  lagrangian_vq(q, v, L_vq);
  lagrangian_qq(q, v, L_qq);
  const Eigen::LLT<DenseMatrix> mass_factor(M);
  const DenseMatrix inverse_mass = mass_factor.solve(DenseMatrix::Identity(n, n));
  // v(q, p) solves L_v(q, v) = p, so L_vq + M ∂v/∂q = 0 and M ∂v/∂p = I.
  const DenseMatrix v_q = -(inverse_mass * L_vq);
  J.resize(2 * n, 2 * n);
  J.topLeftCorner(n, n) = v_q;
  J.topRightCorner(n, n) = inverse_mass;
  J.bottomLeftCorner(n, n) = L_qq + L_vq.transpose() * v_q;
  J.bottomRightCorner(n, n) = L_vq.transpose() * inverse_mass;
}

void SeparableLagrangian::mass_matrix(const Vec&, DenseMatrix& M) const {
  M = problem_.mass().asDiagonal();
}
void SeparableLagrangian::apply_mass(const Vec&, const Vec& v, Vec& Mv) const {
  Mv = MassOperator(problem_).constant_diagonal().cwiseProduct(v);
}
void SeparableLagrangian::solve_mass(const Vec&, const Vec& p, Vec& v) const {
  v = MassOperator(problem_).constant_inverse_diagonal().cwiseProduct(p);
}
void SeparableLagrangian::kinetic_gradient(const Vec& q, const Vec&, Vec& T_q) const {
  T_q = Vec::Zero(q.size());
}
void SeparableLagrangian::mass_velocity_jacobian(const Vec& q, const Vec&, DenseMatrix& D) const {
  D = DenseMatrix::Zero(q.size(), q.size());
}
void SeparableLagrangian::kinetic_hessian(const Vec& q, const Vec&, DenseMatrix& T_qq) const {
  T_qq = DenseMatrix::Zero(q.size(), q.size());
}
void SeparableLagrangian::potential_hessian(const Vec& q, DenseMatrix& K) const {
  SparseMatrix sparse;
  problem_.hessian(q, sparse);
  K = DenseMatrix(sparse);
}

std::shared_ptr<const LagrangianSystem> lagrangian_view(const Problem& problem) {
  if (const LagrangianSystem* own = problem.as_lagrangian()) {
    return std::shared_ptr<const LagrangianSystem>(own, [](const LagrangianSystem*) {});
  }
  if (problem.has(kFirstOrderOnly)) {
    throw std::logic_error("problem '" + problem.name() + "' offers no Lagrangian view");
  }
  return std::make_shared<SeparableLagrangian>(problem);
}

}  // namespace geomint
