#pragma once
// The solve of A lambda = b (Secs. 6-7) behind one interface, with two implementations: the
// paper's explicit sparse J, M^-1 and A = J M^-1 J^T (Sec. 6, system.h and solver.h), and the
// matrix-free sweep that keeps w = M^-1 J^T lambda per body instead (matrix_free.h). Both read the
// same rows, the same f_ext and the same settings, bound lambda by the same force limits and
// measure the same residual (lcp.h), and give the same lambda to round-off (tested on every
// paper scene). World chooses one by WorldDef::assembly.

#include "cps/body.h"
#include "cps/constraint.h"
#include "cps/parameters.h"
#include "row_colours.h"
#include "system.h"
#include "workers.h"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace cps {

/// What one solve needs besides the rows and bodies: dt (s, > 0; a substep's length for the
/// methods that substep), the number of sweeps (>= 1), PGS, Jacobi or coloured PGS, the friction
/// model of the force limits, and the threads a solve may share (nullptr: the calling thread
/// only; the matrix-free path shares a coloured PGS sweep and the right-hand side among them; the
/// result is the same for every count).
struct SolveSettings {
  double dt = 1.0 / 60.0;
  int iterations = 25;
  SolverKind kind = SolverKind::pgs;
  FrictionModel friction = FrictionModel::fixed;
  Workers* workers = nullptr;
  RowPrecision precision = RowPrecision::double_precision;  ///< the matrix-free rows' (prepare())
};

/// A way to solve the step's bounded system A lambda = b.
class ConstraintSolver {
 public:
  virtual ~ConstraintSolver() = default;

  /// Builds what every solve of this step shares, from the rows (c, bodies by index or
  /// kWorldBody) and the bodies (n) as they are before the integration: J, M^-1, A and v1
  /// (explicit), or the packed rows and I^-1 per body (matrix-free); for the sweeps of `kind`
  /// (SolverKind::coloured_pgs: the rows' colours and sweep order too, row_colours.h). The
  /// matrix-free path packs the rows on `workers`' threads (nullptr: the calling thread), with
  /// the same result for every count. `precision`: how the matrix-free path stores its packed
  /// rows (RowPrecision); the explicit path assembles in double and ignores it. `spans`: the
  /// rows' stretches on the same two bodies (colour_spans), from which coloured PGS cuts its
  /// runs without reading every row; nullptr: cut from the rows. Throws std::invalid_argument
  /// when the spans do not cover the rows.
  virtual void prepare(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
                       SolverKind kind, RowPrecision precision, Workers* workers,
                       const std::vector<RowSpan>* spans) = 0;

  /// Solves A lambda = b with settings.iterations sweeps, b of Eq. 6.2.9 from the bodies'
  /// momenta as they are now (read with the world inverse inertia of prepare(), so that the
  /// substeps of one step share one A), f_ext (6n: force and torque per body, N and N m) and each row's target velocity
  /// (push and bias, or bias only: `terms`, Sec. 8.1), from `initial` (c values, N: the warm
  /// start of Sec. 6.2.3) when given, else from lambda = 0. lambda: resized to c (N). The rows
  /// and bodies must be those given to prepare(), and settings.kind coloured PGS only when
  /// prepare()'s was (std::logic_error otherwise).
  virtual void solve(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
                     const Eigen::VectorXd& f_ext, TargetTerms terms,
                     const SolveSettings& settings, std::vector<double>& lambda,
                     const std::vector<double>* initial = nullptr) = 0;

  /// The natural-map residual (lcp.h) of the lambda the last solve() returned: the largest row
  /// residual and the sum of their squares (N, N^2).
  virtual void residual(const std::vector<ConstraintRow>& rows, FrictionModel friction,
                        const std::vector<double>& lambda, double& max,
                        double& sum_squares) const = 0;

  /// The system the last solve() solved, written out explicitly (for a StepSystem): A (c x c,
  /// 1/kg), b (c, m/s^2) and the rows' limits. Built on
  /// request only (the matrix-free path multiplies its packed rows out, J times M^-1 J^T), never
  /// in a step that nobody observes. No errors.
  virtual void system(SparseRowMatrix& A, Eigen::VectorXd& b, RowLimits& limits) const = 0;

  /// The order the last solve() swept the rows in, into order: c row indices for
  /// SolverKind::coloured_pgs, empty for the methods that sweep in row order. No errors.
  virtual void sweep_order(std::vector<int>& order) const = 0;

  /// f = f_ext + J^T lambda (6n, N and N m) for the lambda the last solve() returned, formed per
  /// body from what that solve kept, without another pass over the rows, where the solver can:
  /// the matrix-free coloured PGS from w = M^-1 J^T lambda (f_c = M w, Eq. 6.2.1; its bodies'
  /// entries equal add_constraint_forces()'s to round-off, and a static body's hold f_ext alone,
  /// as nothing moves it), shared among `workers`' threads with the same result for every count.
  /// Returns false and leaves f untouched where it cannot (the explicit path, PGS and Jacobi,
  /// which keep the state hashes of add_constraint_forces()). bodies: those of the solve; f_ext:
  /// 6n. No errors.
  virtual bool constraint_forces(const std::vector<Body>& /*bodies*/, const Eigen::VectorXd& /*f_ext*/,
                                 Eigen::VectorXd& /*f*/, Workers* /*workers*/) const {
    return false;
  }
};

/// The implementation for `assembly`: Assembly::explicit_matrices or Assembly::matrix_free.
std::unique_ptr<ConstraintSolver> make_constraint_solver(Assembly assembly);

/// f = f_ext + J^T lambda (6n: force and torque per body, N and N m; Eq. 6.2.1: the constraint
/// force f_c = J^T lambda added to the external force before the integration of Sec. 3.2).
/// lambda: c (N), one per row. f is resized to f_ext's size (no allocation once it has it).
void add_constraint_forces(const std::vector<ConstraintRow>& rows,
                           const std::vector<double>& lambda, const Eigen::VectorXd& f_ext,
                           Eigen::VectorXd& f);

}  // namespace cps
