#pragma once
// Split impulse: `--push split-impulse`. Source: Bullet Physics, btSequentialImpulseConstraintSolver
// with btContactSolverInfo::m_splitImpulse (resolveSplitPenetrationImpulse, and the position
// update of writeBackBodies with m_pushVelocity and m_turnVelocity); E. Coumans, "Bullet 2.x
// physics SDK manual", split impulse.
//
// Derivation, in the paper's terms. Baumgarte (Sec. 5.3) puts the push beta d / dt into the
// target velocity of the one solve, so the velocity that corrects the overlap stays in the
// momenta and throws the bodies apart (the intersecting stack, Fig. 7 b). The split impulse
// keeps two velocities per body:
//   1. the velocity solve: A lambda = b (Eq. 6.2.9) with each row's target without the push
//      (restitution and speculative bias only), from the bodies' momenta and f_ext; its
//      f_c0 = f_ext + J^T lambda is the force of Eqs. 3.2.1-3.2.2 for the stored momenta;
//   2. the pseudo-velocity solve: the contact rows that carry a push, and the rods, on their own,
//      with the bodies at rest and no external force: A_p lambda_p = v_p / dt, v_p = push,
//      lambda_p >= 0 for contacts, started from 0 every step (Bullet resets m_appliedPushImpulse);
//      its J_p^T lambda_p moves the positions only.
// Positions then move with the momenta of f_c0 plus the pseudo-velocity dt M^-1 J_p^T lambda_p
// (Eq. 3.2.3-3.2.4 with f = f_c0 + J_p^T lambda_p), and the pseudo-velocity is discarded: the
// stored momenta get f_c0 alone. Where the single frame push factor (Sec. 8.1) solves the push
// together with everything else (gravity, friction, the momenta) in its first solve, here the
// push is solved alone, from rest, on the normal rows only: the clamp lambda_p >= 0 acts on the
// push alone, and friction never sees it.
//
// What Bullet has and this adds or leaves:
// - Bullet applies it only past a penetration threshold (m_splitImpulsePenetrationThreshold,
//   -0.04 m): shallower contacts keep the push in the velocity. Here WorldDef::
//   split_impulse_threshold (m, default 0: every overlap goes to the pseudo-velocities); the rows
//   are built with their push moved into bias for depth <= threshold (RowParams::
//   velocity_push_depth).
// - Bullet uses its own ERP for the pseudo-velocities (m_erp2 = 0.8 by default) against 0.2 for
//   Baumgarte; here both use the paper's beta, so that the methods differ by where the push goes,
//   not by how much of it there is (`--beta 0.8` gives Bullet's pseudo-velocity push).
// - Rods: Bullet's joints keep their correction in the velocity (split impulse is for contacts).
//   Here the rods' push goes to the pseudo-velocity solve too, with the contacts, so that no
//   push is left in any momentum; the rods then also hold their length against the push out of
//   an overlap.
// - Both solvers (PGS, Jacobi), both friction models (only the velocity solve has friction rows),
//   restitution (in the velocity solve's bias), warm starting (of the velocity solve; the
//   pseudo-velocity solve starts from 0, as Bullet's), and both assemblies (explicit and
//   matrix-free, for both solves).

#include "constraint_solver.h"

#include "cps/body.h"
#include "cps/constraint.h"
#include "cps/parameters.h"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace cps {

/// The pseudo-velocity solve of the split impulse, with its own rows and solver (buffers kept
/// from step to step: no allocation once they have their working size).
class SplitImpulse {
 public:
  /// Solves the pseudo-velocities of the rows that carry a push (contact rows with push > 0, and
  /// every rod row) with `settings` (its dt the step's, its softness ignored) from rest, and sets
  /// f_position = f_momentum + J_p^T lambda_p (6n: force and torque per body, N and N m): the
  /// force that moves the positions this step. rows: the step's rows (c); bodies (n) as before
  /// the integration; f_momentum: f_c0 of the velocity solve (6n). No errors.
  void solve(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
             Assembly assembly, const SolveSettings& settings, const Eigen::VectorXd& f_momentum,
             Eigen::VectorXd& f_position);

  /// The pseudo-velocity rows of the last solve (c_p) and their lambda (c_p, N).
  const std::vector<ConstraintRow>& rows() const { return rows_; }
  const std::vector<double>& lambda() const { return lambda_; }

 private:
  std::vector<ConstraintRow> rows_;
  std::vector<double> lambda_;
  Eigen::VectorXd zero_force_;  // 6n zeros: no external force on the pseudo-velocities
  std::unique_ptr<ConstraintSolver> solver_;
  Assembly assembly_ = Assembly::matrix_free;
};

}  // namespace cps
