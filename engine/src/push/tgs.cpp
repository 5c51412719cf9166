// Temporal Gauss-Seidel: `--push tgs`. Sources: NVIDIA PhysX 5, PxSolverType::eTGS (the
// position iterations are substeps: each solves the rows once with the bias from the current
// separation and integrates the positions; then the velocity iterations solve without the bias;
// PxRigidBody::setMaxDepenetrationVelocity caps the bias); M. Macklin, K. Storey, M. Lu, P.
// Terdiman, N. Chentanez, S. Jeschke, M. Mueller, "Small Steps in Physics Simulation" (SCA 2019),
// substepping with one iteration per substep; E. Catto, "Solver2D" (2024,
// box2d.org/posts/2024/02/solver2d), TGS-soft, whose soft form Box2D v3 runs (soft_step.cpp).
//
// Derivation, in the paper's terms. One step of length dt is N = tgs_substeps substeps of
// h = dt / N. The rows, A and each body's I^-1 are those of the start of the step (as PhysX's:
// no collision within the step); the contact points stay fixed in the frames of their bodies and
// a contact's current separation is s = -d + n . (p_b - p_a) (as soft_step.cpp). From the
// momenta v0 of the start of the step:
//   1. each substep: one solve of A lambda = b (Eq. 6.2.9) over h with rigid rows whose target
//      carries the Baumgarte push of the current error at the substep (Eq. 5.3.1 with dt = h):
//        contact with s <= 0: push = min(beta max(-s - slop, 0) / h, max_depenetration_speed);
//        contact with s > 0:  bias = -s / h (it may close its gap within the substep, no further);
//        rod: push = -beta C / h (C its current length error); friction rows: 0;
//      then positions AND momenta move with f_cv = f_ext + J^T lambda_k (Eqs. 3.2.1-3.2.4) over h:
//      the biased velocity is kept from one substep to the next, as PhysX's position iterations
//      keep it;
//   2. the relax (PhysX's velocity iterations): the momenta go back to v0 and one solve over the
//      whole step, rigid rows without push (a contact separated by s > 0 at the end of the step
//      targets -s / dt, one with restitution its bounce, Eq. 8.2.1; every other row 0), sets
//      them with f_c0 = f_ext + J^T lambda_r (Eqs. 3.2.1-3.2.2); the positions are not moved.
// PhysX runs its velocity iterations from the velocity the substeps left and from their
// accumulated impulse, with the clamp lambda >= 0 on that total: at convergence that is the
// same LCP as the solve from v0 over dt with f_ext, which is what cps solves; with few sweeps
// PhysX keeps part of the bias in the velocity (hence its depenetration cap), while here the
// relax starts from its own warm start (the previous step's lambda_r times warm_start, or 0),
// as the second solve of Sec. 8.1 does (split.cpp), and gets `iterations` sweeps.
//
// Sweeps. Each substep's solve gets ceil(iterations / N) sweeps, started from the previous
// substep's lambda (the first from the warm start), so that the biased sweeps of a step are the
// paper's `iterations` (rounded up) and `--compare push` at one --iterations compares methods at
// about one cost; `--iterations 4` with 4 substeps is PhysX's one sweep per position iteration.
//
// How it differs from `--push soft` (Box2D v3's soft step, TGS-soft):
//   - rows: here rigid, with a Baumgarte bias beta x error / h per substep, capped at
//     max_depenetration_speed; soft's are implicit springs (contact_hertz, damping ratio) whose
//     bias rate and impulse scale come from b2MakeSoft, capped at contact_push_max_speed;
//   - momenta: here the substeps keep their biased velocity in the momenta and one relax over the
//     whole step replaces it at the end; soft relaxes after every substep (positions with the
//     soft solve, momenta with the relax), so no bias reaches the next substep;
//   - cost: here N solves of ceil(iterations / N) sweeps plus one of `iterations`; soft: 2 N solves
//     of `iterations` each.
// And from `--push split` (Sec. 8.1): the push solve is cut into substeps that see the error as
// the positions move, so more than beta of an overlap is corrected within a step (1 - (1 -
// beta)^N of it).
//
// Both solvers, both friction models, both assemblies (the solves are the paper's), restitution
// (in the relax), warm starting (of the first substep and of the relax). After a step, the rows'
// push and bias hold the relax's targets; lambda is the relax's (the step's contact forces).

#include "push_method.h"

