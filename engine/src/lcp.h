#pragma once
// The bounded problem that both solve paths (the explicit A of Sec. 6 and the matrix-free sweep)
// solve, defined once: the force limits of a row, and the natural-map residual used to compare
// any lambda against the exact solution.

#include <algorithm>
#include <cmath>

namespace cps::detail {

/// The limits [lo, hi] (N) on a row's lambda (Eq. 7.1.1 with clamping). A contact row has
/// [0, +inf), a distance row (-inf, +inf), a friction row the fixed +-mu m |g . n| set when it
/// was built (c_min, c_max; Sec. 5.4); under the coupled friction model (kCoupled) a friction row
/// (normal_row >= 0) instead gets +-mu lambda_n, with lambda_n the current value of its contact
/// row read from `lambda` (as sequential impulse solvers do; Catto, GDC 2005). mu is
/// dimensionless.
template <bool kCoupled>
inline void force_limits(double c_min, double c_max, double mu, int normal_row,
                         const double* lambda, double& lo, double& hi) {
  if (kCoupled && normal_row >= 0) {
    hi = mu * lambda[normal_row];
    lo = -hi;
  } else {
    lo = c_min;
    hi = c_max;
  }
}

/// force_limits with the friction model chosen at run time.
inline void force_limits(bool coupled, double c_min, double c_max, double mu, int normal_row,
                         const double* lambda, double& lo, double& hi) {
  if (coupled) {
    force_limits<true>(c_min, c_max, mu, normal_row, lambda, lo, hi);
  } else {
    force_limits<false>(c_min, c_max, mu, normal_row, lambda, lo, hi);
  }
}

/// The natural-map residual of one row (N): |lambda_j - clamp(lambda_j - (A lambda - b)_j / A_jj,
/// lo, hi)|, with Ax_minus_b = (A lambda - b)_j (m/s^2 for a unit-axis row) and diagonal =
/// A_jj > 0 (1/kg).
/// It is 0 exactly when lambda_j satisfies the row's complementarity conditions, whichever method
/// produced lambda (Facchinei & Pang 2003, Sec. 1.5: the natural map).
inline double natural_map_residual(double lambda_j, double Ax_minus_b, double diagonal, double lo,
                                   double hi) {
  return std::abs(lambda_j - std::clamp(lambda_j - Ax_minus_b / diagonal, lo, hi));
}

}  // namespace cps::detail
