// The Jacobi preconditioner of integrators/conjugate_gradient.hpp.
#include "integrators/conjugate_gradient.hpp"

namespace geomint {

// Eigen::DiagonalPreconditioner::compute's rule, so that solve() gives its bits.
void JacobiPreconditioner::compute(const SparseMatrix& A) {
  inverse_diagonal.resize(A.cols());
  for (Eigen::Index j = 0; j < A.outerSize(); ++j) {
    SparseMatrix::InnerIterator it(A, j);
    while (it && it.index() != j) ++it;
    inverse_diagonal[j] = it && it.index() == j && it.value() != 0.0 ? 1.0 / it.value() : 1.0;
  }
}

}  // namespace geomint