#include "../buffers.h"
#include "../integrator.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace cps {
namespace {

class TemporalGaussSeidel final : public PushMethod {
 public:
  // Biased substeps that move positions and momenta, then the relax over the step from v0.
  void step(StepContext& ctx) override {
    const WorldDef& def = *ctx.def;
    const int substeps = def.tgs_substeps;
    const double h = def.dt / static_cast<double>(substeps);
    ctx.lambda_second.clear();
    if (ctx.rows.empty()) {  // nothing to solve: substeps of free flight under f_ext
      for (int k = 0; k < substeps; ++k) ctx.integrate(ctx.f_ext, ctx.f_ext, h);
      ctx.lambda.clear();
      return;
    }
    begin(ctx.manifolds, *ctx.bodies);
    SolveSettings biased = ctx.settings(h);
    biased.iterations = (def.iterations + substeps - 1) / substeps;
    const std::vector<double>* start = ctx.warm_guess();
    for (int k = 0; k < substeps; ++k) {
      set_targets(ctx.rows, *ctx.distances, *ctx.bodies, def, h, /*relax=*/false);
      if (k > 0) {  // the solve's start must not be its output buffer
        detail::reserve_with_headroom(previous_, ctx.lambda_second.size());
        previous_.assign(ctx.lambda_second.begin(), ctx.lambda_second.end());
        start = &previous_;
      }
      ctx.solve(biased, TargetTerms::push_and_bias, ctx.lambda_second, ctx.f_cv, start);
      ctx.integrate(ctx.f_cv, ctx.f_cv, h);
    }
    restore_momenta(*ctx.bodies);
    set_targets(ctx.rows, *ctx.distances, *ctx.bodies, def, def.dt, /*relax=*/true);
    ctx.solve(ctx.settings(def.dt), TargetTerms::bias_only, ctx.lambda, ctx.f_c0, ctx.warm_guess());
    add_momenta(*ctx.bodies, ctx.f_c0, def.dt);
    ctx.lambda_second.clear();
    ctx.store_warm_start();
  }

 private:
  struct ContactPoint {
    Vec3 local_a = Vec3::Zero();  // the point in a's frame (m)
    Vec3 local_b = Vec3::Zero();  // the point in b's frame (m)
    Vec3 normal = Vec3::UnitY();
    double depth = 0.0;  // m, at the start of the step
  };

  // Records each contact's point in the frames of its bodies, its normal and depth (in the order
  // of the contact rows), and every body's momenta v0 (bodies as at the start of the step).
  void begin(const std::vector<Manifold>& manifolds, const std::vector<Body>& bodies) {
    contacts_.clear();
    detail::reserve_with_headroom(contacts_, contact_point_count(manifolds));
    for_each_contact_point(manifolds, bodies, [this](const Manifold& m, const Contact& c,
                                                     const Body& a, const Body& b,
                                                     const Mat3& Ra_t, const Mat3& Rb_t) {
      contacts_.push_back({Ra_t * (c.point - a.x), Rb_t * (point_on_b(m, c) - b.x), c.normal, c.depth});
    });
    detail::resize_with_headroom(momenta_, bodies.size());
    for (std::size_t i = 0; i < bodies.size(); ++i) momenta_[i] = {bodies[i].p, bodies[i].l};
  }

  void restore_momenta(std::vector<Body>& bodies) const {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      bodies[i].p = momenta_[i].first;
      bodies[i].l = momenta_[i].second;
    }
  }

  // Sets every row's push and bias (m/s) from the bodies as they are now (the comment at the
  // top): a biased substep of length h (relax = false) or the relax over the step (h = dt).
  void set_targets(std::vector<ConstraintRow>& rows, const std::vector<DistanceConstraint>& distances,
                   const std::vector<Body>& bodies, const WorldDef& def, double h, bool relax) const {
    std::size_t contact = 0;
    std::size_t rod = 0;
    for (ConstraintRow& row : rows) {
      row.push = 0.0;
      row.bias = 0.0;
      if (row.kind == RowKind::contact) {
        const ContactPoint& p = contacts_[contact++];
        const Body& a = bodies[static_cast<std::size_t>(row.body_a)];
        const Body& b = bodies[static_cast<std::size_t>(row.body_b)];
        const double s = -p.depth + p.normal.dot((b.x + b.rotation() * p.local_b) -
                                                 (a.x + a.rotation() * p.local_a));
        if (s > 0.0) {
          row.bias = -s / h;
        } else if (!relax) {
          row.push = std::min(def.beta * std::max(-s - def.penetration_slop, 0.0) / h,
                              def.max_depenetration_speed);
        }
        if (relax && row.restitution > 0.0) row.bias = row.restitution;
      } else if (row.kind == RowKind::distance) {
        if (!relax) {
          Vec3 pa;
          Vec3 pb;
          distance_endpoints(distances[rod], bodies, pa, pb);
          row.push = -def.beta * ((pb - pa).norm() - distances[rod].length) / h;
        }
        ++rod;
      }
    }
  }

  std::vector<ContactPoint> contacts_;            // one per contact row, in row order
  std::vector<std::pair<Vec3, Vec3>> momenta_;    // n: p (N s) and l (N m s) at the step's start
  std::vector<double> previous_;                  // c, N: the last substep's lambda
};

}  // namespace

std::unique_ptr<PushMethod> make_tgs() { return std::make_unique<TemporalGaussSeidel>(); }

}  // namespace cps
