// The exact solve of a captured step (see exact_lcp.h).
#include "exact_lcp.h"

#include "shared_library.h"

#include <Eigen/Dense>

#include <siconos/numerics/LCP_Solvers.h>
#include <siconos/numerics/LinearComplementarityProblem.h>
#include <siconos/numerics/NumericsMatrix.h>
#include <siconos/numerics/SolverOptions.h>
#include <siconos/numerics/lcp_cst.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

namespace cps::analysis {
namespace {

// The solution set: a row whose |w*_j| / A_jj is over this part of the force scale is held at its
// bound in every exact solution; eigenvalues of A_FF below kNullTolerance of the largest count as 0.
constexpr double kActiveTolerance = 1e-9;
constexpr double kNullTolerance = 1e-10;
// Coupled friction: at most this many polish rounds (each with the bounds of the last lambda).
constexpr int kMaxFixedPoint = 20;
// Sweeps of the projected Gauss-Seidel start used when Lemke stops (pgs_start): enough for the
// active set of the paper's scenes (PGS converges in velocity there; docs/exact_reference.md).
constexpr int kFallbackSweeps = 2000;
// The proximal point start used when both starts above fail (proximal_start): the weights eps
// tried in turn, as parts of A's largest diagonal entry (1/kg), and the iterations of each.
constexpr double kProximalWeights[] = {1e-5, 1e-6, 1e-7};
constexpr int kProximalIterations = 100;
// Active-set passes of one strictly convex problem of the proximal point start (it ends sooner
// when the active set repeats).
constexpr int kDefinitePasses = 50;

// The bounds of a box problem, per row (N).
struct Box {
  Eigen::VectorXd lo;
  Eigen::VectorXd hi;
};

// Row j touches a movable body (A_jj > 0); the engine's sweeps keep the others at 0.
std::vector<bool> movable_rows(const Eigen::MatrixXd& A) {
  std::vector<bool> movable(static_cast<std::size_t>(A.rows()));
  for (Eigen::Index j = 0; j < A.rows(); ++j) movable[static_cast<std::size_t>(j)] = A(j, j) > 0.0;
  return movable;
}

// The force scale of the problem (N): the largest of |lambda|, |b_j| / A_jj over the movable rows,
// so that tolerances follow the magnitudes (1 when everything is 0).
double force_scale(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lambda) {
  double scale = 0.0;
  for (Eigen::Index j = 0; j < A.rows(); ++j) {
    if (!(A(j, j) > 0.0)) continue;
    scale = std::max({scale, std::abs(lambda[j]), std::abs(b[j]) / A(j, j)});
  }
  return scale > 0.0 ? scale : 1.0;
}

// Siconos numerics' functions cps calls, resolved in its library by the first exact solve
// (siconos()), not at start-up: the library brings BLAS and LAPACK, and Debian's OpenBLAS starts
// threads when it is loaded that spin about 0.1 s of CPU time (docs/benchmarks.md), in every cps
// process, most of which never solve exactly.
struct SiconosFunctions {
  std::string library;
  decltype(&NM_create_from_data) create_from_data = nullptr;
  decltype(&NM_clear) clear = nullptr;
  decltype(&solver_options_create) options_create = nullptr;
  decltype(&solver_options_delete) options_delete = nullptr;
  decltype(&lcp_lexicolemke) lexicolemke = nullptr;
};

SiconosFunctions open_siconos() {
  const std::string what = "Siconos numerics' library";
  const std::string hint = "; the exact solve needs it: install Debian's libsiconos-numerics7 "
                           "(libsiconos-numerics-dev to build cps)";
  const detail::SharedLibrary lib =
      detail::open_shared_library("CPS_SICONOS_LIBRARY", CPS_SICONOS_SONAME, what, hint);
  SiconosFunctions f;
  f.library = lib.file;
  detail::resolve_symbol(lib, "NM_create_from_data", what, hint, f.create_from_data);
  detail::resolve_symbol(lib, "NM_clear", what, hint, f.clear);
  detail::resolve_symbol(lib, "solver_options_create", what, hint, f.options_create);
  detail::resolve_symbol(lib, "solver_options_delete", what, hint, f.options_delete);
  detail::resolve_symbol(lib, "lcp_lexicolemke", what, hint, f.lexicolemke);
  return f;
}

const SiconosFunctions& siconos() {
  // Initialised once, thread-safe; an exception leaves it for the next call to try again.
  static const SiconosFunctions functions = open_siconos();
  return functions;
}

// Owns the Siconos objects of one LCP solve.
struct SiconosLcp {
  LinearComplementarityProblem problem{};
  SolverOptions* options = nullptr;
  ~SiconosLcp() {
    if (options != nullptr) siconos().options_delete(options);
    if (problem.M != nullptr) {
      siconos().clear(problem.M);  // frees the dense data (malloc'ed below)
      std::free(problem.M);
    }
  }
};

// The coupling of friction rows to their contact rows (FrictionModel::coupled): per row, its
// contact row and mu (normal_row -1: bounds fixed by the box).
struct Coupling {
  std::vector<int> normal_row;
  Eigen::VectorXd mu;
};

// Solves the box problem lo <= x <= hi, w = A x - b, x_j = lo_j => w_j >= 0, x_j = hi_j =>
// w_j <= 0, else w_j = 0, for the movable rows (the others: x_j = 0), by Lemke on a standard LCP
// 0 <= z  _|_  M z + q >= 0:
//   x = x0 + P s, with x0_j = lo_j (lo finite), hi_j (only hi finite), 0 (free), and one
//   variable s_k per finite bound (sign +1 from lo, -1 from hi), two for a free row (its + and -
//   parts); s_k's complementary quantity is sign_k w_{row k}. A row with both bounds finite also
//   gets a slack t_j >= 0 with
//     w_j + t_j >= 0 _|_ s_j   and   hi_j - lo_j - s_j >= 0 _|_ t_j.
//   With fixed bounds M = [P^T A P, E; -E^T, 0], positive semi-definite when A is, so Lemke ends
//   at a solution. A row with lo_j = hi_j is fixed there.
// With `coupling` (coupled friction), a friction row j of contact row n has the bounds
// +-mu_j x_n: x_j = s_j - mu_j x_n and 2 mu_j x_n - s_j >= 0 _|_ t_j, which is linear in the
// variables too, so the same LCP holds with P's column of x_n also carrying -mu_j on row j
// (M = Sigma A P, Sigma the rows' selection with signs; no longer symmetric: Lemke may then end
// on a ray, reported as an error).
Eigen::VectorXd solve_box(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Box& box,
                          const std::vector<bool>& movable, const Coupling* coupling) {
  const Eigen::Index c = b.size();
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(c);
  struct Variable {
    Eigen::Index row;
    double sign;
  };
  std::vector<Variable> s_vars;
  std::vector<Eigen::Index> slack_of;  // per s variable: its slack's index among t, or -1
  std::vector<double> slack_width;     // per t variable: hi - lo (N), fixed bounds
  std::vector<Eigen::Index> variable_of(static_cast<std::size_t>(c), -1);  // a row's first s
  const auto coupled_row = [&](Eigen::Index j) {
    if (coupling == nullptr) return -1;
    const int n = coupling->normal_row[static_cast<std::size_t>(j)];
    return n >= 0 && movable[static_cast<std::size_t>(n)] ? n : -1;
  };
  for (Eigen::Index j = 0; j < c; ++j) {
    if (!movable[static_cast<std::size_t>(j)]) continue;
    const double lo = box.lo[j];
    const double hi = box.hi[j];
    const bool lo_finite = std::isfinite(lo);
    const bool hi_finite = std::isfinite(hi);
    if (coupling != nullptr && coupling->normal_row[static_cast<std::size_t>(j)] >= 0) {
      if (coupled_row(j) < 0 || !(coupling->mu[j] > 0.0)) continue;  // bounds 0: x_j = 0
      variable_of[static_cast<std::size_t>(j)] = static_cast<Eigen::Index>(s_vars.size());
      s_vars.push_back({j, 1.0});
      slack_of.push_back(static_cast<Eigen::Index>(slack_width.size()));
      slack_width.push_back(0.0);  // 2 mu x_n, set below
    } else if (lo_finite && hi_finite && !(hi > lo)) {
      x0[j] = lo;  // a fixed row (e.g. friction with mu m |g . n| = 0)
    } else if (lo_finite) {
      x0[j] = lo;
      variable_of[static_cast<std::size_t>(j)] = static_cast<Eigen::Index>(s_vars.size());
      s_vars.push_back({j, 1.0});
      if (hi_finite) {
        slack_of.push_back(static_cast<Eigen::Index>(slack_width.size()));
        slack_width.push_back(hi - lo);
      } else {
        slack_of.push_back(-1);
      }
    } else if (hi_finite) {
      x0[j] = hi;
      variable_of[static_cast<std::size_t>(j)] = static_cast<Eigen::Index>(s_vars.size());
      s_vars.push_back({j, -1.0});
      slack_of.push_back(-1);
    } else {
      variable_of[static_cast<std::size_t>(j)] = static_cast<Eigen::Index>(s_vars.size());
      s_vars.push_back({j, 1.0});
      slack_of.push_back(-1);
      s_vars.push_back({j, -1.0});
      slack_of.push_back(-1);
    }
  }
  const auto ns = static_cast<Eigen::Index>(s_vars.size());
  const auto nt = static_cast<Eigen::Index>(slack_width.size());
  const Eigen::Index m = ns + nt;
  if (m == 0) return x0;
  // P (c x ns): x = x0 + P s.
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(c, ns);
  for (Eigen::Index k = 0; k < ns; ++k) {
    const Variable& vk = s_vars[static_cast<std::size_t>(k)];
    P(vk.row, k) = vk.sign;
    const int n = coupled_row(vk.row);
    if (n >= 0) {  // x_j = s_j - mu_j x_n, and x_n = s_n (a contact row: lo = 0, hi = inf)
      const Eigen::Index kn = variable_of[static_cast<std::size_t>(n)];
      if (kn < 0 || box.lo[n] != 0.0 || std::isfinite(box.hi[n])) {
        throw std::invalid_argument("exact solve: friction row " + std::to_string(vk.row) +
                                    " is coupled to row " + std::to_string(n) +
                                    ", which is not a contact row with bounds [0, inf)");
      }
      P(vk.row, kn) -= coupling->mu[vk.row];
    }
  }
  const Eigen::VectorXd w0 = A * x0 - b;
  const Eigen::MatrixXd AP = A * P;
  const SiconosFunctions& f = siconos();  // may throw: before data is allocated
  // Column-major dense M for Siconos (malloc'ed: NM_clear frees it).
  auto* data = static_cast<double*>(std::calloc(static_cast<std::size_t>(m * m), sizeof(double)));
  if (data == nullptr) throw std::bad_alloc();
  Eigen::Map<Eigen::MatrixXd> M(data, m, m);
  Eigen::VectorXd q(m);
  for (Eigen::Index k = 0; k < ns; ++k) {
    const Variable& vk = s_vars[static_cast<std::size_t>(k)];
    M.block(k, 0, 1, ns) = vk.sign * AP.row(vk.row);
    q[k] = vk.sign * w0[vk.row];
    const Eigen::Index t = slack_of[static_cast<std::size_t>(k)];
    if (t >= 0) {
      M(k, ns + t) = 1.0;
      M(ns + t, k) = -1.0;
      q[ns + t] = slack_width[static_cast<std::size_t>(t)];
      const int n = coupled_row(vk.row);
      if (n >= 0) M(ns + t, variable_of[static_cast<std::size_t>(n)]) += 2.0 * coupling->mu[vk.row];
    }
  }
  SiconosLcp lcp;
  lcp.problem.size = static_cast<int>(m);
  lcp.problem.M = f.create_from_data(NM_DENSE, static_cast<int>(m), static_cast<int>(m), data);
  lcp.problem.q = q.data();
  lcp.options = f.options_create(SICONOS_LCP_LEMKE);
  lcp.options->iparam[SICONOS_IPARAM_MAX_ITER] = static_cast<int>(std::max<Eigen::Index>(10000, 50 * m));
  Eigen::VectorXd z = Eigen::VectorXd::Zero(m);
  Eigen::VectorXd wz = Eigen::VectorXd::Zero(m);
  int info = -1;
  f.lexicolemke(&lcp.problem, z.data(), wz.data(), &info, lcp.options);
  if (info != 0) {
    throw std::runtime_error("exact solve: Siconos lcp_lexicolemke returned info " +
                             std::to_string(info) + " on an LCP of size " + std::to_string(m) +
                             " (1: pivot limit, 2: a ray, no solution found)");
  }
  return x0 + P * z.head(ns);
}

// The pseudo-inverse of the symmetric positive semi-definite A restricted to the rows `rows`
// (eigenvalues below kNullTolerance of the largest count as 0), and the null space basis.
struct RestrictedInverse {
  Eigen::MatrixXd pinv;
  Eigen::MatrixXd null_basis;
};

RestrictedInverse restricted_inverse(const Eigen::MatrixXd& A, const std::vector<int>& rows) {
  const auto f = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd A_FF(f, f);
  for (Eigen::Index k = 0; k < f; ++k) {
    for (Eigen::Index l = 0; l < f; ++l) {
      A_FF(k, l) = A(rows[static_cast<std::size_t>(k)], rows[static_cast<std::size_t>(l)]);
    }
  }
  RestrictedInverse out;
  if (f == 0) {
    out.pinv.resize(0, 0);
    out.null_basis.resize(0, 0);
    return out;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A_FF);
  const double largest = eig.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::VectorXd inv_values = Eigen::VectorXd::Zero(f);
  Eigen::Index null_count = 0;
  for (Eigen::Index k = 0; k < f; ++k) {  // ascending order
    const double e = eig.eigenvalues()[k];
    if (e > kNullTolerance * largest) {
      inv_values[k] = 1.0 / e;
    } else {
      ++null_count;
    }
  }
  out.pinv = eig.eigenvectors() * inv_values.asDiagonal() * eig.eigenvectors().transpose();
  out.null_basis = eig.eigenvectors().leftCols(null_count);
  return out;
}

// The largest natural-map residual (N) of x for the box problem, per lcp.h's definition.
double box_residual(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Box& box,
                    const std::vector<bool>& movable, const Eigen::VectorXd& x) {
  const Eigen::VectorXd w = A * x - b;
  double r = 0.0;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    if (!movable[static_cast<std::size_t>(j)]) continue;
    r = std::max(r, std::abs(x[j] - std::clamp(x[j] - w[j] / A(j, j), box.lo[j], box.hi[j])));
  }
  return r;
}

// Polishes x, a solution of the box problem to the pivoting's accuracy, by active-set Newton
// steps on the natural map (the primal-dual active set method; Hintermueller, Ito & Kunisch,
// SIAM J. Optim. 13, 2003): each row whose x_j - w_j / A_jj lies at or beyond a bound is put on
// that bound, and the others (F) take the least-norm correction that solves
// A_FF x_F = (b - A_FB x_B)_F (A_FF may be singular). Keeps the iterate with the smallest
// residual; returns its F.
std::vector<int> polish(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Box& box,
                        const std::vector<bool>& movable, Eigen::VectorXd& x) {
  const Eigen::Index c = b.size();
  for (Eigen::Index j = 0; j < c; ++j) {
    if (!movable[static_cast<std::size_t>(j)]) x[j] = 0.0;
  }
  Eigen::VectorXd best = x;
  double best_residual = box_residual(A, b, box, movable, x);
  std::vector<int> best_free;
  bool have_free = false;
  std::vector<int> last_free;
  RestrictedInverse inverse;
  for (int pass = 0; pass < 20; ++pass) {
    const Eigen::VectorXd w = A * x - b;
    std::vector<int> free_rows;
    Eigen::VectorXd next = x;
    for (Eigen::Index j = 0; j < c; ++j) {
      if (!movable[static_cast<std::size_t>(j)]) continue;
      const double trial = x[j] - w[j] / A(j, j);
      if (trial <= box.lo[j]) {
        next[j] = box.lo[j];
      } else if (trial >= box.hi[j]) {
        next[j] = box.hi[j];
      } else {
        free_rows.push_back(static_cast<int>(j));
      }
    }
    if (free_rows != last_free || pass == 0) inverse = restricted_inverse(A, free_rows);
    last_free = free_rows;
    const auto f = static_cast<Eigen::Index>(free_rows.size());
    if (f > 0) {
      const Eigen::VectorXd r = A * next - b;
      Eigen::VectorXd r_F(f);
      for (Eigen::Index k = 0; k < f; ++k) r_F[k] = r[free_rows[static_cast<std::size_t>(k)]];
      const Eigen::VectorXd step = inverse.pinv * r_F;
      for (Eigen::Index k = 0; k < f; ++k) next[free_rows[static_cast<std::size_t>(k)]] -= step[k];
    }
    x = next;
    const double residual = box_residual(A, b, box, movable, x);
    if (residual < best_residual || !have_free) {
      if (residual <= best_residual) {
        best = x;
        best_residual = residual;
      }
      best_free = free_rows;
      have_free = true;
    }
    if (residual == 0.0) break;
  }
  x = best;
  return best_free;
}

// The start of the polish when Lemke stops without a solution (its pivot limit: a degenerate
// problem, e.g. a stack's redundant corner rows, can make it cycle): kFallbackSweeps sweeps of
// projected Gauss-Seidel (paper Sec. 7.2) on the box problem from 0, with `coupling` the
// friction bounds +-mu x_n of the current contact rows. Its active set, not its lambda, is what
// the polish needs; the residual check after the polish decides whether the result is exact.
Eigen::VectorXd pgs_start(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Box& box,
                          const std::vector<bool>& movable, const Coupling* coupling) {
  const Eigen::Index c = b.size();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(c);
  for (int sweep = 0; sweep < kFallbackSweeps; ++sweep) {
    for (Eigen::Index j = 0; j < c; ++j) {
      if (!movable[static_cast<std::size_t>(j)]) continue;
      double lo = box.lo[j];
      double hi = box.hi[j];
      const int n = coupling != nullptr ? coupling->normal_row[static_cast<std::size_t>(j)] : -1;
      if (n >= 0) {
        hi = coupling->mu[j] * std::max(x[n], 0.0);
        lo = -hi;
      }
      const double w = A.row(j).dot(x) - b[j];
      x[j] = std::clamp(x[j] - w / A(j, j), lo, hi);
    }
  }
  return x;
}

// Solves the strictly convex box problem min 1/2 x^T M x - q^T x, lo <= x <= hi, on the movable
// rows (M = A + eps I: positive definite there; the other rows stay at 0) from x, by the primal-
// dual active set method (Hintermueller, Ito & Kunisch 2003) with exact solves of M_FF: at most
// kDefinitePasses passes, ending when the active set repeats.
void solve_definite_box(const Eigen::MatrixXd& M, const Eigen::VectorXd& q, const Box& box,
                        const std::vector<bool>& movable, Eigen::VectorXd& x) {
  const Eigen::Index c = q.size();
  std::vector<signed char> last;
  for (int pass = 0; pass < kDefinitePasses; ++pass) {
    const Eigen::VectorXd w = M * x - q;
    // Per row: -1 on lo, 1 on hi, 0 free, 2 not movable.
    std::vector<signed char> state(static_cast<std::size_t>(c), 0);
    std::vector<int> free_rows;
    for (Eigen::Index j = 0; j < c; ++j) {
      if (!movable[static_cast<std::size_t>(j)]) {
        x[j] = 0.0;
        state[static_cast<std::size_t>(j)] = 2;
        continue;
      }
      const double trial = x[j] - w[j] / M(j, j);
      if (trial <= box.lo[j]) {
        x[j] = box.lo[j];
        state[static_cast<std::size_t>(j)] = -1;
      } else if (trial >= box.hi[j]) {
        x[j] = box.hi[j];
        state[static_cast<std::size_t>(j)] = 1;
      } else {
        free_rows.push_back(static_cast<int>(j));
      }
    }
    const auto f = static_cast<Eigen::Index>(free_rows.size());
    if (f > 0) {
      Eigen::MatrixXd M_FF(f, f);
      Eigen::VectorXd r_F(f);
      for (Eigen::Index k = 0; k < f; ++k) x[free_rows[static_cast<std::size_t>(k)]] = 0.0;
      const Eigen::VectorXd fixed_part = M * x;
      for (Eigen::Index k = 0; k < f; ++k) {
        const int row = free_rows[static_cast<std::size_t>(k)];
        r_F[k] = q[row] - fixed_part[row];
        for (Eigen::Index l = 0; l < f; ++l) {
          M_FF(k, l) = M(row, free_rows[static_cast<std::size_t>(l)]);
        }
      }
      const Eigen::VectorXd x_F = M_FF.ldlt().solve(r_F);
      for (Eigen::Index k = 0; k < f; ++k) x[free_rows[static_cast<std::size_t>(k)]] = x_F[k];
    }
    if (state == last) break;
    last = std::move(state);
  }
}

// The start of the polish when Lemke's and PGS's both fail (fixed friction; a stack's redundant
// corner rows make A singular, or nearly so, and the polish's active set cycles): the proximal
// point method (Rockafellar, SIAM J. Control Optim. 14, 1976) on the box problem's quadratic
// program, min 1/2 x^T A x - b^T x over the box, whose minimisers are its solutions (A symmetric
// positive semi-definite): x_{k+1} minimises it plus eps/2 |x - x_k|^2, a strictly convex
// problem (solve_definite_box). The iterates approach a solution while each subproblem stays
// well posed; each is polished (polish) and the first whose residual is under `tolerance` of
// its force scale is returned, else the one with the smallest residual. eps: kProximalWeights of
// A's largest diagonal entry, in turn, kProximalIterations each.
Eigen::VectorXd proximal_start(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Box& box,
                               const std::vector<bool>& movable, double tolerance) {
  const Eigen::Index c = b.size();
  double largest = 0.0;
  for (Eigen::Index j = 0; j < c; ++j) largest = std::max(largest, A(j, j));
  Eigen::VectorXd best = Eigen::VectorXd::Zero(c);
  double best_residual = std::numeric_limits<double>::infinity();
  for (const double weight : kProximalWeights) {
    const double eps = weight * largest;
    const Eigen::MatrixXd M = A + eps * Eigen::MatrixXd::Identity(c, c);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(c).cwiseMax(box.lo).cwiseMin(box.hi);
    for (int k = 0; k < kProximalIterations; ++k) {
      solve_definite_box(M, b + eps * x, box, movable, x);
      Eigen::VectorXd candidate = x;
      polish(A, b, box, movable, candidate);
      const double residual = box_residual(A, b, box, movable, candidate);
      if (residual < best_residual) {
        best = candidate;
        best_residual = residual;
      }
      if (residual <= tolerance * force_scale(A, b, candidate)) return best;
    }
  }
  return best;
}

// The bounds of s's rows with coupled friction limits from `lambda`'s contact rows.
Box coupled_box(const StepSystem& s, const Eigen::VectorXd& lambda) {
  Box box{s.c_min, s.c_max};
  for (Eigen::Index j = 0; j < s.rows(); ++j) {
    const int n = s.normal_row[static_cast<std::size_t>(j)];
    if (n < 0) continue;
    const double limit = s.mu[j] * std::max(lambda[n], 0.0);
    box.lo[j] = -limit;
    box.hi[j] = limit;
  }
  return box;
}

void check_sizes(const StepSystem& s) {
  const Eigen::Index c = s.rows();
  if (s.A.rows() != c || s.A.cols() != c || s.c_min.size() != c || s.c_max.size() != c ||
      s.mu.size() != c || static_cast<Eigen::Index>(s.normal_row.size()) != c) {
    throw std::invalid_argument("exact solve: A is " + std::to_string(s.A.rows()) + " x " +
                                std::to_string(s.A.cols()) + ", b has " + std::to_string(c) +
                                " entries, c_min, c_max, mu, normal_row " +
                                std::to_string(s.c_min.size()) + ", " +
                                std::to_string(s.c_max.size()) + ", " + std::to_string(s.mu.size()) +
                                ", " + std::to_string(s.normal_row.size()) + "; all must be c");
  }
}

// One attempt at s's exact solution: the polish (fixed friction), or the polish rounds with the
// bounds of the last lambda (coupled), from `lambda`; sets lambda, free_rows, polish_rounds, w
// and residual_max.
void polish_solution(const StepSystem& s, const Eigen::MatrixXd& A, const std::vector<bool>& movable,
                     ExactSolution& out) {
  if (s.friction == FrictionModel::fixed) {
    out.free_rows = polish(A, s.b, Box{s.c_min, s.c_max}, movable, out.lambda);
  } else {
    for (int k = 1; k <= kMaxFixedPoint; ++k) {
      const Box box = coupled_box(s, out.lambda);
      Eigen::VectorXd next = out.lambda;
      out.free_rows = polish(A, s.b, box, movable, next);
      const double change = (next - out.lambda).cwiseAbs().maxCoeff();
      out.lambda = next;
      out.polish_rounds = k;
      if (change <= 1e-13 * force_scale(A, s.b, out.lambda)) break;
    }
  }
  out.w = A * out.lambda - s.b;
  const Eigen::VectorXd r = natural_map_residual(s, out.lambda);
  out.residual_max = r.size() > 0 ? r.maxCoeff() : 0.0;
}

}  // namespace

