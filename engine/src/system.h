#pragma once
// The system of paper Sec. 6: J, M^-1, f_ext, v1 and A lambda = b (Eq. 6.2.9).
//
// For n bodies and c rows:
//   v1     6n     system velocity [v_1, w_1, ..., v_n, w_n] (m/s, rad/s)        (Eq. 6.1.1)
//   J      c x 6n one row j_c per constraint, at the columns of its two bodies  (Sec. 6.1.2)
//   M^-1   6n x 6n block diagonal [m_i^-1 D, I_i^-1]                            (Eq. 6.1.2)
//   f_ext  6n     force and torque per body (N, N m)                           (Eq. 6.1.3)
//   v      c      target velocities, push factor and bias (m/s)                 (Eq. 6.1.4)
//   A = J M^-1 J^T (c x c),  b = v / dt - J (v1 / dt + M^-1 f_ext) (c)          (Eq. 6.2.9)
// The constraint force is f_c = J^T lambda (6n, Eq. 6.2.1).

#include "cps/body.h"
#include "cps/constraint.h"
#include "cps/step_system.h"

#include <Eigen/SparseCore>

#include <vector>

namespace cps {

using SparseRowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// TargetTerms (which parts of a row's target velocity enter v) is public: cps/step_system.h.

/// The target velocity v_j (m/s) of a row in a solve of these terms: push + bias, bias, or push.
inline double target_velocity(const ConstraintRow& row, TargetTerms terms) {
  switch (terms) {
    case TargetTerms::push_and_bias: return row.bias + row.push;
    case TargetTerms::bias_only: return row.bias;
    case TargetTerms::push_from_rest: return row.push;
  }
  return 0.0;
}


/// The bounds on lambda, per row (c each): c_min, c_max (N); for friction rows also the index
/// of their contact row and mu (dimensionless), for the coupled friction limit; -1 and 0 for
/// other rows.
struct RowLimits {
  Eigen::VectorXd c_min;
  Eigen::VectorXd c_max;
  std::vector<int> normal_row;
  Eigen::VectorXd mu;
};

/// The assembled system. Sizes as in the header comment.
struct System {
  SparseRowMatrix J;
  Eigen::SparseMatrix<double> M_inv;
  SparseRowMatrix A;
  Eigen::VectorXd b;
  RowLimits limits;
};

/// v1 (6n): [v_i, w_i] per body in body order.
Eigen::VectorXd system_velocity(const std::vector<Body>& bodies);

/// f_ext (6n): [m_i g, 0] per movable body (gravity in m/s^2), zero for static bodies.
Eigen::VectorXd gravity_forces(const std::vector<Body>& bodies, const Vec3& gravity);

/// The same into `f`, resized to 6n (no allocation when f already has that size).
void gravity_forces(const std::vector<Body>& bodies, const Vec3& gravity, Eigen::VectorXd& f);

/// Assembles J, M^-1, A and b from the rows (Eq. 6.2.9). v1 and f_ext have 6n entries for
/// n = bodies.size(); dt > 0 in s. Throws std::invalid_argument on mismatched sizes or a row
/// whose body indices are out of range.
System assemble_system(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
                       const Eigen::VectorXd& v1, const Eigen::VectorXd& f_ext, double dt,
                       TargetTerms terms);

/// J, M^-1, A and the limits of the rows, without b (left empty). Throws std::invalid_argument for
/// a row whose body indices are out of range.
System assemble_matrices(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies);

/// Right-hand side b alone (c), for a second solve that reuses J and A (Eq. 6.2.9).
Eigen::VectorXd assemble_rhs(const std::vector<ConstraintRow>& rows, const SparseRowMatrix& J,
                             const Eigen::SparseMatrix<double>& M_inv, const Eigen::VectorXd& v1,
                             const Eigen::VectorXd& f_ext, double dt, TargetTerms terms);

}  // namespace cps
