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
//      the first's (split.cpp): lambda_s carries the push, and the sweeps that do not converge
//      leave part of it in the momenta. Measured from lambda_s at 25 sweeps: the intersecting
//      stack's cubes reach 1.24 m/s, and energy enters beyond the push work by up to 1.13 J in a
//      step of chain_20 and 0.29 J at dt = 0.1 s (tests/physics/test_stress.cpp, "[push_methods]");
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

#include "push_method.h"

#include "../buffers.h"
#include "../integrator.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace cps {
namespace {

// Box2D's soft parameters of one kind of row over a substep.
struct Softness {
  double bias_rate = 0.0;  // 1/s: the push is bias_rate x depth (m/s)
  double gamma = 0.0;      // dimensionless: the row solves (A_jj (1 + gamma)) (SolveSettings)
};

// b2MakeSoft: stiffness `hertz` (Hz, >= 0), damping ratio zeta (>= 0), substep h (s, > 0).
// hertz = 0 gives a rigid row without push ({0, 0}).
Softness make_softness(double hertz, double zeta, double h) {
  if (!(hertz > 0.0)) return {};
  const double omega = 2.0 * std::numbers::pi * hertz;
  const double a1 = 2.0 * zeta + h * omega;
  const double a2 = h * omega * a1;
  return {omega / a1, 1.0 / a2};
}

class SoftStep final : public PushMethod {
 public:
  // Per substep a soft solve that moves the positions, then a relax solve that sets the momenta;
  // lambda carried from each solve to the next.
  void step(StepContext& ctx) override {
    const WorldDef& def = *ctx.def;
    if (ctx.rows.empty()) {  // nothing to solve: substeps of free flight under f_ext
      const double h = def.dt / static_cast<double>(def.soft_substeps);
      for (int k = 0; k < def.soft_substeps; ++k) ctx.integrate(ctx.f_ext, ctx.f_ext, h);
      ctx.lambda.clear();
      ctx.lambda_second.clear();
      return;
    }
    begin(ctx.rows, ctx.manifolds, *ctx.bodies, def);
    zero_force_.setZero(ctx.f_ext.size());  // no allocation once it has the size
    const std::vector<double>* start = ctx.warm_guess();
    for (int k = 0; k < def.soft_substeps; ++k) {
      // 1. soft solve (lambda_second) from the last relaxed lambda
      set_targets(ctx.rows, *ctx.distances, *ctx.bodies, /*soft=*/true, /*last=*/false);
      SolveSettings soft_settings = ctx.settings(h_);
      soft_settings.softness = &softness_;
      ctx.solve(soft_settings, TargetTerms::push_and_bias, ctx.lambda_second, ctx.f_cv, start);
      // 2. positions with f_s; momenta kept
      ctx.integrate(ctx.f_cv, zero_force_, h_);
      // 3. relax solve (lambda), rigid, without the push, from the last relaxed lambda (not
      //    lambda_s, which carries the push: see the comment at the top); it sets the momenta
      set_targets(ctx.rows, *ctx.distances, *ctx.bodies, /*soft=*/false,
                  /*last=*/k + 1 == def.soft_substeps);
      detail::reserve_with_headroom(relax_start_, ctx.lambda.size());
      relax_start_.assign(ctx.lambda.begin(), ctx.lambda.end());
      ctx.solve(ctx.settings(h_), TargetTerms::bias_only, ctx.lambda, ctx.f_c0,
                k > 0 ? &relax_start_ : ctx.warm_guess());
      add_momenta(*ctx.bodies, ctx.f_c0, h_);
      start = &ctx.lambda;
    }
    ctx.lambda_second.clear();
    ctx.store_warm_start();
  }

 private:
  struct ContactPoint {
    Vec3 local_a = Vec3::Zero();  // the point in a's frame (m)
    Vec3 local_b = Vec3::Zero();  // the point in b's frame (m)
    Vec3 normal = Vec3::UnitY();
    double depth = 0.0;           // m, at the start of the step
    bool touches_static = false;
  };

