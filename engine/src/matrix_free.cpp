// The matrix-free solve (see matrix_free.h): PGS and Jacobi over rows, with w = M^-1 J^T lambda
// per body in place of A = J M^-1 J^T.
#include "cps/matrix_free.h"

#include "buffers.h"

#include <algorithm>
#include <cmath>

namespace cps {
namespace {

using PackedRow = MatrixFreeSystem::Row;
using ConstMap6 = Eigen::Map<const Vec6, Eigen::Aligned16>;

// j_j . w over the row's bodies: sum_i A_ji lambda_i. Two 6-vector dot products (Eigen sums each
// in pairs, so the additions do not form one long chain).
inline double row_times_w(const PackedRow& r, const std::vector<Vec6>& w) {
  return ConstMap6(r.j.data()).dot(w[static_cast<std::size_t>(r.a)]) +
         ConstMap6(r.j.data() + 6).dot(w[static_cast<std::size_t>(r.b)]);
}

// w += M^-1 j^T delta for the row's movable bodies. The fixed slot (static bodies and the world)
// is never written: M^-1 is 0 there, and rows that share only a static body then do not wait on
// each other's stores.
inline void add_to_w(const PackedRow& r, double delta, std::vector<Vec6>& w, int fixed_slot) {
  if (r.a != fixed_slot) w[static_cast<std::size_t>(r.a)] += delta * ConstMap6(r.minv_jt.data());
  if (r.b != fixed_slot) w[static_cast<std::size_t>(r.b)] += delta * ConstMap6(r.minv_jt.data() + 6);
}

template <bool kCoupled>
inline void bounds(const PackedRow& r, const std::vector<double>& lambda, double& lo, double& hi) {
  if (kCoupled && r.normal_row >= 0) {
    hi = r.mu * lambda[static_cast<std::size_t>(r.normal_row)];
    lo = -hi;
  } else {
    lo = r.c_min;
    hi = r.c_max;
  }
}

// The sweeps of solve(), with the solver kind and friction model fixed at compile time so the
// inner loop has no branches on them. Row j's new value (Eq. 7.1.1):
//   (b_j - sum_{i != j} A_ji lambda_i) / A_jj = lambda_j + (b_j - j_j . w) / A_jj
template <bool kJacobi, bool kCoupled>
void sweeps(MatrixFreeSystem& s, int iterations, std::vector<double>& lambda) {
  const std::size_t c = s.rows.size();
  const PackedRow* rows = s.rows.data();
  const double* b = s.b.data();
  double* l = lambda.data();
  const int fixed_slot = static_cast<int>(s.w.size()) - 1;
  for (int k = 0; k < iterations; ++k) {
    for (std::size_t j = 0; j < c; ++j) {
      const PackedRow& row = rows[j];
      if (row.inv_diagonal == 0.0) continue;  // the row touches no movable body: lambda_j stays 0
      double lo;
      double hi;
      bounds<kCoupled>(row, lambda, lo, hi);
      const double value = std::clamp(l[j] + (b[j] - row_times_w(row, s.w)) * row.inv_diagonal, lo, hi);
      if constexpr (kJacobi) {
        s.next[j] = value;
      } else {
        add_to_w(row, value - l[j], s.w, fixed_slot);
        l[j] = value;
      }
    }
    if constexpr (kJacobi) {
      for (std::size_t j = 0; j < c; ++j) {
        if (rows[j].inv_diagonal == 0.0) continue;
        add_to_w(rows[j], s.next[j] - l[j], s.w, fixed_slot);
        l[j] = s.next[j];
      }
    }
  }
}

}  // namespace

void prepare(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
             const std::vector<Body>& bodies) {
  const int n = static_cast<int>(bodies.size());
  detail::resize_with_headroom(s.inv_inertia, bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) s.inv_inertia[i] = bodies[i].inv_inertia_world();
  detail::resize_with_headroom(s.rows, rows.size());
  detail::resize_with_headroom(s.diagonal, rows.size());
  detail::resize_with_headroom(s.w, bodies.size() + 1);  // slot n: static bodies and the fixed world, always 0
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const ConstraintRow& row = rows[r];
    PackedRow& p = s.rows[r];
    // Static bodies and the fixed world share slot n, whose w stays 0 (M^-1 = 0 there).
    const auto slot = [&](int body) {
      return body == kWorldBody || bodies[static_cast<std::size_t>(body)].is_static() ? n : body;
    };
    p.a = slot(row.body_a);
    p.b = slot(row.body_b);
    p.c_min = row.c_min;
    p.c_max = row.c_max;
    p.mu = row.mu;
    p.normal_row = row.normal_row;
    p.minv_jt.fill(0.0);
    double diagonal = 0.0;
    for (int half = 0; half < 2; ++half) {
      const int body = half == 0 ? row.body_a : row.body_b;
      const int o = 6 * half;
      for (int k = 0; k < 6; ++k) p.j[static_cast<std::size_t>(o + k)] = row.j[o + k];
      if (body == kWorldBody) continue;
      const Body& bd = bodies[static_cast<std::size_t>(body)];
      if (bd.is_static()) continue;  // M^-1 = 0: nothing to add
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
    p.inv_diagonal = diagonal > 0.0 ? 1.0 / diagonal : 0.0;
  }
}

void rhs(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
         const std::vector<Body>& bodies, const Vec3& gravity, double dt, TargetTerms terms) {
  detail::resize_with_headroom(s.b, rows.size());
  // a = v1 / dt + M^-1 f_ext per body, in w's storage (solve() overwrites it).
  detail::resize_with_headroom(s.w, bodies.size() + 1);
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
  detail::assign_with_headroom(lambda, rows.size(), 0.0);  // initial guess 0
  for (Vec6& w : s.w) w.setZero();
  const bool coupled = friction == FrictionModel::coupled;
  if (kind == SolverKind::jacobi) {
    detail::assign_with_headroom(s.next, rows.size(), 0.0);
    coupled ? sweeps<true, true>(s, iterations, lambda) : sweeps<true, false>(s, iterations, lambda);
  } else {
    coupled ? sweeps<false, true>(s, iterations, lambda) : sweeps<false, false>(s, iterations, lambda);
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
    if (friction == FrictionModel::coupled) {
      bounds<true>(s.rows[j], lambda, lo, hi);
    } else {
      bounds<false>(s.rows[j], lambda, lo, hi);
    }
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
