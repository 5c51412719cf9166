// Projected Gauss-Seidel (paper Sec. 7.2) and projected Jacobi (Sec. 7.1).
#include "solver.h"

#include "lcp.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cps {
namespace {

// (b_j - sum_{i != j} A_ji lambda_i) and A_jj for row j (Eq. 7.1.1).
void row_sum(const SparseRowMatrix& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lambda,
             Eigen::Index j, double& sum, double& diagonal) {
  sum = b[j];
  diagonal = 0.0;
  for (SparseRowMatrix::InnerIterator it(A, j); it; ++it) {
    if (it.col() == j) {
      diagonal = it.value();
    } else {
      sum -= it.value() * lambda[it.col()];
    }
  }
}

}  // namespace

Eigen::VectorXd solve_lcp(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                          const RowLimits& limits, FrictionModel friction, SolverKind kind,
                          int iterations, const double* initial, const std::vector<int>* order) {
  const Eigen::Index c = b.size();
  if (A.rows() != c || A.cols() != c || limits.c_min.size() != c || limits.c_max.size() != c) {
    throw std::invalid_argument("solve_lcp: A is " + std::to_string(A.rows()) + " x " +
                                std::to_string(A.cols()) + ", b, c_min, c_max have " +
                                std::to_string(c) + ", " + std::to_string(limits.c_min.size()) +
                                ", " + std::to_string(limits.c_max.size()) +
                                " entries; A must be c x c");
  }
  const bool coupled = friction == FrictionModel::coupled;
  if (coupled && (static_cast<Eigen::Index>(limits.normal_row.size()) != c || limits.mu.size() != c)) {
    throw std::invalid_argument("solve_lcp: coupled friction needs normal_row and mu for every row");
  }
  if (iterations < 0) {
    throw std::invalid_argument("solve_lcp: iterations " + std::to_string(iterations) +
                                " must be >= 0");
  }
  const bool coloured = kind == SolverKind::coloured_pgs;
  if (coloured) {
    bool valid = order != nullptr && static_cast<Eigen::Index>(order->size()) == c;
    for (std::size_t i = 0; valid && i < order->size(); ++i) valid = (*order)[i] >= 0 && (*order)[i] < c;
    if (!valid) {
      throw std::invalid_argument("solve_lcp: coloured-pgs needs the sweep order of the " +
                                  std::to_string(c) + " rows (row indices in [0, c))");
    }
  }
  // Bounds of row j given the lambda the row reads from.
  const auto bounds = [&](Eigen::Index j, const Eigen::VectorXd& lambda, double& lo, double& hi) {
    detail::force_limits(coupled, limits.c_min[j], limits.c_max[j],
                         coupled ? limits.mu[j] : 0.0,
                         coupled ? limits.normal_row[static_cast<std::size_t>(j)] : -1,
                         lambda.data(), lo, hi);
  };

  // PGS writes into lambda as it goes; Jacobi writes into `next` and swaps after the sweep.
  const bool jacobi = kind == SolverKind::jacobi;
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(c);  // initial guess 0 (Sec. 7.2) ...
  if (initial != nullptr) {  // ... or the one given (warm starting, Sec. 6.2.3)
    for (Eigen::Index j = 0; j < c; ++j) lambda[j] = A.coeff(j, j) > 0.0 ? initial[j] : 0.0;
  }
  Eigen::VectorXd next = Eigen::VectorXd::Zero(jacobi ? c : 0);
  for (int k = 0; k < iterations; ++k) {
    Eigen::VectorXd& out = jacobi ? next : lambda;
    for (Eigen::Index i = 0; i < c; ++i) {
      const Eigen::Index j = coloured ? (*order)[static_cast<std::size_t>(i)] : i;
      double sum;
      double diagonal;
      row_sum(A, b, lambda, j, sum, diagonal);
      if (!(diagonal > 0.0)) continue;  // the row touches no movable body: lambda_j stays 0
      double lo;
      double hi;
      bounds(j, lambda, lo, hi);
      out[j] = std::clamp(sum / diagonal, lo, hi);
    }
    if (jacobi) lambda.swap(next);
  }
  return lambda;
}

Eigen::VectorXd lcp_residual(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                             const RowLimits& limits, FrictionModel friction,
                             const Eigen::VectorXd& lambda) {
  const Eigen::Index c = b.size();
  if (A.rows() != c || A.cols() != c || lambda.size() != c || limits.c_min.size() != c ||
      limits.c_max.size() != c) {
    throw std::invalid_argument("lcp_residual: A is " + std::to_string(A.rows()) + " x " +
                                std::to_string(A.cols()) + ", b and lambda have " +
                                std::to_string(c) + " and " + std::to_string(lambda.size()) +
                                " entries; they must match");
  }
  const bool coupled = friction == FrictionModel::coupled && !limits.normal_row.empty();
  Eigen::VectorXd r = Eigen::VectorXd::Zero(c);
  for (Eigen::Index j = 0; j < c; ++j) {
    double Ax = 0.0;
    double diagonal = 0.0;
    for (SparseRowMatrix::InnerIterator it(A, j); it; ++it) {
      Ax += it.value() * lambda[it.col()];
      if (it.col() == j) diagonal = it.value();
    }
    if (!(diagonal > 0.0)) continue;
    double lo;
    double hi;
    detail::force_limits(coupled, limits.c_min[j], limits.c_max[j], coupled ? limits.mu[j] : 0.0,
                         coupled ? limits.normal_row[static_cast<std::size_t>(j)] : -1,
                         lambda.data(), lo, hi);
    r[j] = detail::natural_map_residual(lambda[j], Ax - b[j], diagonal, lo, hi);
  }
  return r;
}

Eigen::VectorXd solve_pgs(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                          const Eigen::VectorXd& c_min, const Eigen::VectorXd& c_max,
                          int iterations) {
  RowLimits limits;
  limits.c_min = c_min;
  limits.c_max = c_max;
  return solve_lcp(A, b, limits, FrictionModel::fixed, SolverKind::pgs, iterations);
}

}  // namespace cps
