#pragma once
// The soft step: `--push soft`. Sources: Box2D v3 (erincatto/box2d, src/solver.c b2SolverStage
// order: integrate velocities, warm start, solve, integrate positions, relax, restitution;
// src/contact_solver.c b2PrepareContactsTask, b2SolveContact, b2ApplyRestitution; src/solver_set.c
// and src/core.h b2MakeSoft; src/distance_joint.c for the rods); E. Catto, "Solver2D" (2024,
// box2d.org/posts/2024/02/solver2d), the soft step solver.
//
// Soft rows. A row with stiffness f (Hz) and damping ratio zeta over a substep h (s) is a
// damped spring of angular frequency omega = 2 pi f solved implicitly (Catto, "Soft
// constraints", GDC 2011). With a1 = 2 zeta + h omega and a2 = h omega a1, b2MakeSoft gives
//   bias rate = omega / a1 (1/s),  mass scale = a2 / (1 + a2),  impulse scale = 1 / (1 + a2),
// and the sequential impulse update lambda += -m_eff (mass scale) (J v + bias) - (impulse scale)
// lambda. In the paper's terms (lambda a force, A = J M^-1 J^T, b of Eq. 6.2.9 with the target
// v = bias rate x depth): its fixed point is (A + gamma diag(A)) lambda = b with
// gamma = 1 / a2, and PGS on that matrix is the same update (SolveSettings::softness).
//
// One step of length dt is soft_substeps substeps of h = dt / substeps. The rows, A and each
// body's I^-1 are those of the start of the step (as Box2D's: it does not collide again within
// a step). Each substep, from the momenta v0 it starts with:
//   1. soft solve: every contact row with current separation s <= 0 (an overlap) targets
//      min(bias rate x max(-s - slop, 0), contact_push_max_speed) and is soft (contact_hertz,
//      capped at a quarter of the substep rate as Box2D does, twice it against a static body);
//      a separated one (s > 0) targets -s / h and is rigid (it may close its gap within the
//      substep, no further, like a speculative contact). Each rod targets -bias rate x C (C its current length error, m) and
//      is soft (rod_hertz, rod_damping_ratio: Box2D's joint softness). Friction rows target 0,
//      rigid. lambda_s starts from the previous substep's relaxed lambda: Box2D's accumulated
//      impulse, which it re-applies each substep ("warm start"); the first substep starts from
//      the warm starting cache (WorldDef::warm_start times the last step's relaxed lambda,
//      Sec. 6.2.3; Box2D always warm starts, with factor 1) or from 0.
//   2. positions move with f_s = f_ext + J^T lambda_s over h (Eqs. 3.2.3-3.2.4); the momenta
//      stay v0.
//   3. relax solve: the same rows, rigid, without the push (a contact targets -s / h if its
//      points separated in the substep, else 0; rods 0), from the momenta v0; its
//      f_r = f_ext + J^T lambda_r sets the momenta (Eqs. 3.2.1-3.2.2). Box2D applies the relax
//      as a change of velocity from v_soft with its accumulated impulse, that is, it starts
//      from lambda_s (solving from v0 for the total lambda_r gives the same velocity). Here it
//      starts from the previous substep's lambda_r instead (the warm start guess in the first
//      substep), as the paper's second solve of Sec. 8.1 starts from its own lambda and not from
//      the first's (world.cpp): lambda_s carries the push, and the sweeps that do not converge
//      leave part of it in the momenta. Measured from lambda_s at 25 sweeps: the intersecting
//      stack's cubes reach 1.24 m/s, and energy enters beyond the push work by up to 1.13 J in a
//      step of chain_20 and 0.29 J at dt = 0.1 s (tests/test_stress.cpp, "[push_methods]");
//      from the last lambda_r: 0.003 m/s, and the bound holds. Box2D's one relax sweep per
//      substep could not do more than continue from lambda_s.
// After the last substep the restitution of a contact that approached faster than the
// threshold at the start of the step (ConstraintRow::restitution, Eq. 8.2.1) is applied: the
// last relax solve targets it (Box2D runs a separate restitution pass over those points after
// the relax; here it is folded into the last relax, which then also keeps the other rows).
// The current separation of a contact is that of its point fixed in both bodies' frames along
// the normal of the start of the step, s = -d + n . (p_b - p_a) (Box2D's: fixed normal,
// anchors rotated with their bodies); a rod's error is from its current end points.
//
// In the paper's terms each substep is the single frame push factor (Sec. 8.1) at dt = h with
// soft rows: positions move with the solve that has the push, the momenta with the one that has
// not; the differences are the soft rows, the push rate (bias rate with a speed limit instead of
// beta / h), the substeps, and the second solve started from the first's lambda.
//
// Both solvers (the soft rows in PGS and Jacobi alike), both friction models (friction rows are
// rigid), both assemblies (the explicit path adds gamma diag(A) to A; the matrix-free path
// sweeps soft rows row by row), restitution as above. Cost: 2 x substeps solves of `iterations`
// sweeps each per step (Box2D v3 runs 4 substeps of one sweep each: `--iterations 1`).
// After a step, the rows' push and bias hold the targets of the last relax solve.

