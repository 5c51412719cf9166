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

#include "push_method.h"

#include "../buffers.h"
#include "../constraint_solver.h"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace cps {
namespace {

class SplitImpulse final : public PushMethod {
 public:
  // Shallow contacts (depth <= split_impulse_threshold, m) keep their push in the velocity solve.
  void adjust_rows(const WorldDef& def, RowParams& params) const override {
    params.velocity_push_depth = def.split_impulse_threshold;
  }

  // 1. the velocity solve without the push sets f_c0 (the momenta); 2. the push on
  // pseudo-velocities from rest adds J_p^T lambda_p to the force that moves the positions.
  void step(StepContext& ctx) override {
    ctx.lambda_second.clear();
    ctx.solve(TargetTerms::bias_only, ctx.lambda, ctx.f_c0, ctx.warm_guess());
    ctx.store_warm_start();
    if (!ctx.rows.empty()) {
      solve_pseudo_velocities(ctx.rows, *ctx.bodies, ctx.def->assembly, ctx.settings(ctx.def->dt),
                              ctx.f_c0, ctx.f_cv);
      ++ctx.counters.solves;
    } else {
      ctx.f_cv = ctx.f_c0;
    }
    ctx.integrate(ctx.f_cv, ctx.f_c0, ctx.def->dt);
  }

 private:
  // Solves the pseudo-velocities of the rows that carry a push (contact rows with push > 0, and
  // every rod row) with `settings` from rest, and sets
  // f_position = f_momentum + J_p^T lambda_p (6n). rows: the step's (c); bodies (n) as before the
  // integration; f_momentum: f_c0 of the velocity solve (6n).
  void solve_pseudo_velocities(const std::vector<ConstraintRow>& rows,
                               const std::vector<Body>& bodies, Assembly assembly,
                               const SolveSettings& settings, const Eigen::VectorXd& f_momentum,
                               Eigen::VectorXd& f_position) {
    rows_.clear();
    detail::reserve_with_headroom(rows_, rows.size());
    for (const ConstraintRow& r : rows) {
      if ((r.kind == RowKind::contact && r.push > 0.0) || r.kind == RowKind::distance) {
        rows_.push_back(r);
        rows_.back().normal_row = -1;  // no friction rows here
      }
    }
    if (rows_.empty()) {
      lambda_.clear();
      f_position = f_momentum;
      return;
    }
    if (!solver_ || assembly_ != assembly) {
      solver_ = make_constraint_solver(assembly);
      assembly_ = assembly;
    }
    zero_force_.setZero(f_momentum.size());  // no allocation once it has the size
    solver_->prepare(rows_, bodies, settings.kind, settings.precision, settings.workers, nullptr);
    solver_->solve(rows_, bodies, zero_force_, TargetTerms::push_from_rest, settings, lambda_,
                   nullptr);
    add_constraint_forces(rows_, lambda_, f_momentum, f_position);  // + J_p^T lambda_p
  }

  std::vector<ConstraintRow> rows_;  // c_p pseudo-velocity rows
  std::vector<double> lambda_;       // c_p, N
  Eigen::VectorXd zero_force_;       // 6n zeros: no external force on the pseudo-velocities
  std::unique_ptr<ConstraintSolver> solver_;
  Assembly assembly_ = Assembly::matrix_free;
};

}  // namespace

std::unique_ptr<PushMethod> make_split_impulse() { return std::make_unique<SplitImpulse>(); }

}  // namespace cps
