// The system J, M^-1, A, b of paper Sec. 6 (Eqs. 6.1.1-6.1.4, 6.2.9).
#include "system.h"

#include <stdexcept>
#include <string>

namespace cps {
namespace {

Eigen::Index body_column(int body) { return 6 * static_cast<Eigen::Index>(body); }

}  // namespace

Eigen::VectorXd system_velocity(const std::vector<Body>& bodies) {
  Eigen::VectorXd v1(6 * static_cast<Eigen::Index>(bodies.size()));
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const auto k = body_column(static_cast<int>(i));
    v1.segment<3>(k) = bodies[i].velocity();
    v1.segment<3>(k + 3) = bodies[i].angular_velocity();
  }
  return v1;
}

void gravity_forces(const std::vector<Body>& bodies, const Vec3& gravity, Eigen::VectorXd& f) {
  f.resize(6 * static_cast<Eigen::Index>(bodies.size()));  // no allocation when the size is kept
  f.setZero();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies[i].is_static()) f.segment<3>(body_column(static_cast<int>(i))) = bodies[i].mass * gravity;
  }
}

Eigen::VectorXd gravity_forces(const std::vector<Body>& bodies, const Vec3& gravity) {
  Eigen::VectorXd f;
  gravity_forces(bodies, gravity, f);
  return f;
}

Eigen::VectorXd assemble_rhs(const std::vector<ConstraintRow>& rows, const SparseRowMatrix& J,
                             const Eigen::SparseMatrix<double>& M_inv, const Eigen::VectorXd& v1,
                             const Eigen::VectorXd& f_ext, double dt, TargetTerms terms) {
  // b = v / dt - J (v1 / dt + M^-1 f_ext)   (Eq. 6.2.9)
  Eigen::VectorXd v(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    v[static_cast<Eigen::Index>(r)] = target_velocity(rows[r], terms);
  }
  if (terms == TargetTerms::push_from_rest) return v / dt;  // v1 = 0, f_ext = 0
  const Eigen::VectorXd accel = v1 / dt + M_inv * f_ext;
  return v / dt - J * accel;
}

System assemble_system(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
                       const Eigen::VectorXd& v1, const Eigen::VectorXd& f_ext, double dt,
                       TargetTerms terms) {
  const auto n = static_cast<Eigen::Index>(bodies.size());
  if (v1.size() != 6 * n || f_ext.size() != 6 * n) {
    throw std::invalid_argument("assemble_system: v1 has " + std::to_string(v1.size()) +
                                " and f_ext " + std::to_string(f_ext.size()) +
                                " entries; both must have 6n = " + std::to_string(6 * n));
  }
  System s = assemble_matrices(rows, bodies);
  s.b = assemble_rhs(rows, s.J, s.M_inv, v1, f_ext, dt, terms);
  return s;
}

System assemble_matrices(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies) {
  const auto n = static_cast<Eigen::Index>(bodies.size());
  const auto c = static_cast<Eigen::Index>(rows.size());
  System s;
  // J: one row per constraint, 12 entries at the columns of its two bodies (Sec. 6.1.2).
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(12 * c));
  s.limits.c_min.resize(c);
  s.limits.c_max.resize(c);
  s.limits.mu.resize(c);
  s.limits.normal_row.resize(static_cast<std::size_t>(c));
  for (Eigen::Index r = 0; r < c; ++r) {
    const ConstraintRow& row = rows[static_cast<std::size_t>(r)];
    for (int body : {row.body_a, row.body_b}) {
      if (body != kWorldBody && (body < 0 || body >= n)) {
        throw std::invalid_argument("assemble_matrices: row " + std::to_string(r) +
                                    " refers to body " + std::to_string(body) + "; there are " +
                                    std::to_string(n));
      }
    }
    // A fixed world point (kWorldBody) has no columns: its half of j acts on nothing.
    for (int k = 0; k < 6; ++k) {
      if (row.body_a != kWorldBody) triplets.emplace_back(r, body_column(row.body_a) + k, row.j[k]);
      if (row.body_b != kWorldBody) triplets.emplace_back(r, body_column(row.body_b) + k, row.j[k + 6]);
    }
    s.limits.c_min[r] = row.c_min;
    s.limits.c_max[r] = row.c_max;
    s.limits.mu[r] = row.mu;
    s.limits.normal_row[static_cast<std::size_t>(r)] = row.normal_row;
  }
  s.J.resize(c, 6 * n);
  s.J.setFromTriplets(triplets.begin(), triplets.end());

  // M^-1: block diagonal [m^-1 D, I^-1] (Eq. 6.1.2). Static bodies have no entries at all, so
  // two rows that share only a static body are not coupled in A.
  triplets.clear();
  for (Eigen::Index i = 0; i < n; ++i) {
    const Body& body = bodies[static_cast<std::size_t>(i)];
    if (body.is_static()) continue;
    const Mat3 I_inv = body.inv_inertia_world();
    for (int k = 0; k < 3; ++k) {
      triplets.emplace_back(6 * i + k, 6 * i + k, body.inv_mass);
      for (int m = 0; m < 3; ++m) triplets.emplace_back(6 * i + 3 + k, 6 * i + 3 + m, I_inv(k, m));
    }
  }
  s.M_inv.resize(6 * n, 6 * n);
  s.M_inv.setFromTriplets(triplets.begin(), triplets.end());

  // A = J M^-1 J^T (Eq. 6.2.9).
  const SparseRowMatrix JM = s.J * s.M_inv;
  s.A = JM * SparseRowMatrix(s.J.transpose());
  return s;
}

}  // namespace cps
