// The distance of a lambda to the set of exact solutions of a captured step (see exact_lcp.h,
// ExactSolution::Distance).
//
// With p = x_F - lambda*_F on the free rows F (the others are fixed), the set is
// {p = N z : l <= p <= u}, N the null basis of A_FF, l and u the bounds less lambda*_F. The
// projection of v = y_F - lambda*_F onto it is a convex quadratic program; its Lagrangian dual,
// relaxing the bounds with multipliers m (m_j >= 0 pushing from the upper bound, <= 0 from the
// lower, 0 where that bound is infinite), is
//   g(m) = min over p = N z of 1/2 |p - v|^2 + m.p - sum_j m_j (m_j > 0 ? u_j : l_j),
// whose minimiser is p = N N^T (v - m), and g(m) <= 1/2 dist^2 for every such m (weak duality;
// Boyd & Vandenberghe 2004, Sec. 5.2). Any multipliers thus give a lower bound, and any member of
// the set an upper one: the interval is certified whatever the iteration did.
#include "exact_lcp.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace cps::analysis {
namespace {

// Dykstra's sweeps before the active-set steps (each costs two products with N, f x d).
constexpr int kDykstraSweeps = 400;
// Active-set steps after them: each solves the projection with the guessed rows on their bounds.
constexpr int kActiveSetRounds = 30;
// A member lies within the bounds to kFeasible of the force scale; the interval is exact when
// narrower than kGap of the force scale or of the distance, whichever is larger (the dual bound
// carries round-off of the distance's own size).
constexpr double kFeasible = 1e-9;
constexpr double kGap = 1e-6;

// The free rows' projection problem in shifted coordinates (see the file comment).
struct Shifted {
  const Eigen::MatrixXd& N;  // f x d, orthonormal columns
  Eigen::VectorXd l;         // f, N: lower bounds less lambda*_F (<= 0; -inf allowed)
  Eigen::VectorXd u;         // f, N: upper bounds less lambda*_F (>= 0; +inf allowed)
  Eigen::VectorXd v;         // f, N: y_F - lambda*_F
};

Eigen::VectorXd onto_affine(const Eigen::MatrixXd& N, const Eigen::VectorXd& p) {
  return N * (N.transpose() * p);
}

// 2 g(m) (N^2), the dual bound of the squared distance; m is cleaned to the signs it may take.
double dual_bound(const Shifted& q, Eigen::VectorXd m) {
  for (Eigen::Index j = 0; j < m.size(); ++j) {
    if ((m[j] > 0.0 && !std::isfinite(q.u[j])) || (m[j] < 0.0 && !std::isfinite(q.l[j])) ||
        !std::isfinite(m[j])) {
      m[j] = 0.0;
    }
  }
  const Eigen::VectorXd p = onto_affine(q.N, q.v - m);
  double g = 0.5 * (p - q.v).squaredNorm() + m.dot(p);
  for (Eigen::Index j = 0; j < m.size(); ++j) {
    if (m[j] != 0.0) g -= m[j] * (m[j] > 0.0 ? q.u[j] : q.l[j]);
  }
  return 2.0 * g;
}

// Whether p lies within the bounds to `tol` (N).
bool within(const Shifted& q, const Eigen::VectorXd& p, double tol) {
  for (Eigen::Index j = 0; j < p.size(); ++j) {
    if (p[j] < q.l[j] - tol || p[j] > q.u[j] + tol) return false;
  }
  return true;
}

// The best point of the set and the best dual bound found so far.
struct Best {
  Eigen::VectorXd p;              // f, a member (p = 0 is lambda* itself)
  double squared = 0.0;           // |p - v|^2
  double bound = 0.0;             // the best 2 g(m)
  void offer_point(const Shifted& q, const Eigen::VectorXd& candidate, double tol) {
    if (!within(q, candidate, tol)) return;
    const double d = (candidate - q.v).squaredNorm();
    if (d < squared) {
      p = candidate;
      squared = d;
    }
  }
  void offer_bound(const Shifted& q, const Eigen::VectorXd& m) { bound = std::max(bound, dual_bound(q, m)); }
};

// Whether the interval [sqrt(bound), sqrt(squared)] is narrower than distance() asks.
bool closed(const Best& best, double scale) {
  const double upper = std::sqrt(best.squared);
  return upper - std::sqrt(std::max(0.0, best.bound)) <= kGap * std::max(scale, upper);
}

// One active-set step: the projection of v onto {p = N z, p_j = bound_j for side_j != 0}
// (least-norm where the rows on their bounds are dependent), and its multipliers m (f; non-zero
// on those rows only): v - p = m + (a part orthogonal to N's columns).
void active_set_step(const Shifted& q, const std::vector<int>& side, Eigen::VectorXd& p,
                     Eigen::VectorXd& m) {
  const Eigen::Index f = q.v.size();
  std::vector<Eigen::Index> rows;
  for (Eigen::Index j = 0; j < f; ++j) {
    if (side[static_cast<std::size_t>(j)] != 0) rows.push_back(j);
  }
  const Eigen::VectorXd z0 = q.N.transpose() * q.v;
  Eigen::VectorXd z = z0;
  m = Eigen::VectorXd::Zero(f);
  if (!rows.empty()) {
    const auto a = static_cast<Eigen::Index>(rows.size());
    Eigen::MatrixXd N_a(a, q.N.cols());
    Eigen::VectorXd c_a(a);
    for (Eigen::Index k = 0; k < a; ++k) {
      const Eigen::Index j = rows[static_cast<std::size_t>(k)];
      N_a.row(k) = q.N.row(j);
      c_a[k] = side[static_cast<std::size_t>(j)] > 0 ? q.u[j] : q.l[j];
    }
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> rows_on_bounds(N_a);
    z += rows_on_bounds.solve(c_a - N_a * z0);
    // z0 - z = N_a^T nu: nu is the least-norm solution of that (N_a^T has full column rank
    // unless the rows on their bounds are dependent).
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> normals(N_a.transpose());
    const Eigen::VectorXd nu = normals.solve(z0 - z);
    for (Eigen::Index k = 0; k < a; ++k) m[rows[static_cast<std::size_t>(k)]] = nu[k];
  }
  p = q.N * z;
}

// The projection of q.v onto the set, as far as it can be certified (see the file comment).
Best project(const Shifted& q, double scale) {
  const Eigen::Index f = q.v.size();
  const double tol = kFeasible * scale;
  Best best;
  best.p = Eigen::VectorXd::Zero(f);
  best.squared = q.v.squaredNorm();
  // The projection onto the affine set: exact when it lies within the bounds.
  const Eigen::VectorXd a0 = onto_affine(q.N, q.v);
  best.offer_bound(q, Eigen::VectorXd::Zero(f));  // |v - a0|^2: the distance to the affine set
  best.offer_point(q, a0, tol);
  if (closed(best, scale)) return best;
  // Dykstra's alternating projections between the affine set (no correction term needed: it is a
  // subspace in these coordinates) and the box, whose correction q_box is the box's multiplier.
  Eigen::VectorXd p = q.v;
  Eigen::VectorXd q_box = Eigen::VectorXd::Zero(f);
  Eigen::VectorXd a = a0;
  for (int k = 0; k < kDykstraSweeps; ++k) {
    a = onto_affine(q.N, p);
    const Eigen::VectorXd t = a + q_box;
    const Eigen::VectorXd next = t.cwiseMax(q.l).cwiseMin(q.u);
    q_box = t - next;
    const double change = (next - p).cwiseAbs().maxCoeff();
    p = next;
    if (change <= 1e-3 * tol) break;
  }
  best.offer_bound(q, q_box);
  best.offer_point(q, a, tol);
  // Shrinking the affine iterate towards lambda* (p = 0, a member) until it is within the bounds.
  double t = 1.0;
  for (Eigen::Index j = 0; j < f; ++j) {
    if (a[j] > q.u[j]) t = std::min(t, q.u[j] / a[j]);
    if (a[j] < q.l[j]) t = std::min(t, q.l[j] / a[j]);
  }
  best.offer_point(q, t * a, tol);
  // Active-set steps from the rows Dykstra holds on a bound: add the rows the step leaves
  // beyond a bound, release those whose multiplier pulls.
  std::vector<int> side(static_cast<std::size_t>(f), 0);
  for (Eigen::Index j = 0; j < f; ++j) side[static_cast<std::size_t>(j)] = q_box[j] > 0.0 ? 1 : q_box[j] < 0.0 ? -1 : 0;
  Eigen::VectorXd m;
  for (int round = 0; round < kActiveSetRounds; ++round) {
    active_set_step(q, side, p, m);
    best.offer_point(q, p, tol);
    best.offer_bound(q, m);
    if (closed(best, scale)) break;
    bool changed = false;
    for (Eigen::Index j = 0; j < f; ++j) {
      int& s = side[static_cast<std::size_t>(j)];
      const int want = p[j] > q.u[j] + tol ? 1 : p[j] < q.l[j] - tol ? -1 : s != 0 && m[j] * s < -tol ? 0 : s;
      changed = changed || want != s;
      s = want;
    }
    if (!changed) break;
  }
  return best;
}

}  // namespace

