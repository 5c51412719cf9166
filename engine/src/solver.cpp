// Projected Gauss-Seidel, paper Sec. 7.2.
#include "cps/solver.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace cps {

Eigen::VectorXd solve_pgs(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                          const Eigen::VectorXd& c_min, const Eigen::VectorXd& c_max,
                          int iterations) {
  const Eigen::Index c = b.size();
  if (A.rows() != c || A.cols() != c || c_min.size() != c || c_max.size() != c) {
    throw std::invalid_argument("solve_pgs: A is " + std::to_string(A.rows()) + " x " +
                                std::to_string(A.cols()) + ", b, c_min, c_max have " +
                                std::to_string(c) + ", " + std::to_string(c_min.size()) + ", " +
                                std::to_string(c_max.size()) + " entries; A must be c x c");
  }
  if (iterations < 0) {
    throw std::invalid_argument("solve_pgs: iterations " + std::to_string(iterations) +
                                " must be >= 0");
  }
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(c);  // initial guess 0
  for (int k = 0; k < iterations; ++k) {
    for (Eigen::Index j = 0; j < c; ++j) {
      // lambda_j = (b_j - sum_{i != j} A_ji lambda_i) / A_jj   (Eq. 7.1.1)
      double sum = b[j];
      double diagonal = 0.0;
      for (SparseRowMatrix::InnerIterator it(A, j); it; ++it) {
        if (it.col() == j) {
          diagonal = it.value();
        } else {
          sum -= it.value() * lambda[it.col()];
        }
      }
      if (!(diagonal > 0.0)) continue;  // the row touches no movable body
      lambda[j] = std::clamp(sum / diagonal, c_min[j], c_max[j]);
    }
  }
  return lambda;
}

}  // namespace cps
