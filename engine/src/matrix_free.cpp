// The matrix-free solve (see matrix_free.h): PGS and Jacobi over rows, with w = M^-1 J^T lambda
// per body in place of A = J M^-1 J^T.
#include "cps/matrix_free.h"

#include <algorithm>
#include <cmath>

namespace cps {
namespace {

using PackedRow = MatrixFreeSystem::Row;

// j_j . w over the row's bodies: sum_i A_ji lambda_i.
inline double row_times_w(const PackedRow& r, const std::vector<Vec6>& w) {
  const Vec6& wa = w[static_cast<std::size_t>(r.a)];
  const Vec6& wb = w[static_cast<std::size_t>(r.b)];
  double d = 0.0;
  for (int k = 0; k < 6; ++k) d += r.j[static_cast<std::size_t>(k)] * wa[k];
  for (int k = 0; k < 6; ++k) d += r.j[static_cast<std::size_t>(k + 6)] * wb[k];
  return d;
}

inline void add_to_w(const PackedRow& r, double delta, std::vector<Vec6>& w) {
  Vec6& wa = w[static_cast<std::size_t>(r.a)];
  Vec6& wb = w[static_cast<std::size_t>(r.b)];
  for (int k = 0; k < 6; ++k) wa[k] += delta * r.minv_jt[static_cast<std::size_t>(k)];
  for (int k = 0; k < 6; ++k) wb[k] += delta * r.minv_jt[static_cast<std::size_t>(k + 6)];
}

inline void bounds(const ConstraintRow& r, FrictionModel friction,
                   const std::vector<double>& lambda, double& lo, double& hi) {
  if (friction == FrictionModel::coupled && r.normal_row >= 0) {
    hi = r.mu * lambda[static_cast<std::size_t>(r.normal_row)];
    lo = -hi;
  } else {
    lo = r.c_min;
    hi = r.c_max;
  }
}

}  // namespace

void prepare(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
             const std::vector<Body>& bodies) {
  const int n = static_cast<int>(bodies.size());
  s.inv_inertia.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) s.inv_inertia[i] = bodies[i].inv_inertia_world();
  s.rows.resize(rows.size());
  s.diagonal.resize(rows.size());
  s.w.resize(bodies.size() + 1);  // slot n: the fixed world, always 0
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const ConstraintRow& row = rows[r];
    PackedRow& p = s.rows[r];
    p.a = row.body_a == kWorldBody ? n : row.body_a;
    p.b = row.body_b == kWorldBody ? n : row.body_b;
    p.minv_jt.fill(0.0);
    double diagonal = 0.0;
    for (int half = 0; half < 2; ++half) {
      const int body = half == 0 ? row.body_a : row.body_b;
      const int o = 6 * half;
      for (int k = 0; k < 6; ++k) p.j[static_cast<std::size_t>(o + k)] = row.j[o + k];
      if (body == kWorldBody) continue;
      const Body& bd = bodies[static_cast<std::size_t>(body)];
      const Vec3 lin = bd.inv_mass * row.j.segment<3>(o);
      const Vec3 ang = s.inv_inertia[static_cast<std::size_t>(body)] * row.j.segment<3>(o + 3);
      for (int k = 0; k < 3; ++k) {
        p.minv_jt[static_cast<std::size_t>(o + k)] = lin[k];
        p.minv_jt[static_cast<std::size_t>(o + 3 + k)] = ang[k];
      }
      for (int k = 0; k < 6; ++k) {
        diagonal += row.j[o + k] * p.minv_jt[static_cast<std::size_t>(o + k)];
      }
    }
    s.diagonal[r] = diagonal;
  }
}

void rhs(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
         const std::vector<Body>& bodies, const Vec3& gravity, double dt, TargetTerms terms) {
  s.b.resize(rows.size());
  // a = v1 / dt + M^-1 f_ext per body, in w's storage (solve() overwrites it).
  s.w.resize(bodies.size() + 1);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& body = bodies[i];
    Vec6& a = s.w[i];
    a.head<3>() = body.inv_mass * body.p / dt;
    a.tail<3>() = s.inv_inertia[i] * body.l / dt;
    if (!body.is_static()) a.head<3>() += body.inv_mass * (body.mass * gravity);
  }
  s.w.back().setZero();
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const double v = rows[r].bias + (terms == TargetTerms::push_and_bias ? rows[r].push : 0.0);
    s.b[r] = v / dt - row_times_w(s.rows[r], s.w);
  }
}

void solve(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows, FrictionModel friction,
           SolverKind kind, int iterations, std::vector<double>& lambda) {
  const std::size_t c = rows.size();
  lambda.assign(c, 0.0);  // initial guess 0
  for (Vec6& w : s.w) w.setZero();
  const bool jacobi = kind == SolverKind::jacobi;
  if (jacobi) s.next.assign(c, 0.0);
  for (int k = 0; k < iterations; ++k) {
    for (std::size_t j = 0; j < c; ++j) {
      const double diagonal = s.diagonal[j];
      if (!(diagonal > 0.0)) continue;  // the row touches no movable body: lambda_j stays 0
      const PackedRow& row = s.rows[j];
      // b_j - sum_{i != j} A_ji lambda_i = b_j - (j_j . w - A_jj lambda_j)   (Eq. 7.1.1)
      const double sum = s.b[j] - (row_times_w(row, s.w) - diagonal * lambda[j]);
      double lo;
      double hi;
      bounds(rows[j], friction, lambda, lo, hi);
      const double value = std::clamp(sum / diagonal, lo, hi);
      if (jacobi) {
        s.next[j] = value;
      } else {
        add_to_w(row, value - lambda[j], s.w);
        lambda[j] = value;
      }
    }
    if (jacobi) {
      for (std::size_t j = 0; j < c; ++j) {
        if (!(s.diagonal[j] > 0.0)) continue;
        add_to_w(s.rows[j], s.next[j] - lambda[j], s.w);
        lambda[j] = s.next[j];
      }
    }
  }
}

void residual(const MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
              FrictionModel friction, const std::vector<double>& lambda, double& max,
              double& sum_squares) {
  max = 0.0;
  sum_squares = 0.0;
  for (std::size_t j = 0; j < rows.size(); ++j) {
    const double diagonal = s.diagonal[j];
    if (!(diagonal > 0.0)) continue;
    double lo;
    double hi;
    bounds(rows[j], friction, lambda, lo, hi);
    const double Ax = row_times_w(s.rows[j], s.w);
    const double r = std::abs(lambda[j] - std::clamp(lambda[j] - (Ax - s.b[j]) / diagonal, lo, hi));
    max = std::max(max, r);
    sum_squares += r * r;
  }
}

void add_constraint_forces(const std::vector<ConstraintRow>& rows,
                           const std::vector<double>& lambda, Eigen::VectorXd& f) {
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const ConstraintRow& row = rows[r];
    if (row.body_a != kWorldBody) f.segment<6>(6 * row.body_a) += lambda[r] * row.j.head<6>();
    if (row.body_b != kWorldBody) f.segment<6>(6 * row.body_b) += lambda[r] * row.j.tail<6>();
  }
}

}  // namespace cps
