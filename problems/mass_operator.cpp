// MassOperator (problems/mass_operator.hpp): the constant-diagonal case from the problem's stored
// vectors, every other through the problem's LagrangianSystem.
#include "problems/mass_operator.hpp"

#include <Eigen/Cholesky>
#include <stdexcept>

namespace geomint {

MassOperator::MassOperator(const Problem& problem) : problem_(&problem) {
  if (const LagrangianSystem* system = problem.as_lagrangian()) {
    system_ = system;
  } else if (problem.has(kFirstOrderOnly)) {
    throw std::logic_error("problem '" + problem.name() +
                           "' is of kind first_order: it has no mass operator");
  } else {
    diagonal_ = &problem.mass();
    inverse_diagonal_ = &problem.inverse_mass();
  }
}

void MassOperator::not_diagonal() const {
  throw std::logic_error("problem '" + problem_->name() +
                         "' has a configuration-dependent mass M(q), not a constant diagonal; "
                         "use MassOperator::apply/solve");
}

void MassOperator::apply_columns(const Vec& q, Eigen::MatrixXd& X) const {
  if (diagonal_ != nullptr) {
    X = diagonal_->asDiagonal() * X;
    return;
  }
  Eigen::MatrixXd M;
  system_->mass_matrix(q, M);
  X = M * X;
}

void MassOperator::solve_columns(const Vec& q, Eigen::MatrixXd& X) const {
  if (diagonal_ != nullptr) {
    X = inverse_diagonal_->asDiagonal() * X;
    return;
  }
  Eigen::MatrixXd M;
  system_->mass_matrix(q, M);
  X = M.llt().solve(X);
}

void MassOperator::dense(const Vec& q, Eigen::MatrixXd& M) const {
  if (diagonal_ != nullptr) {
    M = diagonal_->asDiagonal();
    return;
  }
  system_->mass_matrix(q, M);
}

double MassOperator::max_diagonal(const Vec& q) const {
  if (diagonal_ != nullptr) return diagonal_->maxCoeff();
  Eigen::MatrixXd M;
  system_->mass_matrix(q, M);
  return M.diagonal().maxCoeff();
}

double MassOperator::kinetic_general(const Vec& q, const Vec& p) const {
  Vec v;
  system_->solve_mass(q, p, v);
  return 0.5 * p.dot(v);
}

}  // namespace geomint