  // Records, for the step's rows (c; contact rows in the order of the manifolds' points, as
  // World::build_rows makes them, then friction rows, then one row per distance constraint),
  // each contact's point in the frames of its two bodies, its normal and depth, which rows touch
  // a static body, and the softness of each kind for def (substep h = def.dt / soft_substeps).
  // bodies: as at the start of the step.
  void begin(const std::vector<ConstraintRow>& rows, const std::vector<Manifold>& manifolds,
             const std::vector<Body>& bodies, const WorldDef& def) {
    h_ = def.dt / static_cast<double>(def.soft_substeps);
    slop_ = def.penetration_slop;
    max_push_ = def.contact_push_max_speed;
    // Box2D: the contact stiffness at most a quarter of the substep rate; twice it for a contact
    // with a static body.
    const double contact_hertz = std::min(def.contact_hertz, 0.25 / h_);
    contact_soft_ = make_softness(contact_hertz, def.contact_damping_ratio, h_);
    static_soft_ = make_softness(2.0 * contact_hertz, def.contact_damping_ratio, h_);
    rod_soft_ = make_softness(def.rod_hertz, def.rod_damping_ratio, h_);
    contacts_.clear();
    detail::reserve_with_headroom(contacts_, contact_point_count(manifolds));
    for_each_contact_point(manifolds, bodies, [this](const Manifold&, const Contact& c,
                                                     const Body& a, const Body& b,
                                                     const Mat3& Ra_t, const Mat3& Rb_t) {
      ContactPoint& p = contacts_.emplace_back();
      p.local_a = Ra_t * (c.point - a.x);
      p.local_b = Rb_t * (c.point - b.x);
      p.normal = c.normal;
      p.depth = c.depth;
      p.touches_static = a.is_static() || b.is_static();
    });
    detail::resize_with_headroom(softness_, rows.size());
  }

  // Sets every row's push and bias (m/s) for one solve from the bodies as they are now (the
  // comment at the top): the soft solve (soft = true; softness_ then holds each row's gamma) or
  // the relax solve (soft = false; with the restitution targets when last).
  void set_targets(std::vector<ConstraintRow>& rows,
                   const std::vector<DistanceConstraint>& distances,
                   const std::vector<Body>& bodies, bool soft, bool last) {
    std::size_t contact = 0;
    std::size_t rod = 0;
    for (std::size_t r = 0; r < rows.size(); ++r) {
      ConstraintRow& row = rows[r];
      double gamma = 0.0;
      row.push = 0.0;
      row.bias = 0.0;
      if (row.kind == RowKind::contact) {
        const ContactPoint& p = contacts_[contact++];
        const Body& a = bodies[static_cast<std::size_t>(row.body_a)];
        const Body& b = bodies[static_cast<std::size_t>(row.body_b)];
        // s = -d + n . (p_b - p_a): both points were at the contact point at the start of the step.
        const double s =
            -p.depth + p.normal.dot((b.x + b.rotation() * p.local_b) - (a.x + a.rotation() * p.local_a));
        if (s > 0.0) {
          // Rigid: the points may approach by the gap s within the substep, no further (j . v >=
          // -s / h; Box2D's bias s / h in its sign convention, as a speculative contact here).
          row.bias = -s / h_;
        } else if (soft) {
          const Softness& k = p.touches_static ? static_soft_ : contact_soft_;
          row.push = std::min(k.bias_rate * std::max(-s - slop_, 0.0), max_push_);
          gamma = k.gamma;
        }
        if (!soft && last && row.restitution > 0.0) row.bias = row.restitution;
      } else if (row.kind == RowKind::distance) {
        if (soft) {
          Vec3 pa;
          Vec3 pb;
          distance_endpoints(distances[rod], bodies, pa, pb);
          row.push = -rod_soft_.bias_rate * ((pb - pa).norm() - distances[rod].length);
          gamma = rod_soft_.gamma;
        }
        ++rod;
      }
      softness_[r] = gamma;
    }
  }

  std::vector<ContactPoint> contacts_;  // one per contact row, in row order
  std::vector<double> softness_;        // gamma per row (c) of the last soft set_targets
  std::vector<double> relax_start_;     // the last relaxed lambda (c, N)
  Eigen::VectorXd zero_force_;          // 6n zeros: the positions-only integration
  Softness contact_soft_;
  Softness static_soft_;
  Softness rod_soft_;
  double h_ = 0.0;  // the substep (s)
  double slop_ = 0.0;
  double max_push_ = 0.0;
};

}  // namespace

std::unique_ptr<PushMethod> make_soft_step() { return std::make_unique<SoftStep>(); }

}  // namespace cps
