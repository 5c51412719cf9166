#pragma once
// Per-step criteria of a solve against the exact solution, after ContactBench (Le Lidec,
// Jallet, Montaut, Laptev, Stasse, Carpentier, "Contact models in robotics: a comparative
// analysis", IEEE T-RO 2024, Sec. VI: the force error against a reference, the velocity error,
// Signorini and friction-cone violations, complementarity) and the natural map of
// Facchinei & Pang 2003, Sec. 1.5.
//
// Units follow engine/src/system.h: A lambda = b with lambda in N, b in m/s^2 and A in 1/kg;
// w = A lambda - b = (J v2 - v) / dt (m/s^2), where v2 is the system velocity after the step's
// momenta update (Sec. 3.2) and v the rows' target velocities (m/s), so dt w is a row's relative
// velocity after the solve beyond its target (m/s).

#include "exact_lcp.h"

#include "cps/step_system.h"

#include <Eigen/Core>

#include <string>
#include <string_view>

namespace cps::analysis {

/// How far one lambda is from solving a StepSystem, and from its exact solution.
struct Criteria {
  /// N: |lambda - lambda*|, the Euclidean distance to the nearest exact solution found
  /// (ExactSolution::distance's upper_N: the distance to the solution set when
  /// lambda_error_exact; for coupled friction, to the one solution found).
  double lambda_error_N = 0.0;
  /// N: a lower bound of the distance to the solution set (ExactSolution::distance's lower_N;
  /// equal to lambda_error_N when lambda_error_exact; 0 for coupled friction).
  double lambda_error_lower_N = 0.0;
  /// lambda_error_N / |lambda*|, with |lambda*| the smallest norm of an exact solution
  /// (ExactSolution::smallest_norm_N; dimensionless). Where lambda* = 0 (no row pushes) the
  /// error is over the problem's force scale instead (ExactSolution::force_scale_N).
  double lambda_error_relative = 0.0;
  /// Whether lambda_error_N is the distance to the solution set (the interval
  /// [lambda_error_lower_N, lambda_error_N] is certified narrow), or only an upper bound of it.
  bool lambda_error_exact = false;
  /// N s: the impulse error dt |lambda - lambda*|, the change of momentum it makes over the step.
  double impulse_error_Ns = 0.0;
  /// m/s: |J (v2 - v2*)| = dt |A (lambda - lambda*)|, the rows' post-solve velocity error; the
  /// same for every exact solution lambda*.
  double velocity_error_mps = 0.0;
  /// N: the largest negative contact force, max over contact rows of max(-lambda_j, 0).
  double signorini_force_N = 0.0;
  /// m/s: the largest approach beyond a contact row's target after the solve,
  /// max over contact rows of max(-dt w_j, 0).
  double signorini_velocity_mps = 0.0;
  /// W: the largest complementarity product of a contact row, max |lambda_j dt w_j| (force times
  /// separating velocity beyond the target: the power of a contact that pushes while it opens).
  double complementarity_W = 0.0;
  /// N: the largest friction force beyond its limit, max over friction rows of the distance of
  /// lambda_j outside [c_min_j, c_max_j] (fixed) or [-mu lambda_n, mu lambda_n] (coupled, with
  /// lambda_n = max(lambda's contact row, 0)): the friction box of Sec. 5.4 (the engine's
  /// friction set is a box, not a cone).
  double friction_violation_N = 0.0;
  /// N: the largest natural-map residual (cps::natural_map_residual: per row
  /// |lambda_j - clamp(lambda_j - w_j / A_jj, lo_j, hi_j)|, a force so that rows of every kind
  /// compare; 0 exactly at a solution).
  double natural_map_N = 0.0;
  /// Whether lambda or a criterion is not finite (a diverged sweep): every number above is +inf.
  bool diverged = false;
};

/// The criteria of `lambda` (c, N) on s against `exact` (solve_exact(s)). A lambda with a
/// non-finite entry (a diverged sweep), or whose criteria overflow, is `diverged`: every
/// criterion is then +inf (lambda_error_exact false), never NaN. Throws std::invalid_argument
/// when lambda does not have c entries.
Criteria evaluate(const StepSystem& s, const ExactSolution& exact, const Eigen::VectorXd& lambda);

/// The CSV columns of a row of criteria (comma-separated), in the order csv_fields writes them.
inline constexpr std::string_view kCriteriaColumns =
    "lambda_error_N,lambda_error_lower_N,lambda_error_relative,lambda_error_exact,"
    "impulse_error_Ns,velocity_error_mps,signorini_force_N,signorini_velocity_mps,"
    "complementarity_W,friction_violation_N,natural_map_N,diverged";

/// The fields of kCriteriaColumns for c, comma-separated, numbers with 17 significant digits
/// (read back exactly; a diverged row's as "inf"), the flags as 0 or 1. No errors.
std::string csv_fields(const Criteria& c);

}  // namespace cps::analysis
