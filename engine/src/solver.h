#pragma once
// Iterative solution of A lambda = b with bounds on lambda (paper Sec. 6.2.3 and 7):
// projected Gauss-Seidel, and Jacobi for comparison.

#include "cps/parameters.h"
#include "system.h"

#include <vector>

namespace cps {

/// Solves A lambda = b subject to the bounds of each row (Eq. 7.1.1 with clamping):
///   lambda_j = clamp((b_j - sum_{i != j} A_ji lambda_i) / A_jj, lo_j, hi_j)
/// from an initial guess and with a fixed number of sweeps over the rows in order (PGS and
/// Jacobi) or in `order` (SolverKind::coloured_pgs: c row indices, each once; a Gauss-Seidel
/// sweep in that order, row_colours.h). The guess is
/// `initial` (c values, N) when given, else 0 (the paper's); a row with A_jj <= 0 starts at 0
/// whatever the guess. lo_j, hi_j are
/// limits.c_min_j, limits.c_max_j, except for friction rows under FrictionModel::coupled, where
/// they are -+mu_j lambda_{normal_row_j} with the current contact-row value.
/// A: c x c (row-major sparse, symmetric, A_jj > 0); b: c. Returns lambda (c, N for unit-axis
/// rows). A row with A_jj <= 0 (it touches no movable body) keeps lambda_j = 0.
/// Throws std::invalid_argument on mismatched sizes, iterations < 0, or coloured_pgs without an
/// order of c valid row indices.
Eigen::VectorXd solve_lcp(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                          const RowLimits& limits, FrictionModel friction, SolverKind kind,
                          int iterations, const double* initial = nullptr,
                          const std::vector<int>* order = nullptr);

/// The natural-map residual of the bounded problem at `lambda` (c), per row
///   r_j = |lambda_j - clamp(lambda_j - (A lambda - b)_j / A_jj, lo_j, hi_j)|   (N)
/// with the bounds of solve_lcp (coupled friction bounds from lambda's own contact rows). It is 0
/// exactly when lambda solves the LCP, whatever method produced it, so PGS and Jacobi are compared
/// on the same footing. Rows with A_jj <= 0 count as 0. Returns the per-row residuals (c).
/// Throws std::invalid_argument on mismatched sizes.
Eigen::VectorXd lcp_residual(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                             const RowLimits& limits, FrictionModel friction,
                             const Eigen::VectorXd& lambda);

/// Projected Gauss-Seidel exactly as the pseudo code of Sec. 7.2, with fixed bounds c_min, c_max
/// (c each): solve_lcp with SolverKind::pgs and FrictionModel::fixed.
Eigen::VectorXd solve_pgs(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                          const Eigen::VectorXd& c_min, const Eigen::VectorXd& c_max,
                          int iterations);

}  // namespace cps