#include "cps/body.h"
#include "cps/collision.h"
#include "cps/constraint.h"
#include "cps/parameters.h"

#include <vector>

namespace cps {

/// Box2D's soft parameters of one kind of row over a substep.
struct Softness {
  double bias_rate = 0.0;  ///< 1/s: the push is bias_rate x depth (m/s)
  double gamma = 0.0;      ///< dimensionless: the row solves (A_jj (1 + gamma)) (SolveSettings)
};

/// b2MakeSoft: stiffness `hertz` (Hz, >= 0), damping ratio zeta (>= 0), substep h (s, > 0).
/// hertz = 0 gives a rigid row without push ({0, 0}). No errors.
Softness make_softness(double hertz, double zeta, double h);

/// What the substeps of one soft step need about the rows, and their targets.
class SoftStep {
 public:
  /// Records, for the step's rows (c; contact rows in the order of the manifolds' points, as
  /// World::build_rows makes them, then friction rows, then one row per distance constraint), each
  /// contact's point in the frames of its two bodies, its normal and depth, which rows touch a
  /// static body, and the softness of each kind for def (substep h = def.dt / def.soft_substeps).
  /// bodies: as at the start of the step. No errors.
  void begin(const std::vector<ConstraintRow>& rows, const std::vector<Manifold>& manifolds,
             const std::vector<Body>& bodies, const WorldDef& def);

  /// Sets every row's push and bias (m/s) for one solve from the bodies as they are now (header
  /// comment): the soft solve (soft = true; softness() then holds each row's gamma) or the relax
  /// solve (soft = false; with the restitution targets when last). No errors.
  void set_targets(std::vector<ConstraintRow>& rows, const std::vector<DistanceConstraint>& distances,
                   const std::vector<Body>& bodies, bool soft, bool last);

  /// gamma per row (c) of the last soft set_targets.
  const std::vector<double>& softness() const { return softness_; }
  /// The substep of the current step (s).
  double substep() const { return h_; }

 private:
  struct ContactPoint {
    Vec3 local_a = Vec3::Zero();  ///< the point in a's frame (m)
    Vec3 local_b = Vec3::Zero();  ///< the point in b's frame (m)
    Vec3 normal = Vec3::UnitY();
    double depth = 0.0;           ///< m, at the start of the step
    bool touches_static = false;
  };
  std::vector<ContactPoint> contacts_;  // one per contact row, in row order
  std::vector<double> softness_;
  Softness contact_soft_;
  Softness static_soft_;
  Softness rod_soft_;
  double h_ = 0.0;
  double slop_ = 0.0;
  double max_push_ = 0.0;
};

}  // namespace cps
