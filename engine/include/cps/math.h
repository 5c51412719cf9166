#pragma once
// Vector, matrix and quaternion types of the engine (Eigen, double precision, SI units).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>

namespace cps {

using Vec3 = Eigen::Vector3d;      ///< 3-vector (unit given where used)
using Mat3 = Eigen::Matrix3d;      ///< 3 x 3 matrix
using Quat = Eigen::Quaterniond;   ///< orientation o = [w, x, y, z], unit length
using Vec12 = Eigen::Matrix<double, 12, 1>;  ///< one constraint row j_c: [lin a, ang a, lin b, ang b]

/// Positive infinity, used for unbounded constraint force limits c_max (N).
inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// True if every component of v is finite. Unlike Eigen's allFinite() (which computes x - x)
/// it raises no floating point exception on inf, so validation works with traps enabled.
template <class Derived>
bool all_finite(const Eigen::MatrixBase<Derived>& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v.derived().coeff(i))) return false;
  }
  return true;
}

}  // namespace cps