ExactSolution::Distance ExactSolution::distance(const StepSystem& s, const Eigen::VectorXd& y) const {
  if (y.size() != lambda.size()) {
    throw std::invalid_argument("distance: lambda has " + std::to_string(y.size()) +
                                " entries; the system has " + std::to_string(lambda.size()) + " rows");
  }
  if (!y.allFinite()) throw std::invalid_argument("distance: lambda has a non-finite entry");
  Distance out;
  out.nearest = lambda;
  if (s.friction != FrictionModel::fixed || null_basis.cols() == 0) {
    out.upper_N = (y - lambda).norm();
    // The unique solution (fixed friction), or the one found (coupled: no lower bound).
    out.lower_N = s.friction == FrictionModel::fixed ? out.upper_N : 0.0;
    out.exact = out.upper_N == out.lower_N;
    return out;
  }
  const auto f = static_cast<Eigen::Index>(free_rows.size());
  Shifted q{null_basis, Eigen::VectorXd(f), Eigen::VectorXd(f), Eigen::VectorXd(f)};
  for (Eigen::Index k = 0; k < f; ++k) {
    const int j = free_rows[static_cast<std::size_t>(k)];
    q.l[k] = s.c_min[j] - lambda[j];
    q.u[k] = s.c_max[j] - lambda[j];
    q.v[k] = y[j] - lambda[j];
  }
  const Best best = project(q, force_scale_N);
  for (Eigen::Index k = 0; k < f; ++k) out.nearest[free_rows[static_cast<std::size_t>(k)]] += best.p[k];
  const double fixed_part = (y - lambda).squaredNorm() - q.v.squaredNorm();  // rows outside F
  out.upper_N = (y - out.nearest).norm();
  out.lower_N = std::min(out.upper_N, std::sqrt(std::max(0.0, fixed_part) + std::max(0.0, best.bound)));
  out.exact = out.upper_N - out.lower_N <= kGap * std::max(force_scale_N, out.upper_N);
  return out;
}

}  // namespace cps::analysis
