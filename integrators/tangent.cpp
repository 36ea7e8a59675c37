// Linearised one-step maps (integrators/tangent.hpp; docs/USAGE.md "Optional structure metrics").
#include "integrators/tangent.hpp"

#include "problems/lagrangian.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {

bool tangent_applies(const Problem& problem) {
  return problem.has(kHessian) && !problem.has(kForce) && !problem.has(kConstraints) &&
         problem.kind() != ProblemKind::kLagrangian;
}

Eigen::MatrixXd dense_hessian(const Problem& problem, const Vec& q) {
  SparseMatrix hessian;
  problem.hessian(q, hessian);
  return Eigen::MatrixXd(hessian);
}

TangentBlock::TangentBlock(int n)
    : q(Eigen::MatrixXd::Zero(n, 2 * n)), p(Eigen::MatrixXd::Zero(n, 2 * n)) {
  q.leftCols(n).setIdentity();
  p.rightCols(n).setIdentity();
}

Eigen::MatrixXd TangentBlock::stacked() const {
  Eigen::MatrixXd out(2 * q.rows(), q.cols());
  out << q, p;
  return out;
}

Eigen::MatrixXd quadrature_del_tangent(const Problem& problem, const Vec& q0, const Vec& q1,
                                       const Vec& v, double h,
                                       const std::vector<QuadratureNode>& nodes) {
  const long n = q0.size();
  const MassOperator mass(problem);
  Eigen::MatrixXd solve_matrix;
  mass.dense(q0, solve_matrix);
  Eigen::MatrixXd q_coupling = Eigen::MatrixXd::Zero(n, n);  // ∂R/∂q₀
  std::vector<Eigen::MatrixXd> hessians;
  for (const QuadratureNode& node : nodes) {
    const Vec at = node.a == 0.0 ? q0 : node.a == 1.0 ? q1 : Vec(q0 + (node.a * h) * v);
    hessians.push_back(dense_hessian(problem, at));
    solve_matrix += (h * h * node.w * node.a * (1 - node.a)) * hessians.back();
    q_coupling += (h * node.w * (1 - node.a)) * hessians.back();
  }
  // δv for the unit perturbations of (q₀, p₀): the columns [−∂R/∂q₀, I].
  Eigen::MatrixXd rhs(n, 2 * n);
  rhs << -q_coupling, Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd dv = solve_matrix.partialPivLu().solve(rhs);
  TangentBlock block(static_cast<int>(n));
  Eigen::MatrixXd dq0 = block.q;
  block.q += h * dv;
  block.p = dv;
  mass.apply_columns(q0, block.p);
  for (size_t j = 0; j < nodes.size(); ++j) {
    block.p -= (h * nodes[j].w * nodes[j].a) * (hessians[j] * (dq0 + (nodes[j].a * h) * dv));
  }
  return block.stacked();
}

}  // namespace geomint
