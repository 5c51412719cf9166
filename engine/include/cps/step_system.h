#pragma once
// The system a solve of a step hands to its sweeps (paper Sec. 6, Eq. 6.2.9), captured as data:
// A lambda = b with the bounds c_min <= lambda <= c_max of each row (a box-constrained linear
// complementarity problem), the rows' kinds, and the lambda the engine's solve returned. A world
// hands one to its solve observer (World::set_solve_observer) after each solve; the engine's own
// sweeps (Sec. 7) run on it again through solve_sweeps, so that a captured step can be solved to
// any number of sweeps, or exactly (demos/analysis/exact_lcp.h), and the results compared.

#include "cps/constraint.h"
#include "cps/parameters.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cstdint>
#include <functional>
#include <vector>

namespace cps {

/// Which parts of each row's target velocity enter v: the full push + bias (the ordinary solve,
/// and the first solve of Sec. 8.1), bias only (the second solve of Sec. 8.1, v without the
/// constraint-correcting push factor), or the push alone with the bodies taken at rest and no
/// external force, b = push / dt (the pseudo-velocity solve of the split impulse,
/// engine/src/push/split_impulse.cpp).
enum class TargetTerms : int { push_and_bias, bias_only, push_from_rest };

/// One solve of a step, as the solver saw it. c rows; units as in engine/src/system.h (unit-axis
/// rows, Sec. 9.2: lambda in N, v in m/s).
struct StepSystem {
  std::int64_t step = 0;  ///< the step it belongs to: World::counters().steps before the step
  int solve = 0;          ///< which solve of the step (0 first; the push method decides how many)
  TargetTerms terms = TargetTerms::push_and_bias;  ///< the targets b was built from (Sec. 8.1)
  double dt = 0.0;        ///< s: the length of time the solve spans (b's v / dt)
  SolverKind solver = SolverKind::pgs;  ///< the engine's method for this solve (Sec. 7)
  int iterations = 0;     ///< the engine's sweeps for this solve (count)
  FrictionModel friction = FrictionModel::fixed;  ///< how friction rows are bounded (Sec. 5.4)
  /// c x c, 1/kg (1/(kg m^2) terms times m^2): A = J M^-1 J^T (Eq. 6.2.9), symmetric positive
  /// semi-definite, as the solve used it (the explicit path's matrix, or the matrix-free path's
  /// packed rows multiplied out).
  Eigen::SparseMatrix<double, Eigen::RowMajor> A;
  Eigen::VectorXd b;      ///< c, m/s^2: b = v / dt - J (v1 / dt + M^-1 f_ext) (Eq. 6.2.9)
  Eigen::VectorXd c_min;  ///< c, N: lower force limits (-inf for rods; Sec. 5.2-5.4)
  Eigen::VectorXd c_max;  ///< c, N: upper force limits (+inf for contacts and rods)
  /// c: a friction row's contact row (the coupled limit +-mu lambda_n reads it), -1 otherwise.
  std::vector<int> normal_row;
  Eigen::VectorXd mu;     ///< c, dimensionless: a friction row's coefficient, 0 otherwise
  std::vector<RowKind> kinds;  ///< c: contact, friction or distance (Sec. 5)
  Eigen::VectorXd initial;  ///< c, N: the solve's initial guess (0, or the warm start, Sec. 6.2.3)
  Eigen::VectorXd lambda;   ///< c, N: what the engine's solve returned
  /// c row indices, the order a SolverKind::coloured_pgs solve swept the rows in (by graph
  /// colour, engine/src/row_colours.h); empty for the other methods, which sweep in row order.
  std::vector<int> order;

  /// The number of rows, c.
  Eigen::Index rows() const { return b.size(); }
};

/// Called after each solve of a step with the system it solved; see World::set_solve_observer.
using SolveObserver = std::function<void(const StepSystem&)>;

/// Asked after each solve, before its system is written out (A alone is c x c doubles): `step`
/// (World::counters().steps before the step), `solve` (StepSystem::solve) and `rows` (c); true
/// hands the system to the observer, false skips it at the cost of the call. It may throw, to
/// refuse a system too large for what the caller would do with it: the exception leaves
/// World::step, and the world may then only be destroyed or assigned.
using SolveFilter = std::function<bool(std::int64_t step, int solve, Eigen::Index rows)>;

/// Called after each solve of a step, after the observer, with the system it solved (its
/// lambda the engine's) and `lambda` holding a copy of the engine's lambda (c, N): what the
/// function leaves in `lambda` is what the step goes on with, in place of the engine's. For
/// replacing the engine's sweeps by another solve of the same system (an exact one,
/// demos/analysis/exact_lcp.h); see World::set_solve_override.
using SolveOverride = std::function<void(const StepSystem&, Eigen::VectorXd& lambda)>;

/// The engine's own sweeps (engine/src/solver.cpp, solve_lcp: the same code the explicit path of
/// every step runs) on a captured system: `sweeps` sweeps of projected Gauss-Seidel (Sec. 7.2),
/// projected Jacobi (Sec. 7.1) or coloured PGS (in s.order), lambda_j = clamp((b_j - sum_{i != j} A_ji lambda_i) / A_jj, lo_j,
/// hi_j) (Eq. 7.1.1), with the bounds of s.friction (fixed c_min, c_max, or +-mu lambda_n). From
/// `start` (c values, N) when given, else from lambda = 0 (Sec. 7.2). Returns lambda (c, N).
/// Throws std::invalid_argument on mismatched sizes, a start of the wrong size, sweeps < 0, or
/// coloured PGS on a system captured without its order (s.order empty).
Eigen::VectorXd solve_sweeps(const StepSystem& s, SolverKind method, int sweeps,
                             const Eigen::VectorXd* start = nullptr);

/// The natural-map residual of lambda (c, N) on s, per row (c values, N):
///   r_j = |lambda_j - clamp(lambda_j - (A lambda - b)_j / A_jj, lo_j, hi_j)|
/// the engine's own measure (engine/src/lcp.h; Facchinei & Pang 2003, Sec. 1.5), scaled by the
/// diagonal so that it is a force, with s.friction's bounds (coupled: from lambda's own contact
/// rows). 0 exactly when lambda solves the problem. Rows with A_jj <= 0 count 0.
/// Throws std::invalid_argument on mismatched sizes.
Eigen::VectorXd natural_map_residual(const StepSystem& s, const Eigen::VectorXd& lambda);

}  // namespace cps
