// The matrix-free solve (see matrix_free.h): PGS and Jacobi over rows, with w = M^-1 J^T lambda
// per body in place of A = J M^-1 J^T.
#include "cps/matrix_free.h"

#include <algorithm>
#include <cmath>

namespace cps {
namespace {

// M^-1 j^T for one body's half of a row (6): [m^-1 j_lin, I^-1 j_ang].
void minv_times(const Body& body, const double* j, double* out) {
  const Vec3 lin = body.inv_mass * Vec3(j[0], j[1], j[2]);
  const Vec3 ang = body.inv_inertia_world() * Vec3(j[3], j[4], j[5]);
  for (int k = 0; k < 3; ++k) {
    out[k] = lin[k];
    out[k + 3] = ang[k];
  }
}

double dot6(const double* a, const Vec6& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
}

// j_j . w over the row's bodies: sum_i A_ji lambda_i.
double row_times_w(const ConstraintRow& r, const std::vector<Vec6>& w) {
  double d = 0.0;
  if (r.body_a != kWorldBody) d += dot6(r.j.data(), w[static_cast<std::size_t>(r.body_a)]);
  if (r.body_b != kWorldBody) d += dot6(r.j.data() + 6, w[static_cast<std::size_t>(r.body_b)]);
  return d;
}

void add_to_w(const ConstraintRow& r, const std::array<double, 12>& minv_jt, double delta,
              std::vector<Vec6>& w) {
  if (r.body_a != kWorldBody) {
    Vec6& wa = w[static_cast<std::size_t>(r.body_a)];
    for (int k = 0; k < 6; ++k) wa[k] += delta * minv_jt[static_cast<std::size_t>(k)];
  }
  if (r.body_b != kWorldBody) {
    Vec6& wb = w[static_cast<std::size_t>(r.body_b)];
    for (int k = 0; k < 6; ++k) wb[k] += delta * minv_jt[static_cast<std::size_t>(k + 6)];
  }
}

void bounds(const ConstraintRow& r, FrictionModel friction, const std::vector<double>& lambda,
            double& lo, double& hi) {
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
  s.minv_jt.resize(rows.size());
  s.diagonal.resize(rows.size());
  s.w.resize(bodies.size());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const ConstraintRow& row = rows[r];
    std::array<double, 12>& m = s.minv_jt[r];
    m.fill(0.0);
    double diagonal = 0.0;
    if (row.body_a != kWorldBody) {
      minv_times(bodies[static_cast<std::size_t>(row.body_a)], row.j.data(), m.data());
      for (int k = 0; k < 6; ++k) diagonal += row.j[k] * m[static_cast<std::size_t>(k)];
    }
    if (row.body_b != kWorldBody) {
      minv_times(bodies[static_cast<std::size_t>(row.body_b)], row.j.data() + 6, m.data() + 6);
      for (int k = 6; k < 12; ++k) diagonal += row.j[k] * m[static_cast<std::size_t>(k)];
    }
    s.diagonal[r] = diagonal;
  }
}

void rhs(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
         const std::vector<Body>& bodies, const Vec3& gravity, double dt, TargetTerms terms) {
  s.b.resize(rows.size());
  // a = v1 / dt + M^-1 f_ext per body, in w's storage (overwritten by solve()).
  s.w.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& body = bodies[i];
    Vec6& a = s.w[i];
    a.head<3>() = body.velocity() / dt;
    a.tail<3>() = body.angular_velocity() / dt;
    if (!body.is_static()) a.head<3>() += body.inv_mass * (body.mass * gravity);
  }
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const double v = rows[r].bias + (terms == TargetTerms::push_and_bias ? rows[r].push : 0.0);
    s.b[r] = v / dt - row_times_w(rows[r], s.w);
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
      // b_j - sum_{i != j} A_ji lambda_i = b_j - (j_j . w - A_jj lambda_j)   (Eq. 7.1.1)
      const double sum = s.b[j] - (row_times_w(rows[j], s.w) - diagonal * lambda[j]);
      double lo;
      double hi;
      bounds(rows[j], friction, lambda, lo, hi);
      const double value = std::clamp(sum / diagonal, lo, hi);
      if (jacobi) {
        s.next[j] = value;
      } else {
        add_to_w(rows[j], s.minv_jt[j], value - lambda[j], s.w);
        lambda[j] = value;
      }
    }
    if (jacobi) {
      for (std::size_t j = 0; j < c; ++j) {
        if (!(s.diagonal[j] > 0.0)) continue;
        add_to_w(rows[j], s.minv_jt[j], s.next[j] - lambda[j], s.w);
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
    const double Ax = row_times_w(rows[j], s.w);
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
