#pragma once
// Projected Gauss-Seidel (paper Sec. 7): solves A lambda = b with c_min <= lambda <= c_max.

#include "cps/system.h"

namespace cps {

/// Projected Gauss-Seidel exactly as the pseudo code of Sec. 7.2: initial guess lambda = 0,
/// `iterations` sweeps over the rows in order, each row
///   lambda_j = clamp((b_j - sum_{i != j} A_ji lambda_i) / A_jj, c_min_j, c_max_j)   (Eq. 7.1.1)
/// using the new values at once. A: c x c (row-major sparse, symmetric, A_jj > 0); b, c_min,
/// c_max: c. Returns lambda (c, in N for unit-axis rows). A row with A_jj <= 0 (it touches no
/// movable body) keeps lambda_j = 0. Throws std::invalid_argument on mismatched sizes or
/// iterations < 0.
Eigen::VectorXd solve_pgs(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                          const Eigen::VectorXd& c_min, const Eigen::VectorXd& c_max,
                          int iterations);

}  // namespace cps
