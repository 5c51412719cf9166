#pragma once
// An exact solution of a captured step's bounded system (cps/step_system.h): A lambda = b with
// c_min <= lambda <= c_max per row, a box-constrained linear complementarity problem (paper
// Sec. 6-7, Eq. 6.2.9; the "mixed" or "boxed" LCP of Cottle, Pang & Stone 1992, Sec. 1.2).
//
// Fixed friction limits (FrictionModel::fixed): the box problem is turned into a standard LCP
// (every finite bound gives a shifted variable, a two-sided row a second, slack variable; a free
// row is split into its positive and negative parts), solved by Siconos numerics' lexicographic
// Lemke method (lcp_lexicolemke: a pivoting method, finite for this positive semi-definite
// matrix), then polished: the rows with a clearly non-zero post-solve w = A lambda - b are held
// at their bound, and the others take the least-norm Newton correction of A_FF lambda_F = b_F -
// A_FB lambda_B, which leaves the natural-map residual at round-off.
//
// Coupled friction limits (FrictionModel::coupled, +-mu lambda_n): the bounds are linear in
// lambda, so the problem is still one LCP (a friction row's lambda measured from -mu lambda_n,
// with a slack for the width 2 mu lambda_n), no longer symmetric; Lemke on it, then the polish
// with the bounds of the current lambda, repeated while they move. Lemke is not guaranteed to
// end at a solution of a non-symmetric LCP: solve_exact throws when the result does not pass the
// residual check (the funnel at rest, docs/exact_reference.md).
//
// Where Lemke stops (its pivot limit: degenerate problems such as a stack's redundant corner
// rows can make it cycle; or a ray), the polish starts instead from 2000 sweeps of projected
// Gauss-Seidel. Where that fails too with fixed friction (a stack's corner rows make A singular
// or nearly so, and the polish's active set cycles), from the iterates of the proximal point
// method on the problem's quadratic program (Rockafellar 1976: each iterate the solution of the
// strictly convex problem with A + eps I). Whichever start, the result counts as exact only if
// its natural-map residual is under 1e-9 of the force scale (or the tolerance given), else
// solve_exact throws.
//
// A = J M^-1 J^T is only positive semi-definite: a box resting on four contact points, or a pile
// of balls with more contact rows than degrees of freedom, has many lambda that solve the
// problem, while w = A lambda - b and the contact forces on each body, J^T lambda, are the same
// for all (a convex quadratic program's minimisers share A lambda). For fixed friction the set of
// exact solutions is therefore S = {x in the box : x_j = lambda*_j where w*_j != 0, A x = A lambda*},
// a polytope; ExactSolution::distance projects any lambda onto it (solution_set.cpp), so that an
// iterate's error is its distance to the set, not to an arbitrary member.

#include "cps/step_system.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace cps::analysis {

/// The exact solution of one StepSystem, and the set of all of them (fixed friction).
struct ExactSolution {
  /// c, N: one exact solution (Lemke's, polished).
  Eigen::VectorXd lambda;
  /// c, m/s^2: w = A lambda - b, the same for every exact solution (fixed friction).
  Eigen::VectorXd w;
  /// How it was found, for reports: "siconos lexicolemke + polish", "siconos lexicolemke
  /// (coupled bounds) + polish", or, where Lemke stopped at its pivot limit or a ray or its
  /// polished result missed the residual check, "pgs start + polish" ("pgs start (coupled
  /// bounds) + polish"): the polish from 2000 PGS sweeps, exact all the same since it passed
  /// the residual check; where that missed it too (fixed friction), "proximal point start +
  /// polish".
  std::string method;
  /// Coupled friction: rounds of the polish, each with the bounds of the last lambda (0 for
  /// fixed friction).
  int polish_rounds = 0;
  /// The largest natural-map residual of lambda (N; cps::natural_map_residual).
  double residual_max = 0.0;
  /// Rows free to move within the solution set (F: touching a movable body, with w*_j = 0 to
  /// the tolerance, whether lambda*_j lies inside its bounds or on one), by index; the others are
  /// the same in every exact solution (fixed friction).
  std::vector<int> free_rows;
  /// |F| x d, orthonormal columns: a basis of the null space of A_FF; the exact solutions are
  /// lambda + [N z on the rows F] within the bounds (d = 0: lambda is the only one).
  Eigen::MatrixXd null_basis;
  /// N: |lambda*|, the smallest norm of an exact solution (fixed friction: distance(0)'s
  /// nearest, the least-norm member of the set when certified, else the least found; coupled:
  /// |lambda|). The scale of the relative force error.
  double smallest_norm_N = 0.0;
  /// N: the problem's force scale, max of |lambda_j| and |b_j| / A_jj over the rows touching a
  /// movable body (1 when all are 0); the tolerances above are parts of it.
  double force_scale_N = 1.0;

  /// How far y is from the set of exact solutions. Throws std::invalid_argument when y has the
  /// wrong size or a non-finite entry.
  struct Distance;
  Distance distance(const StepSystem& s, const Eigen::VectorXd& y) const;
};

/// The distance of a lambda to the exact solutions: an interval [lower_N, upper_N] that holds
/// it, and the member `nearest` at upper_N. Fixed friction: the Euclidean projection onto the
/// solution set S (exact_lcp.h's file comment) by Dykstra's alternating projections between the
/// affine set and the box (Boyle & Dykstra 1986), finished by active-set steps; lower_N is the
/// Lagrangian dual bound of the projection's multipliers (weak duality), so the interval is
/// certified whatever the iteration did. Coupled friction: the set is not described, the
/// distance is to the one solution found and lower_N is 0.
struct ExactSolution::Distance {
  /// c, N: an exact solution (within the bounds and on the affine set to 1e-9 of the force
  /// scale), the nearest to y found.
  Eigen::VectorXd nearest;
  /// N: |y - nearest|, an upper bound of y's distance to S.
  double upper_N = 0.0;
  /// N: a lower bound of y's distance to S (0 for coupled friction).
  double lower_N = 0.0;
  /// Whether upper_N - lower_N is within 1e-6 of force_scale_N or of upper_N, whichever is
  /// larger: upper_N is then the distance.
  bool exact = false;
};

/// Solves s exactly (see the file comment). Throws std::invalid_argument for a system whose
/// sizes disagree (or a coupled friction row whose contact row is not bounded [0, inf)),
/// std::runtime_error when the polished solution's natural-map residual is above 1e-9 of the
/// problem's force scale (max |lambda_j|, |b_j| / A_jj; N) from every start (Lemke's solution,
/// PGS sweeps, the proximal point iterates), and std::runtime_error naming the library when
/// Siconos numerics cannot be opened. Siconos is opened (dlopen) by the first solve
/// that needs Lemke, not at start-up: CPS_SICONOS_LIBRARY if set and not empty, else the SONAME
/// found when cps was configured (CMake's CPS_SICONOS_SONAME, e.g. libsiconos_numerics.so.7).
ExactSolution solve_exact(const StepSystem& s);

/// As solve_exact(s), with the residual check at `tolerance` of the force scale in place of 1e-9
/// (dimensionless, in (0, 1e-3]; typical 1e-9 for a reference, 1e-6 where a step only has to be
/// solved far past what the engine's sweeps reach, as the mass ratio scorecard's). Throws as
/// solve_exact, and std::invalid_argument for a tolerance outside (0, 1e-3].
ExactSolution solve_exact(const StepSystem& s, double tolerance);

}  // namespace cps::analysis