ExactSolution solve_exact(const StepSystem& s) { return solve_exact(s, 1e-9); }

ExactSolution solve_exact(const StepSystem& s, double tolerance) {
  if (!(tolerance > 0.0 && tolerance <= 1e-3)) {
    throw std::invalid_argument("exact solve: residual tolerance " + std::to_string(tolerance) +
                                " of the force scale; allowed: (0, 1e-3]");
  }
  check_sizes(s);
  siconos();  // opened here: a missing library is an error, not a Lemke failure to fall back from
  const Eigen::MatrixXd A(s.A);
  const std::vector<bool> movable = movable_rows(A);
  const bool coupled = s.friction != FrictionModel::fixed;
  const Coupling coupling{s.normal_row, s.mu};
  const Box box{s.c_min, s.c_max};
  // The bounds are linear in lambda with coupled friction too: one LCP (solve_box with the
  // coupling), then the polish with the bounds of the current lambda, repeated while they move.
  ExactSolution out;
  std::string lemke_failure;
  try {
    out.lambda = solve_box(A, s.b, box, movable, coupled ? &coupling : nullptr);
    out.method = coupled ? "siconos lexicolemke (coupled bounds) + polish" : "siconos lexicolemke + polish";
    polish_solution(s, A, movable, out);
  } catch (const std::runtime_error& e) {  // Lemke's pivot limit or a ray
    lemke_failure = e.what();
  }
  const auto passes = [&](const ExactSolution& x) {
    return x.lambda.size() == s.rows() && x.residual_max <= tolerance * force_scale(A, s.b, x.lambda);
  };
  if (!passes(out)) {  // Lemke stopped, or its polished result is not exact: start from PGS
    ExactSolution retry;
    retry.lambda = pgs_start(A, s.b, box, movable, coupled ? &coupling : nullptr);
    retry.method = coupled ? "pgs start (coupled bounds) + polish" : "pgs start + polish";
    polish_solution(s, A, movable, retry);
    ExactSolution proximal;
    if (!passes(retry) && !coupled) {  // both active sets cycle: the proximal point start
      proximal.lambda = proximal_start(A, s.b, box, movable, tolerance);
      proximal.method = "proximal point start + polish";
      polish_solution(s, A, movable, proximal);
      if (passes(proximal)) retry = std::move(proximal);
    }
    if (!passes(retry)) {
      std::ostringstream why;
      why << "exact solve: ";
      if (!lemke_failure.empty()) {
        why << lemke_failure << "; ";
      } else {
        why << "Lemke's polished solution has a natural-map residual of " << out.residual_max
            << " N; ";
      }
      why << "from " << kFallbackSweeps << " PGS sweeps the polished solution has "
          << retry.residual_max << " N";
      if (!coupled) why << ", from the proximal point start " << proximal.residual_max << " N";
      why << ", all above " << tolerance << " of the force scale "
          << force_scale(A, s.b, retry.lambda) << " N";
      throw std::runtime_error(why.str());
    }
    out = std::move(retry);
  }
  out.force_scale_N = force_scale(A, s.b, out.lambda);
  if (!coupled) {
    // The solution set's free rows (w*_j = 0 to the tolerance, inside a bound or on it) and
    // free directions, the null space of A_FF.
    out.free_rows.clear();
    for (Eigen::Index j = 0; j < s.rows(); ++j) {
      if (movable[static_cast<std::size_t>(j)] &&
          std::abs(out.w[j]) <= kActiveTolerance * out.force_scale_N * A(j, j)) {
        out.free_rows.push_back(static_cast<int>(j));
      }
    }
    out.null_basis = restricted_inverse(A, out.free_rows).null_basis;
    out.smallest_norm_N = out.distance(s, Eigen::VectorXd::Zero(s.rows())).upper_N;
  } else {
    out.null_basis.resize(static_cast<Eigen::Index>(out.free_rows.size()), 0);
    out.smallest_norm_N = out.lambda.norm();
  }
  return out;
}

}  // namespace cps::analysis
