// The soft step: `--push soft`. Sources: Box3D (erincatto/box3d 0.1.0, src/solver.c: the stage
// order of b3SolverStep; src/contact_solver.c: b3PrepareContacts, b3WarmStartContacts,
// b3SolveContacts with useBias true and false, b3ApplyRestitution, b3StoreImpulses;
// src/distance_joint.c: the rigid rod; src/solver.h: b3MakeSoft; src/physics_world.c: the
// softness of a step) and Box2D v3 (erincatto/box2d, src/solver.c, src/contact_solver.c), whose
// 2D solver Box3D's follows; E. Catto, "Solver2D" (2024), the soft step.
//
// Soft rows. A row with stiffness f (Hz) and damping ratio zeta over a substep h (s) is a damped
// spring of angular frequency omega = 2 pi f solved implicitly (Catto, "Soft constraints", GDC
// 2011). With a1 = 2 zeta + h omega and a2 = h omega a1 (b3MakeSoft):
//   bias rate = omega / a1 (1/s), mass scale = a2 / (1 + a2), impulse scale = 1 / (1 + a2),
// and a row's sequential impulse update (impulses P in N s over one substep, the row's effective
// mass m = 1 / (J M^-1 J^T) = 1 / A_jj of Eq. 6.2.9) is
//   dP = -m (mass scale) (J v + bias rate C) - (impulse scale) P,   P += dP, clamped,
// with C the row's current position error (m, negative for an overlap). In the paper's terms the
// row force is lambda = P / h (N) and the push is the target -bias rate C (m/s) of Eq. 5.3.1
// with a spring's rate in place of beta / dt.
//
// One step of length dt is soft_substeps substeps of h = dt / soft_substeps, in Box3D's stages:
//   prepare (once a step): each contact point's anchors r_a, r_b relative to the centres of
//     mass (m, world frame, fixed for the step), its normal and tangents and the effective mass
//     of each of its rows, its separation at the start of the step and its approach speed (for
//     restitution); each rod's anchors and axial mass; each body's I^-1 (as in b3PrepareContacts:
//     the bodies' inverse inertias of the start of the step serve every substep). The impulses
//     start from the warm-start cache (WorldDef::warm_start times the last step's, Sec. 6.2.3;
//     Box3D always warm starts with factor 1) or from 0: as Box3D keeps them on its contacts
//     (WarmStartRule::manifold; b3UpdateContact, b3PrepareContacts), each point's normal impulse
//     found by its feature id, and the friction impulse (a vector, projected onto this step's
//     tangents) and twist of the manifold of the same body pair, whichever points it has. The
//     restart variant below takes the sustained rule of the other methods, by row.
//   each substep:
//     1. integrate velocities: v += h m^-1 f, w += h I^-1 tau (f_ext, Sec. 6.1);
//     2. warm start: every row's accumulated impulse applied to the velocities;
//     3. solve (bias on), `iterations` sweeps: per graph colour its rods, then its manifolds'
//        contact points (below). A
//        point with current separation s > 0 is speculative: rigid, bias s / h (the points may
//        close the gap within the substep, no further). Else the row is soft with the push
//        max(mass scale x bias rate x min(s + slop, 0), -contact_push_max_speed) (Box3D's
//        contactSpeed cap; slop 0 is Box3D's). Contacts with a static body are stiffer: twice
//        the stiffness and half the damping ratio. No friction here (b3SolveContacts: "No
//        friction when applying bias").
//     4. integrate positions: x += h v; o += 1/2 [0, w] o h, normalised (Eq. 3.2.4; or the
//        axis-angle step of Eq. 12.4.1); each body's displacement dp and rotation dq over the
//        step so far are kept, and a point's current separation is
//        s = s0 + n . (dp_b - dp_a + dq_b r_b - dq_a r_a) - n . (r_b - r_a) at fixed n.
//     5. relax (bias off), `iterations` sweeps, continuing from the accumulated impulses (with
//        soft_relax restart instead from the velocities before step 2 and the impulses the last
//        relax left, re-applied: the variant below): rods
//        rigid, contact points rigid (speculative ones keep s / h), then each manifold's
//        friction at its centre (b3PrepareContacts' weighted average of the anchors): a twist
//        row about the normal and two tangent rows with their coupled 2 x 2 effective mass,
//        clamped to a disc of radius mu times the manifold's normal impulse (the coupled
//        model, as Box3D) or the sum of its points' fixed limits mu m |g.n| / points (Sec. 5.4),
//        the twist to the same times the points' lever arms.
//   after the last substep:
//     6. restitution: each contact point with a restitution target v_r (Eq. 8.2.1, its
//        contact row's, restitution_target) that took an impulse in the step gets
//        dP = -m (J v - v_r), the accumulated impulse clamped at 0 (b3ApplyRestitution);
//     7. store impulses (b3StoreImpulses): the points' normal impulses and each manifold's
//        friction vector and twist, over h, into the warm-start cache; the bodies' momenta
//        p = m v, l = I w with the I of the start of the step. ctx.lambda (lambda = P / h per
//        row, N; a manifold's friction as forces at its points' friction rows) is written when
//        asked for (write_lambda()).
// Stiffness: the contact's is capped at an eighth of the substep rate (b3World_Step), a rod's at
// a quarter (b3PrepareJoint). A rod (distance constraint) is Box3D's rigid distance joint: its
// axis and anchors follow the bodies within the step (the current anchors, dq r), its effective
// mass is the start of the step's; its error C = |p_b - p_a| - length.
//
// The variant soft_relax = restart is the single frame push factor's second solve (Sec. 8.1) at
// dt = h: the soft solve's impulses move the positions and are then taken back, and the relax
// sets the momenta from where the substep began; it warm starts by the sustained rule (the
// smaller of the last two lambdas, warm_start.h), whose reason it shares. Box3D's relax continues from the soft solve's
// velocities and impulses; where one relax sweep does not take out all of the push, the rest stays
// in the momenta, and a step can gain more energy than its push's work: measured at 25 sweeps on
// chain_20 (1.36 J in a step), the stack at dt = 0.1 s (0.20 J) and the heavy ball on the grid
// (0.15 J), where restart keeps the bound (tests/physics/test_stress.cpp, "[push_methods]").
//
// Sweep order: the rods and manifolds are graph-coloured once a step (constraint_graph.h, Box3D's
// constraint graph: 23 colours and an overflow; the rods first, then the manifolds, each in
// order); the warm start, solve and relax sweep the overflow in order, then colour by colour. The rows
// of a colour share no moving body, so WorldDef::threads threads share each colour's rows
// (workers.h; a barrier after each colour) and every count gives the same result.
//
// Lanes: outside the overflow, a colour's manifolds are swept four at a time in SIMD lanes
// (soft_lanes.h, Box3D's wide contact solver), each lane's arithmetic the scalar sweep's, so the
// result is the same bit for bit; the overflow, the rods and the restart variant are swept one
// at a time.
//
// Differences from Box3D: double precision (its lanes are floats); the manifolds as the collide
// stage makes them (WorldDef::manifold_points and contact_recycle_distance choose Box3D's 4
// points and its recycling, whose anchors stay as they were made, as Box3D's); no rolling
// resistance, no gyroscopic term (Box3D integrates one; for the spheres and cubes of the scenes
// it is zero), no speed caps on the bodies (Box3D clamps at 400 m/s and a quarter turn a step).
// The solvers of A lambda = b (--solver, --assembly) play no part: the rows are swept as the
// source sweeps them, Gauss-Seidel over body velocities.

#include "push_method.h"
#include "soft_lanes.h"

#include "../buffers.h"
#include "../constraint_graph.h"
#include "../integrator.h"
#include "../workers.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <numbers>
#include <utility>
#include <vector>

namespace cps {
namespace {

// Fewest bodies or manifolds a stage shares among threads (count): below it waking them
// (microseconds, tens on a virtual machine) costs about what the work does.
constexpr std::size_t kMinParallel = 256;

// Manifolds ahead whose bodies and lanes the prepare stage asks for (count; twice as far for the
// manifolds themselves; prefetch_manifold()).
constexpr std::size_t kManifoldsAhead = 4;

using soft::LaneGroup;
using soft::LanePoint;
using soft::Softness;
using soft::SolverBody;

// Stiffness `hertz` (Hz, >= 0), damping ratio zeta (>= 0), substep h (s, > 0). hertz = 0 gives a
// rigid row without push.
Softness make_softness(double hertz, double zeta, double h) {
  if (!(hertz > 0.0)) return {};
  const double omega = 2.0 * std::numbers::pi * hertz;
  const double a1 = 2.0 * zeta + h * omega;
  const double a2 = h * omega * a1;
  const double a3 = 1.0 / (1.0 + a2);
  return {omega / a1, a2 * a3, a3};
}

// One row along a unit axis between anchors r_a, r_b (a contact's normal): what a sweep reads,
// prepared once a step. r_a x axis and r_b x axis are not kept: the sweeps form them from the
// anchors, which they read anyway, so that a point streams fewer bytes.
struct AxisRow {
  Vec3 axis = Vec3::Zero();
  Vec3 Irn_a = Vec3::Zero();   // I_a^-1 (r_a x axis)
  Vec3 Irn_b = Vec3::Zero();   // I_b^-1 (r_b x axis)
  double mass = 0.0;           // kg: 1 / (J M^-1 J^T)
  double impulse = 0.0;        // N s: accumulated over the current substep
};

struct ContactPoint {
  int a = 0;
  int b = 0;
  int row = 0;                   // the contact row's index in ctx.rows
  bool touches_static = false;
  Vec3 r_a = Vec3::Zero();       // m: anchor relative to a's centre of mass
  Vec3 r_b = Vec3::Zero();
  double base_separation = 0.0;  // m: s0 - n . (r_b - r_a)
  double restitution = 0.0;      // m/s: the row's restitution target (0: none)
  double total_impulse = 0.0;    // N s: sum of the normal impulses over the step
  double lever_arm = 0.0;        // m: distance from the manifold's friction centre (on a)
  AxisRow normal;
};

// A manifold's friction, solved once at its centre as Box3D solves it (b3PrepareContacts: the
// anchors' average weighted by closeness; two tangent rows with a coupled 2 x 2 effective mass,
// clamped to a disc; a twist row about the normal clamped by the points' lever arms).
struct ManifoldFriction {
  int a = 0;
  int b = 0;
  std::size_t begin = 0;  // its points in contacts_ (from 0 in a scratch buffer for a lane's)
  std::size_t end = 0;
  int first_friction_row = -1;  // the friction rows of its first point in ctx.rows, or -1
  Vec3 normal = Vec3::UnitY();
  Vec3 t1 = Vec3::UnitX();
  Vec3 t2 = Vec3::UnitZ();
  Vec3 center_a = Vec3::Zero();  // m: the centre relative to a's centre of mass
  Vec3 center_b = Vec3::Zero();
  Eigen::Matrix2d tangent_mass = Eigen::Matrix2d::Zero();  // kg: the inverse of K (2 x 2)
  Eigen::Vector2d impulse = Eigen::Vector2d::Zero();       // N s along t1, t2
  double twist_mass = 0.0;     // kg m^2
  double twist_impulse = 0.0;  // N m s
  double mu = 0.0;
  double fixed_limit = -1.0;   // N s a substep: the fixed model's limit per point; < 0: coupled
};


struct Rod {
  int a = 0;
  int b = 0;
  int row = 0;
  Vec3 r_a = Vec3::Zero();  // m: anchor relative to a's centre, world frame, start of the step
  Vec3 r_b = Vec3::Zero();
  Vec3 delta_center = Vec3::Zero();  // m: centre of b minus centre of a at the start
  double length = 0.0;
  double mass = 0.0;     // kg: axial effective mass at the start of the step
  double impulse = 0.0;  // N s
  Vec3 axis0 = Vec3::UnitY();  // the start of the step's axis, for a rod of length 0
};

// The velocity of a body's point at offset r (m/s).
inline Vec3 point_velocity(const SolverBody& s, const Vec3& r) { return s.v + s.w.cross(r); }

// j . v of an axis row with anchors r_a, r_b (m; m/s): the rate at which the points separate
// along the axis.
inline double row_speed(const AxisRow& row, const Vec3& r_a, const Vec3& r_b, const SolverBody& a,
                        const SolverBody& b) {
  return row.axis.dot(b.v - a.v) + r_b.cross(row.axis).dot(b.w) - r_a.cross(row.axis).dot(a.w);
}

// Applies impulse P (N s) along an axis row: -P to a, +P to b.
inline void apply(const AxisRow& row, double P, SolverBody& a, SolverBody& b) {
  a.v -= (a.inv_mass * P) * row.axis;
  a.w -= P * row.Irn_a;
  b.v += (b.inv_mass * P) * row.axis;
  b.w += P * row.Irn_b;
}

// Sets `row` (in place: a contact point's is written straight into its storage) along unit
// `axis` between anchors r_a, r_b (m) of bodies a and b, with accumulated impulse `impulse` (N s).
void set_axis_row(AxisRow& row, const Vec3& axis, const Vec3& r_a, const Vec3& r_b, const SolverBody& a,
                  const SolverBody& b, double impulse) {
  row.axis = axis;
  const Vec3 rn_a = r_a.cross(axis);
  const Vec3 rn_b = r_b.cross(axis);
  row.Irn_a = a.inv_I * rn_a;
  row.Irn_b = b.inv_I * rn_b;
  const double k = a.inv_mass + b.inv_mass + rn_a.dot(row.Irn_a) + rn_b.dot(row.Irn_b);
  row.mass = k > 0.0 ? 1.0 / k : 0.0;
  row.impulse = impulse;
}

class SoftStep final : public PushMethod {
 public:
  // Box3D's warm start (the last step's impulses, kept by point and by manifold), or for the
  // restart variant the sustained rule of the other methods (warm_start.h).
  WarmStartRule warm_start_rule(const WorldDef& def) const override {
    return def.soft_relax == SoftRelax::restart ? WarmStartRule::sustained : WarmStartRule::manifold;
  }

  // Prepared from the manifolds; only the sustained rule of the warm start reads the rows' limits.
  bool reads_contact_rows(const WorldDef& def) const override { return def.soft_relax == SoftRelax::restart; }

  void step(StepContext& ctx) override {
    const WorldDef& def = *ctx.def;
    const double h = def.dt / static_cast<double>(def.soft_substeps);
    workers_ = ctx.workers() != nullptr ? ctx.workers() : &one_thread_;
    {
      StageTimer timer(ctx, &StageTimes::prepare);
      prepare(ctx, h);
    }
    auto substeps = [this, &ctx, h](int t) { run_substeps(ctx, h, t); };
    workers_->run(substeps);
    StageTimer timer(ctx, &StageTimes::store);
    apply_restitution(ctx.layout);
    store_momenta(ctx);
    ctx.lambda_second.clear();
    if (def.soft_relax == SoftRelax::continue_solve) {
      if (ctx.warm()) store_warm_start(ctx, 1.0 / h);
      inv_h_ = 1.0 / h;
      ctx.lambda_pending = true;  // write_lambda()
    } else {
      write_lambda(ctx, 1.0 / h, workers_);
      ctx.store_warm_start();  // from ctx.lambda
    }
  }

  void write_lambda(StepContext& ctx) const override { write_lambda(ctx, inv_h_, nullptr); }

 private:
  // Stage "prepare": solver bodies, contact points and rods from ctx's bodies, manifolds and the
  // rods' rows, with the warm-start impulses: Box3D's from the cache, or for the restart variant
  // by row (contact rows in the manifolds' point order, then two friction rows per point when the
  // world has friction, then one row per rod: World::build_rows, which leaves the contact and
  // friction rows unwritten: reads_contact_rows).
  void prepare(StepContext& ctx, double h) {
    const WorldDef& def = *ctx.def;
    const std::vector<Body>& bodies = *ctx.bodies;
    const std::vector<ConstraintRow>& rows = ctx.rows;
    // The warm start: by row (ctx's initial guesses) under the sustained rule, else Box3D's
    // impulses from the cache itself.
    const bool by_row = warm_start_rule(def) == WarmStartRule::sustained;
    const std::vector<double>* warm = by_row ? ctx.warm_guess() : nullptr;
    const WarmStartCache* last = !by_row && ctx.warm() ? ctx.warm_start.get() : nullptr;
    const auto guess = [&](std::size_t r) { return warm != nullptr ? (*warm)[r] * h : 0.0; };

    const std::size_t n = bodies.size();
    bodies_ = n;
    const auto threads = static_cast<std::size_t>(workers_->count());
    detail::resize_with_headroom(solver_bodies_, n + threads);
    detail::resize_with_headroom(inertia_, n);
    parallel_blocks(workers_, n, kMinParallel, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const Body& body = bodies[i];
        SolverBody& s = solver_bodies_[i];
        s = SolverBody{};
        if (body.is_static()) continue;
        s.inv_mass = body.inv_mass;
        s.inv_I = body.inv_inertia_world();
        s.v = body.velocity();
        s.w = s.inv_I * body.l;
        inertia_[i] = s.inv_I.inverse();
      }
    });
    for (std::size_t t = 0; t < threads; ++t) solver_bodies_[n + t] = SolverBody{};  // stand-ins
    // A static body and the world (kWorldBody) are -1 in the sweeps (body()); read here, a
    // static body's entry and the stand-in n are both zero.
    const auto index = [n](int body) { return body == kWorldBody ? n : static_cast<std::size_t>(body); };
    const auto moving = [&bodies](int body) { return moving_index(bodies, body); };

    // Box3D's softness of a step (b3World_Step, b3PrepareJoint).
    const double contact_hertz = std::min(def.contact_hertz, 0.125 / h);
    contact_soft_ = make_softness(contact_hertz, def.contact_damping_ratio, h);
    static_soft_ = make_softness(2.0 * contact_hertz, 0.5 * def.contact_damping_ratio, h);
    rod_soft_ = make_softness(std::min(def.rod_hertz, 0.25 / h), def.rod_damping_ratio, h);
    slop_ = def.penetration_slop;
    max_push_ = def.contact_push_max_speed;

    const std::size_t points = ctx.contact_points;
    const bool friction = ctx.layout.friction;  // the rows carry each pair's mu
    const bool coupled = def.friction_model == FrictionModel::coupled;
    // Box3D's friction centre weight: 1 for touching points, falling to 0 past twice the
    // speculative distance (m).
    const double inv_tau = 1.0 / std::max(def.contact_margin, 1e-9);
    // The points' friction tangents as World::build_rows gave them to the friction rows, so that
    // the warm start and write_lambda() need not read the rows back (tangents()).
    cached_tangents_ =
        friction && def.warm_start > 0.0 && ctx.warm_start != nullptr ? ctx.warm_start->tangents(0) : nullptr;
    const std::vector<DistanceConstraint>& distances = *ctx.distances;
    colour(ctx.manifolds, distances, moving);
    // Each manifold's first contact row (its points' rows follow in order): its first point.
    detail::reserve_with_headroom(first_row_, ctx.first_points.size());
    first_row_.assign(ctx.first_points.begin(), ctx.first_points.end());
    // The manifolds and their points stored colour by colour (manifold_order_), so that a
    // colour's sweep reads them in order; written here in ctx's order, which reads ctx's
    // manifolds, rows and warm start in order: manifold k goes to slot slot_[k], its points from
    // point_start_[slot_[k]].
    const std::size_t count = ctx.manifolds.size();
    detail::resize_with_headroom(slot_, count);
    for (std::size_t j = 0; j < count; ++j) slot_[manifold_order_[j]] = j;
    detail::assign_with_headroom(point_start_, count + 1, std::size_t{0});
    for (std::size_t k = 0; k < count; ++k) {
      point_start_[slot_[k] + 1] = static_cast<std::size_t>(ctx.manifolds[k].count);
    }
    for (std::size_t j = 0; j < count; ++j) point_start_[j + 1] += point_start_[j];
    detail::resize_with_headroom(contacts_, points);
    detail::resize_with_headroom(manifolds_, count);
    // The points' restitution targets (m/s, by row), kept where some pair may bounce.
    const bool may_bounce = ctx.may_bounce;
    if (may_bounce) {
      detail::resize_with_headroom(restitution_targets_, points);
    } else {
      restitution_targets_.clear();
    }
    const ManifoldInput in{def,
                           bodies,
                           ctx.manifolds,
                           ctx.layout,
                           warm,
                           last,
                           def.warm_start,
                           ctx.warm_start.get(),
                           may_bounce ? restitution_targets_.data() : nullptr,
                           h,
                           friction,
                           coupled,
                           inv_tau};
    lanes_ = def.soft_relax == SoftRelax::continue_solve;
    if (lanes_) layout_lanes();
    // With lanes, a colour's manifold goes straight into its group's lane (lane_of()) and only
    // the overflow's into its slot. Each manifold writes only its own slot, points and lane:
    // shared among the threads.
    std::atomic<bool> any_target{false};
    parallel_blocks(workers_, count, kMinParallel, [&](std::size_t begin, std::size_t end) {
      bool restitution = false;
      ManifoldFriction f;
      std::array<ContactPoint, kMaxManifoldPoints> scratch;
      for (std::size_t k = begin; k < end; ++k) {
        if (k + 2 * kManifoldsAhead < end) prefetch_manifold(ctx.manifolds[k + 2 * kManifoldsAhead]);
        if (k + kManifoldsAhead < end) prefetch_bodies_and_lanes(in, k + kManifoldsAhead);
        const std::size_t j = slot_[k];
        if (lanes_ && manifold_colour_[k] != ConstraintGraph::kOverflow) {
          restitution = prepare_manifold(in, k, 0, f, scratch.data()) || restitution;
          const auto [g, l] = lane_of(k);
          put_lane(g, l, j, f, scratch.data());
        } else {
          restitution = prepare_manifold(in, k, point_start_[j], manifolds_[j], contacts_.data() + point_start_[j]) ||
                        restitution;
        }
      }
      if (restitution) any_target.store(true, std::memory_order_relaxed);
    });
    restitution_ = any_target.load(std::memory_order_relaxed);
    if (lanes_) {
      // The step's total normal impulses matter only to the restitution (apply_restitution()).
      const bool restitution = any_restitution();
      if (restitution) {
        detail::assign_with_headroom(lane_totals_, lane_points_.size(), soft::LaneTotal{});
      } else {
        lane_totals_.clear();
      }
      sweep_.bodies = solver_bodies_.data();
      sweep_.stand_in = &lane_stand_in_;
      sweep_.points = lane_points_.data();
      sweep_.prefetch = lane_points_.size() * sizeof(soft::LanePoint) >= detail::kPrefetchFrom;
      sweep_.totals = restitution ? lane_totals_.data() : nullptr;
      sweep_.friction = friction;
      sweep_.inv_h = 1.0 / h;
      sweep_.contact = contact_soft_;
      sweep_.stiff = static_soft_;
      sweep_.slop = slop_;
      sweep_.max_push = max_push_;
    }

    const std::size_t first_rod = ctx.layout.first_rod();
    rods_.clear();
    detail::reserve_with_headroom(rods_, distances.size());
    for (const std::size_t r : rod_order_) {
      const DistanceConstraint& d = distances[r];
      Vec3 p_a;
      Vec3 p_b;
      distance_endpoints(d, bodies, p_a, p_b);
      Rod& rod = rods_.emplace_back();
      rod.a = moving(d.body_a);
      rod.b = moving(d.body_b);
      rod.row = static_cast<int>(first_rod + r);
      const Vec3 x_a = bodies[static_cast<std::size_t>(d.body_a)].x;
      const Vec3 x_b = d.body_b == kWorldBody ? Vec3::Zero() : bodies[static_cast<std::size_t>(d.body_b)].x;
      rod.r_a = p_a - x_a;
      rod.r_b = p_b - x_b;
      rod.delta_center = x_b - x_a;
      rod.length = d.length;
      rod.axis0 = rows[first_rod + r].j.segment<3>(6);  // the row's axis (+y for coincident ends)
      AxisRow axial;
      set_axis_row(axial, rod.axis0, rod.r_a, rod.r_b, solver_bodies_[index(d.body_a)],
                   solver_bodies_[index(d.body_b)], 0.0);
      rod.mass = axial.mass;
      rod.impulse = last != nullptr ? def.warm_start * last->last_rod(r) * h : guess(first_rod + r);
    }
    if (def.soft_relax == SoftRelax::restart) {  // save()'s buffers
      detail::resize_with_headroom(saved_velocities_, solver_bodies_.size());
      detail::resize_with_headroom(saved_impulses_, contacts_.size() + rods_.size());
    }
  }

  // What prepare_manifold() reads: the step's world, bodies and manifolds, the warm start, where
  // the points' restitution targets go, the substep h (s), whether the manifolds have friction
  // rows and the coupled friction model, and 1 / the contact margin (1/m).
  struct ManifoldInput {
    const WorldDef& def;
    const std::vector<Body>& bodies;
    const std::vector<Manifold>& manifolds;
    const RowLayout& layout;
    const std::vector<double>* warm;  // the rows' initial lambdas (N), or null
    const WarmStartCache* last;       // or Box3D's warm start from the cache itself, or null
    double factor;                    // its factor (WorldDef::warm_start)
    const WarmStartCache* cache;
    double* restitution_targets;  // m/s by contact row, or null where no pair may bounce
    double h;
    bool friction;
    bool coupled;
    double inv_tau;
  };

  // The prepare stage's prefetching, kManifoldsAhead manifolds ahead: the lines of a manifold
  // that prepare_manifold() reads (through its first four points; twice as far ahead, so that
  // its bodies can be found; the store stage asks for them too), then its bodies' (Body and
  // SolverBody) and its lane's group and points, which put_lane() writes. The stage goes through
  // the manifolds in ctx's order and the lanes lie in colour order, so each manifold's lanes are
  // elsewhere; without this the stores to them held up the next manifold (docs/benchmarks.md).
  // Always inlined: as calls, GCC took them for functions without effects and dropped them.
  [[gnu::always_inline]] static void prefetch_manifold(const Manifold& m) {
    const auto* start = reinterpret_cast<const char*>(&m);
    const auto* past = reinterpret_cast<const char*>(m.contacts.data() + 4);
    detail::prefetch_lines<false>(start, static_cast<std::size_t>(past - start));
    __builtin_prefetch(&m.anchor_shift, 0, 3);
  }
  [[gnu::always_inline]] void prefetch_bodies_and_lanes(const ManifoldInput& in, std::size_t k) const {
    const Manifold& m = in.manifolds[k];
    for (const int i : {m.body_a, m.body_b}) {
      const Body& body = in.bodies[static_cast<std::size_t>(i)];
      __builtin_prefetch(&body.x, 0, 3);
      __builtin_prefetch(&body.inv_mass, 0, 3);
      __builtin_prefetch(&body.friction, 0, 3);
      const SolverBody& sb = solver_bodies_[static_cast<std::size_t>(i)];
      __builtin_prefetch(&sb.inv_I, 0, 3);
      __builtin_prefetch(&sb.inv_mass, 0, 3);
    }
    if (!lanes_ || manifold_colour_[k] == ConstraintGraph::kOverflow) return;
    const LaneGroup& group = groups_[lane_of(k).first];
    detail::prefetch_lines<true>(&group, sizeof(LaneGroup));
    detail::prefetch_lines<true>(lane_points_.data() + group.first_point,
                                   static_cast<std::size_t>(group.points) * sizeof(LanePoint));
  }

  // The store stage's prefetching: the lines of manifold k's lane that store_warm_start() reads
  // (its group's t1, t2, impulses and count, and its points' impulses).
  [[gnu::always_inline]] void prefetch_stored_lanes(const std::vector<Manifold>& manifolds, std::size_t k) const {
    if (!lanes_ || manifold_colour_[k] == ConstraintGraph::kOverflow) return;
    const LaneGroup& group = groups_[lane_of(k).first];
    detail::prefetch_lines<false>(&group.t1, 2 * sizeof(soft::LaneVec3));
    detail::prefetch_lines<false>(&group.impulse1, 4 * sizeof(soft::Lanes));
    __builtin_prefetch(&group.count, 0, 3);
    const LanePoint* q = lane_points_.data() + group.first_point;
    for (int i = 0; i < manifolds[k].count; ++i) __builtin_prefetch(&q[i].impulse, 0, 3);
  }

  // Whether a contact of the step has a restitution target (set by prepare).
  bool any_restitution() const {
    return restitution_;
  }

  // A static body and the world are -1 in the sweeps (body()).
  static int moving_index(const std::vector<Body>& bodies, int body) {
    return body == kWorldBody || bodies[static_cast<std::size_t>(body)].is_static() ? -1 : body;
  }

  // Manifold k of ctx prepared into f and its points [points, points + count): anchors, normal
  // rows with their warm-start impulses, the friction at the centre; f's points are numbered
  // from `first` (its slot's point_start_, 0 for a lane's). True when a point has a restitution
  // target.
  bool prepare_manifold(const ManifoldInput& in, std::size_t k, std::size_t first, ManifoldFriction& f,
                        ContactPoint* points) const {
    const Manifold& m = in.manifolds[k];
    const double h = in.h;
    const auto guess = [&](std::size_t r) {
      if (in.last != nullptr) return in.factor * in.last->last_normal(r) * h;
      return in.warm != nullptr ? (*in.warm)[r] * h : 0.0;
    };
    std::size_t g = first_row_[k];  // the point's index over the step: its contact row
    const Body& body_a = in.bodies[static_cast<std::size_t>(m.body_a)];
    const Body& body_b = in.bodies[static_cast<std::size_t>(m.body_b)];
    const SolverBody& a = solver_bodies_[static_cast<std::size_t>(m.body_a)];
    const SolverBody& b = solver_bodies_[static_cast<std::size_t>(m.body_b)];
    f = ManifoldFriction{};
    f.a = moving_index(in.bodies, m.body_a);
    f.b = moving_index(in.bodies, m.body_b);
    f.begin = first;
    f.normal = m.contacts[0].normal;
    Vec3 center_a = Vec3::Zero();
    Vec3 center_b = Vec3::Zero();
    double total_weight = 0.0;
    // The restitution targets as write_normal_rows gives them to the contact rows (Eq. 8.2.1).
    const double eps = pair_restitution(in.def.restitution, body_a.restitution, body_b.restitution);
    const bool bouncy = eps > 0.0;
    const BodyVelocity vel_a = bouncy ? body_velocity(body_a) : BodyVelocity{};
    const BodyVelocity vel_b = bouncy ? body_velocity(body_b) : BodyVelocity{};
    bool restitution = false;
    const auto count = static_cast<std::size_t>(m.count);
    for (std::size_t i = 0; i < count; ++i, ++g) {
      const Contact& c = m.contacts[i];
      ContactPoint& p = points[i];
      p = ContactPoint{};
      p.a = f.a;
      p.b = f.b;
      p.row = static_cast<int>(g);
      p.r_a = c.point - body_a.x;
      p.r_b = point_on_b(m, c) - body_b.x;
      p.base_separation = -c.depth - c.normal.dot(p.r_b - p.r_a);
      if (bouncy) {
        p.restitution = restitution_target(axis_row(c.normal, p.r_a, p.r_b), c, vel_a, vel_b, eps,
                                           in.def.restitution_threshold, in.def.dt)
                            .value_or(0.0);
      }
      if (in.restitution_targets != nullptr) in.restitution_targets[g] = p.restitution;
      restitution = restitution || p.restitution > 0.0;
      p.touches_static = body_a.is_static() || body_b.is_static();
      set_axis_row(p.normal, c.normal, p.r_a, p.r_b, a, b, guess(g));
      const double weight = std::clamp(2.0 + c.depth * in.inv_tau, 1e-10, 1.0);
      center_a += weight * p.r_a;
      center_b += weight * p.r_b;
      total_weight += weight;
    }
    f.end = f.begin + count;
    if (!in.friction) return restitution;
    const std::size_t first_friction = in.layout.friction_row(first_row_[k]);
    f.center_a = center_a / total_weight;
    f.center_b = center_b / total_weight;
    for (std::size_t i = 0; i < count; ++i) points[i].lever_arm = (points[i].r_a - f.center_a).norm();
    f.first_friction_row = static_cast<int>(first_friction);
    f.mu = pair_friction(in.def.friction, body_a.friction, body_b.friction);  // the rows' mu
    // The fixed model's limit: its first point's friction rows' (write_friction_rows).
    f.fixed_limit = in.coupled ? -1.0 : friction_limit(f.mu, body_a, body_b, m.count, in.def.gravity, f.normal) * h;
    tangent_basis(f.normal, f.t1, f.t2);
    const Vec3 rt_a1 = f.center_a.cross(f.t1);
    const Vec3 rt_a2 = f.center_a.cross(f.t2);
    const Vec3 rt_b1 = f.center_b.cross(f.t1);
    const Vec3 rt_b2 = f.center_b.cross(f.t2);
    Eigen::Matrix2d K;
    K(0, 0) = a.inv_mass + b.inv_mass + rt_a1.dot(a.inv_I * rt_a1) + rt_b1.dot(b.inv_I * rt_b1);
    K(1, 1) = a.inv_mass + b.inv_mass + rt_a2.dot(a.inv_I * rt_a2) + rt_b2.dot(b.inv_I * rt_b2);
    K(0, 1) = K(1, 0) = rt_a1.dot(a.inv_I * rt_a2) + rt_b1.dot(b.inv_I * rt_b2);
    f.tangent_mass = K.determinant() != 0.0 ? Eigen::Matrix2d(K.inverse()) : Eigen::Matrix2d::Zero();
    const double k_twist = f.normal.dot((a.inv_I + b.inv_I) * f.normal);
    f.twist_mass = k_twist > 0.0 ? 1.0 / k_twist : 0.0;
    if (in.last != nullptr) {  // Box3D's: the pair's friction and twist of the last step
      Vec3 F;
      double twist = 0.0;
      in.last->last_friction(k, F, twist);
      f.impulse = (in.factor * h) * Eigen::Vector2d(F.dot(f.t1), F.dot(f.t2));
      f.twist_impulse = in.factor * h * twist;
      return restitution;
    }
    // The warm start by row (the restart variant): the friction rows' initial lambdas (N)
    // summed back into the force at the centre and its twist about the normal, as impulses over
    // h. write_lambda() writes each point's force as an equal share of the centre's plus the
    // twist's tangential force tau (n x d_i), so with the same points the twist is
    // sum n . (d_i x (F_i - share)). Only then: from other points, or some of them, that
    // moment is not the twist they carried, and warm starting it spun large_pyramid's bottom
    // boxes about their normals at up to 11 rad/s within 1 s.
    if (in.warm == nullptr) return restitution;
    const std::vector<double>& warm = *in.warm;
    Vec3 P = Vec3::Zero();
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t r = first_friction + 2 * i;
      Vec3 t1;
      Vec3 t2;
      tangents(points[i], t1, t2);
      P += h * (warm[r] * t1 + warm[r + 1] * t2);
    }
    f.impulse = Eigen::Vector2d(P.dot(f.t1), P.dot(f.t2));
    if (in.cache != nullptr && in.cache->same_points(k)) {
      const Vec3 share = P / static_cast<double>(m.count);
      double L = 0.0;
      for (std::size_t i = 0; i < count; ++i) {
        const std::size_t r = first_friction + 2 * i;
        Vec3 t1;
        Vec3 t2;
        tangents(points[i], t1, t2);
        const Vec3 F = h * (warm[r] * t1 + warm[r + 1] * t2);
        L += f.normal.dot((points[i].r_a - f.center_a).cross(F - share));
      }
      f.twist_impulse = L;
    }
    return restitution;
  }

  // The colours' manifolds (the overflow's excepted) in groups of soft::kLanes (soft_lanes.h):
  // colour c's groups are [group_start_[c], group_start_[c + 1]), group g's lanes the slots
  // groups_[g].slot, its points from groups_[g].first_point in lane_points_. A lane without a
  // manifold (in a colour's last group) is zero; put_lane() writes the others.
  void layout_lanes() {
    constexpr auto kLanes = static_cast<std::size_t>(soft::kLanes);
    std::size_t groups = 0;
    for (int c = 0; c <= ConstraintGraph::kOverflow; ++c) {
      const auto i = static_cast<std::size_t>(c);
      group_start_[i] = groups;
      if (c == ConstraintGraph::kOverflow) continue;  // swept one at a time
      groups += (manifold_start_[i + 1] - manifold_start_[i] + kLanes - 1) / kLanes;
    }
    group_start_[ConstraintGraph::kOverflow + 1] = groups;
    detail::resize_with_headroom(groups_, groups);
    std::size_t points = 0;
    for (int c = 0; c < ConstraintGraph::kOverflow; ++c) {
      const auto i = static_cast<std::size_t>(c);
      const std::size_t end = manifold_start_[i + 1];
      for (std::size_t g = group_start_[i], k = manifold_start_[i]; g < group_start_[i + 1]; ++g, k += kLanes) {
        LaneGroup& group = groups_[g];
        std::size_t most = 0;
        for (std::size_t l = 0; l < kLanes && k + l < end; ++l) {
          most = std::max(most, point_start_[k + l + 1] - point_start_[k + l]);
        }
        if (k + kLanes > end) group = LaneGroup{};  // lanes without a manifold
        group.first_point = points;
        group.points = static_cast<int>(most);
        points += most;
      }
    }
    detail::resize_with_headroom(lane_points_, points);
    for (int c = 0; c < ConstraintGraph::kOverflow; ++c) {  // the colours' last groups' empty lanes
      const auto i = static_cast<std::size_t>(c);
      const std::size_t used = (manifold_start_[i + 1] - manifold_start_[i]) % kLanes;
      if (used == 0) continue;
      const LaneGroup& group = groups_[group_start_[i + 1] - 1];
      for (int k = 0; k < group.points; ++k) {
        LanePoint& q = lane_points_[group.first_point + static_cast<std::size_t>(k)];
        for (auto l = static_cast<int>(used); l < soft::kLanes; ++l) zero_lane(q, l);
      }
    }
  }

  // The group and lane of manifold k of ctx, in a colour other than the overflow.
  std::pair<std::size_t, int> lane_of(std::size_t k) const {
    const auto c = static_cast<std::size_t>(manifold_colour_[k]);
    const std::size_t offset = slot_[k] - manifold_start_[c];
    return {group_start_[c] + offset / soft::kLanes, static_cast<int>(offset % soft::kLanes)};
  }

  // Element l of a lane vector, written through a double (so that threads writing other lanes
  // of the same vector write other objects).
  static double& at(soft::Lanes& lanes, int l) { return reinterpret_cast<double*>(&lanes)[l]; }

  static void put(soft::LaneVec3& lanes, int l, const Vec3& v) {
    at(lanes.x, l) = v.x();
    at(lanes.y, l) = v.y();
    at(lanes.z, l) = v.z();
  }

  static void zero_lane(LanePoint& q, int l) {
    put(q.r_a, l, Vec3::Zero());
    put(q.r_b, l, Vec3::Zero());
    at(q.base_separation, l) = 0.0;
    at(q.mass, l) = 0.0;
    at(q.impulse, l) = 0.0;
    at(q.lever_arm, l) = 0.0;
  }

  // Manifold f of slot j and its points (prepare_manifold()) into lane l of group g, its lane of
  // the group's points past its own zero.
  void put_lane(std::size_t g, int l, std::size_t j, const ManifoldFriction& f, const ContactPoint* points) {
    LaneGroup& group = groups_[g];
    const std::size_t count = f.end - f.begin;
    group.a[l] = f.a;
    group.b[l] = f.b;
    group.slot[l] = static_cast<int>(j);
    LanePoint* q = lane_points_.data() + group.first_point;
    for (std::size_t i = 0; i < count; ++i) {
      const ContactPoint& p = points[i];
      LanePoint& lp = q[i];
      put(lp.r_a, l, p.r_a);
      put(lp.r_b, l, p.r_b);
      at(lp.mass, l) = p.normal.mass;
      at(lp.impulse, l) = p.normal.impulse;
      at(lp.base_separation, l) = p.base_separation;
      at(lp.lever_arm, l) = p.lever_arm;
    }
    for (auto i = static_cast<int>(count); i < group.points; ++i) zero_lane(q[i], l);
    at(group.count, l) = static_cast<double>(count);
    at(group.touches_static, l) = count > 0 && points[0].touches_static ? 1.0 : 0.0;
    put(group.normal, l, f.normal);
    put(group.t1, l, f.t1);
    put(group.t2, l, f.t2);
    put(group.center_a, l, f.center_a);
    put(group.center_b, l, f.center_b);
    at(group.k00, l) = f.tangent_mass(0, 0);
    at(group.k01, l) = f.tangent_mass(0, 1);
    at(group.k10, l) = f.tangent_mass(1, 0);
    at(group.k11, l) = f.tangent_mass(1, 1);
    at(group.impulse1, l) = f.impulse.x();
    at(group.impulse2, l) = f.impulse.y();
    at(group.twist_mass, l) = f.twist_mass;
    at(group.twist_impulse, l) = f.twist_impulse;
    at(group.mu, l) = f.mu;
    at(group.fixed_limit, l) = f.fixed_limit;
  }

  // Lane l of group g, manifold k of ctx, as the scalar manifold and points the restitution and
  // write_lambda() read: f (its bodies, friction at the centre and impulses; its points numbered
  // from 0) and points [points, points + count) with their rows, anchors, normals, impulses and
  // the step's totals when kept (their I^-1 (r x n) and masses are not kept in lanes:
  // set_axis_row forms them), and their restitution targets where prepare() kept them.
  void lane_manifold(const RowLayout& layout, std::size_t k,
                     std::size_t g, int l, ManifoldFriction& f, ContactPoint* points) const {
    const LaneGroup& group = groups_[g];
    const LanePoint* q = lane_points_.data() + group.first_point;
    const soft::LaneTotal* totals = lane_totals_.empty() ? nullptr : lane_totals_.data() + group.first_point;
    f = ManifoldFriction{};
    f.a = group.a[l];
    f.b = group.b[l];
    f.end = static_cast<std::size_t>(group.count[l]);
    for (std::size_t i = 0; i < f.end; ++i) {
      ContactPoint& p = points[i];
      p = ContactPoint{};
      p.a = f.a;
      p.b = f.b;
      p.row = static_cast<int>(first_row_[k] + i);
      p.r_a = Vec3(q[i].r_a.x[l], q[i].r_a.y[l], q[i].r_a.z[l]);
      p.r_b = Vec3(q[i].r_b.x[l], q[i].r_b.y[l], q[i].r_b.z[l]);
      p.normal.axis = Vec3(group.normal.x[l], group.normal.y[l], group.normal.z[l]);
      p.normal.impulse = q[i].impulse[l];
      p.total_impulse = totals != nullptr ? totals[i].impulse[l] : 0.0;
      p.restitution = restitution_targets_.empty() ? 0.0 : restitution_targets_[static_cast<std::size_t>(p.row)];
    }
    if (!sweep_.friction) return;
    f.first_friction_row = static_cast<int>(layout.friction_row(first_row_[k]));
    f.normal = Vec3(group.normal.x[l], group.normal.y[l], group.normal.z[l]);
    f.t1 = Vec3(group.t1.x[l], group.t1.y[l], group.t1.z[l]);
    f.t2 = Vec3(group.t2.x[l], group.t2.y[l], group.t2.z[l]);
    f.center_a = Vec3(group.center_a.x[l], group.center_a.y[l], group.center_a.z[l]);
    f.center_b = Vec3(group.center_b.x[l], group.center_b.y[l], group.center_b.z[l]);
    f.impulse = Eigen::Vector2d(group.impulse1[l], group.impulse2[l]);
    f.twist_impulse = group.twist_impulse[l];
  }

  // Colours the rods, then the manifolds, in order (constraint_graph.h; `moving` maps a body
  // index to itself or to -1 for a static body and the world), and lists each colour's in
  // order.
  template <class Moving>
  void colour(const std::vector<Manifold>& manifolds, const std::vector<DistanceConstraint>& distances,
              Moving&& moving) {
    graph_.reset(bodies_, StaticColours::last);  // Box3D's
    rod_colour_.clear();
    for (const DistanceConstraint& d : distances) rod_colour_.push_back(graph_.add(moving(d.body_a), moving(d.body_b)));
    manifold_colour_.clear();
    for (const Manifold& m : manifolds) manifold_colour_.push_back(graph_.add(moving(m.body_a), moving(m.body_b)));
    order_by_colour(rod_colour_, rod_start_, rod_order_);
    order_by_colour(manifold_colour_, manifold_start_, manifold_order_);
  }

  // The substeps, as thread t of workers_ runs them (every thread runs this with its own t and
  // they meet at workers_->sync()): each sweeps its share of every colour's rods and manifolds
  // and of the bodies; thread 0 alone sweeps the overflow, runs the restart variant's save and
  // restore, and times the stages.
  void run_substeps(StepContext& ctx, double h, int t) {
    const WorldDef& def = *ctx.def;
    const bool restart = def.soft_relax == SoftRelax::restart;
    const bool main = t == 0;
    for (int k = 0; k < def.soft_substeps; ++k) {
      {
        StageTimer timer(ctx, &StageTimes::integrate, main);
        integrate_velocities(ctx.f_ext, h, t);
        workers_->sync();
      }
      {
        StageTimer timer(ctx, &StageTimes::solve, main);
        if (restart) {
          if (main) save();
          workers_->sync();
        }
        warm_start(t);
        for (int i = 0; i < def.iterations; ++i) solve(/*use_bias=*/true, h, t);
      }
      {
        StageTimer timer(ctx, &StageTimes::integrate, main);
        integrate_positions(*ctx.bodies, h, def.rotation, t);
        workers_->sync();
      }
      StageTimer timer(ctx, &StageTimes::relax, main);
      if (restart) {
        if (main) restore();
        workers_->sync();
        warm_start(t);
      }
      for (int i = 0; i < def.iterations; ++i) solve(/*use_bias=*/false, h, t);
    }
  }

  // Thread t's share [begin, end) of `count` items split evenly over the threads.
  std::pair<std::size_t, std::size_t> share(std::size_t count, int t) const {
    const auto threads = static_cast<std::size_t>(workers_->count());
    const auto k = static_cast<std::size_t>(t);
    return {count * k / threads, count * (k + 1) / threads};
  }

  // Calls rod_fn(rod, t) and manifold_fn(manifold, t) for the overflow's rods and manifolds
  // (thread 0, in order), then for thread t's share of each colour's, colour by colour, with a
  // barrier after each (Box3D's order: b3SolverStep); with lanes_, group_fn(groups, count) for
  // thread t's share of a colour's groups in place of its manifolds.
  template <class RodFn, class ManifoldFn, class GroupFn>
  void sweep_colours(int t, RodFn&& rod_fn, ManifoldFn&& manifold_fn, GroupFn&& group_fn) {
    for (int k = 0; k < ConstraintGraph::kColours; ++k) {
      const bool overflow = k == 0;
      const auto c = static_cast<std::size_t>(sweep_colour(k));
      const std::size_t rods = rod_start_[c + 1] - rod_start_[c];
      const std::size_t manifolds = manifold_start_[c + 1] - manifold_start_[c];
      if (rods + manifolds == 0) continue;  // every thread sees the same counts
      if (!overflow || t == 0) {
        const auto [rb, re] = overflow ? std::pair<std::size_t, std::size_t>{0, rods} : share(rods, t);
        for (std::size_t i = rb; i < re; ++i) rod_fn(rods_[rod_start_[c] + i], t);
        if (lanes_ && !overflow) {  // the colour's manifolds in groups of lanes
          const auto [gb, ge] = share(group_start_[c + 1] - group_start_[c], t);
          if (ge > gb) group_fn(groups_.data() + group_start_[c] + gb, ge - gb);
          workers_->sync();
          continue;
        }
        const auto [mb, me] =
            overflow ? std::pair<std::size_t, std::size_t>{0, manifolds} : share(manifolds, t);
        for (std::size_t i = mb; i < me; ++i) {
          manifold_fn(manifolds_[manifold_start_[c] + i], t);
        }
      }
      workers_->sync();
    }
  }

  // SoftRelax::restart: keeps the velocities before the warm start and the impulses the relax
  // left (the soft solve changes the normal and rod impulses only), and puts them back.
  // Writes only into buffers prepare() sized: it runs inside the threads' task, which must not
  // throw.
  void save() {
    for (std::size_t i = 0; i < solver_bodies_.size(); ++i) {
      saved_velocities_[i] = {solver_bodies_[i].v, solver_bodies_[i].w};
    }
    std::size_t k = 0;
    for (const ContactPoint& p : contacts_) saved_impulses_[k++] = p.normal.impulse;
    for (const Rod& rod : rods_) saved_impulses_[k++] = rod.impulse;
  }
  void restore() {
    for (std::size_t i = 0; i < solver_bodies_.size(); ++i) {
      solver_bodies_[i].v = saved_velocities_[i].first;
      solver_bodies_[i].w = saved_velocities_[i].second;
    }
    std::size_t k = 0;
    for (ContactPoint& p : contacts_) p.normal.impulse = saved_impulses_[k++];
    for (Rod& rod : rods_) rod.impulse = saved_impulses_[k++];
  }

  // Stage "integrate velocities": f_ext (6n: force and torque per body, N and N m) over h, for
  // thread t's share of the bodies.
  void integrate_velocities(const Eigen::VectorXd& f_ext, double h, int t) {
    const auto [begin, end] = share(bodies_, t);
    for (std::size_t i = begin; i < end; ++i) {
      SolverBody& s = solver_bodies_[i];
      if (s.inv_mass == 0.0) continue;
      const auto k = 6 * static_cast<Eigen::Index>(i);
      s.v += (h * s.inv_mass) * f_ext.segment<3>(k);
      s.w += h * (s.inv_I * f_ext.segment<3>(k + 3));
    }
  }

  // The solver body of index i (>= 0), or for -1 (a static body, the world) thread t's stand-in:
  // static bodies are never written, and each thread writes the zero updates of its own.
  SolverBody& body(int i, int t) {
    return solver_bodies_[i >= 0 ? static_cast<std::size_t>(i) : bodies_ + static_cast<std::size_t>(t)];
  }

  // A rod's current anchors (m) and the vector from its a end to its b end (m).
  static void rod_geometry(const Rod& rod, const SolverBody& a, const SolverBody& b, Vec3& r_a,
                           Vec3& r_b, Vec3& separation) {
    r_a = a.dR * rod.r_a;
    r_b = b.dR * rod.r_b;
    separation = rod.delta_center + (b.dp - a.dp) + (r_b - r_a);
  }

  static Vec3 axis_of(const Vec3& separation, const Vec3& fallback) {
    const double length = separation.norm();
    return length > 0.0 ? Vec3(separation / length) : fallback;
  }

  // Applies impulse P (N s) along `axis` at the current anchors of a rod.
  static void apply_rod(const Vec3& r_a, const Vec3& r_b, const Vec3& axis, double P, SolverBody& a,
                        SolverBody& b) {
    const Vec3 impulse = P * axis;
    a.v -= a.inv_mass * impulse;
    a.w -= a.inv_I * r_a.cross(impulse);
    b.v += b.inv_mass * impulse;
    b.w += b.inv_I * r_b.cross(impulse);
  }

  // Stage "warm start": every accumulated impulse applied to the velocities (thread t's share).
  void warm_start(int t) {
    sweep_colours(
        t,
        [this](const Rod& rod, int tt) {
          SolverBody& a = body(rod.a, tt);
          SolverBody& b = body(rod.b, tt);
          Vec3 r_a;
          Vec3 r_b;
          Vec3 separation;
          rod_geometry(rod, a, b, r_a, r_b, separation);
          apply_rod(r_a, r_b, axis_of(separation, rod.axis0), rod.impulse, a, b);
        },
        [this](const ManifoldFriction& f, int tt) {
          SolverBody& a = body(f.a, tt);
          SolverBody& b = body(f.b, tt);
          for (std::size_t i = f.begin; i < f.end; ++i) apply(contacts_[i].normal, contacts_[i].normal.impulse, a, b);
          if (f.first_friction_row < 0) return;
          apply_friction(f, f.impulse.x() * f.t1 + f.impulse.y() * f.t2, a, b);
          apply_twist(f, f.twist_impulse, a, b);
        },
        [this](const LaneGroup* groups, std::size_t count) { soft::warm_start_lanes(groups, count, sweep_); });
  }

  // Applies a friction impulse P (N s, world frame) at the manifold's centre: -P to a, +P to b.
  static void apply_friction(const ManifoldFriction& f, const Vec3& P, SolverBody& a, SolverBody& b) {
    a.v -= a.inv_mass * P;
    a.w -= a.inv_I * f.center_a.cross(P);
    b.v += b.inv_mass * P;
    b.w += b.inv_I * f.center_b.cross(P);
  }

  // Applies a twist impulse L (N m s) about the normal: -L to a, +L to b.
  static void apply_twist(const ManifoldFriction& f, double L, SolverBody& a, SolverBody& b) {
    const Vec3 torque = L * f.normal;
    a.w -= a.inv_I * torque;
    b.w += b.inv_I * torque;
  }

  // One sweep of the stages "solve" (use_bias) or "relax", thread t's share: per colour its rods,
  // then its manifolds' points (normal rows, then, in the relax, their friction).
  void solve(bool use_bias, double h, int t) {
    const double inv_h = 1.0 / h;
    sweep_colours(
        t, [this, use_bias](Rod& rod, int tt) { solve_rod(rod, use_bias, body(rod.a, tt), body(rod.b, tt)); },
        [this, use_bias, inv_h](ManifoldFriction& f, int tt) {
          SolverBody& a = body(f.a, tt);
          SolverBody& b = body(f.b, tt);
          double total = 0.0;        // N s: the manifold's normal impulse
          double twist_limit = 0.0;  // N m s: sum of lever arm x normal impulse
          for (std::size_t i = f.begin; i < f.end; ++i) {
            ContactPoint& p = contacts_[i];
            solve_normal(p, a, b, use_bias, inv_h);
            total += p.normal.impulse;
            twist_limit += p.lever_arm * p.normal.impulse;
          }
          if (!use_bias && f.first_friction_row >= 0) solve_friction(f, total, twist_limit, a, b);
        },
        [this, use_bias](LaneGroup* groups, std::size_t count) { soft::solve_lanes(groups, count, sweep_, use_bias); });
  }

  void solve_rod(Rod& rod, bool use_bias, SolverBody& a, SolverBody& b) const {
    Vec3 r_a;
    Vec3 r_b;
    Vec3 separation;
    rod_geometry(rod, a, b, r_a, r_b, separation);
    const Vec3 axis = axis_of(separation, rod.axis0);
    const double speed = axis.dot(point_velocity(b, r_b) - point_velocity(a, r_a));
    double bias = 0.0;
    double mass_scale = 1.0;
    double impulse_scale = 0.0;
    if (use_bias) {
      bias = rod_soft_.bias_rate * (separation.norm() - rod.length);
      mass_scale = rod_soft_.mass_scale;
      impulse_scale = rod_soft_.impulse_scale;
    }
    const double dP = -mass_scale * rod.mass * (speed + bias) - impulse_scale * rod.impulse;
    rod.impulse += dP;
    apply_rod(r_a, r_b, axis, dP, a, b);
  }

  void solve_normal(ContactPoint& p, SolverBody& a, SolverBody& b, bool use_bias, double inv_h) const {
    const AxisRow& row = p.normal;
    const Vec3 ds = (b.dp - a.dp) + (b.dR * p.r_b - a.dR * p.r_a);
    const double s = row.axis.dot(ds) + p.base_separation;
    double bias = 0.0;
    double mass_scale = 1.0;
    double impulse_scale = 0.0;
    if (s > 0.0) {
      bias = s * inv_h;  // speculative
    } else if (use_bias) {
      const Softness& k = p.touches_static ? static_soft_ : contact_soft_;
      bias = std::max(k.mass_scale * k.bias_rate * std::min(s + slop_, 0.0), -max_push_);
      mass_scale = k.mass_scale;
      impulse_scale = k.impulse_scale;
    }
    const double speed = row_speed(row, p.r_a, p.r_b, a, b);
    const double old = row.impulse;
    const double next = std::max(old - row.mass * (mass_scale * speed + bias) - impulse_scale * old, 0.0);
    p.normal.impulse = next;
    p.total_impulse += next;
    apply(row, next - old, a, b);
  }

  // The relax's friction of a manifold (b3SolveContacts, useBias false): the twist row, then the
  // two tangent rows at the centre, clamped to mu times the manifold's normal impulse `total`
  // (N s; coupled) or to the fixed limits, twist_limit (N m s) the lever arms' share.
  static void solve_friction(ManifoldFriction& f, double total, double twist_limit, SolverBody& a,
                             SolverBody& b) {
    const double points = static_cast<double>(f.end - f.begin);
    double limit = f.mu * total;
    double twist_max = f.mu * twist_limit;
    if (f.fixed_limit >= 0.0) {  // the fixed model: mu m |g.n| / points per point (Sec. 5.4)
      limit = f.fixed_limit * points;
      twist_max = total > 0.0 ? limit * twist_limit / total : 0.0;
    }
    {
      const double speed = f.normal.dot(b.w - a.w);
      const double old = f.twist_impulse;
      f.twist_impulse = std::clamp(old - f.twist_mass * speed, -twist_max, twist_max);
      apply_twist(f, f.twist_impulse - old, a, b);
    }
    const Vec3 vr = (b.v + b.w.cross(f.center_b)) - (a.v + a.w.cross(f.center_a));
    const Eigen::Vector2d vt(vr.dot(f.t1), vr.dot(f.t2));
    Eigen::Vector2d next = f.impulse - f.tangent_mass * vt;
    const double length2 = next.squaredNorm();
    if (length2 > limit * limit) next *= limit / std::sqrt(length2);
    const Eigen::Vector2d d = next - f.impulse;
    f.impulse = next;
    apply_friction(f, d.x() * f.t1 + d.y() * f.t2, a, b);
  }

  // Stage "integrate positions": bodies and the solver's displacements over h, for thread t's
  // share of the bodies.
  void integrate_positions(std::vector<Body>& bodies, double h, RotationUpdate rotation, int t) {
    const auto [begin, end] = share(bodies_, t);
    for (std::size_t i = begin; i < end; ++i) {
      SolverBody& s = solver_bodies_[i];
      if (s.inv_mass == 0.0) continue;
      Body& body = bodies[i];
      const Vec3 dx = h * s.v;
      body.x += dx;
      s.dp += dx;
      body.o = rotated(body.o, s.w, h, rotation);
      s.dq = rotated(s.dq, s.w, h, rotation);
      s.dR = s.dq.toRotationMatrix();
    }
  }

  // Stage "restitution" (Eq. 8.2.1 as b3ApplyRestitution applies it), point by point in the
  // order of the slots: the lanes' manifolds by group and lane, then the overflow's.
  void apply_restitution(const RowLayout& layout) {
    if (!any_restitution()) return;
    const auto bounce = [this](ContactPoint& p) {
      if (p.restitution <= 0.0 || p.total_impulse == 0.0) return;
      SolverBody& a = body(p.a, 0);
      SolverBody& b = body(p.b, 0);
      const double old = p.normal.impulse;
      const double next = std::max(old - p.normal.mass * (row_speed(p.normal, p.r_a, p.r_b, a, b) - p.restitution), 0.0);
      p.normal.impulse = next;
      p.total_impulse += next - old;
      apply(p.normal, next - old, a, b);
    };
    const std::size_t groups = lanes_ ? group_start_[ConstraintGraph::kOverflow + 1] : 0;
    ManifoldFriction f;
    std::array<ContactPoint, kMaxManifoldPoints> points;
    for (std::size_t g = 0; g < groups; ++g) {
      LanePoint* q = lane_points_.data() + groups_[g].first_point;
      soft::LaneTotal* totals = lane_totals_.data() + groups_[g].first_point;
      for (int l = 0; l < soft::kLanes && groups_[g].slot[l] >= 0; ++l) {
        const std::size_t k = manifold_order_[static_cast<std::size_t>(groups_[g].slot[l])];
        lane_manifold(layout, k, g, l, f, points.data());
        for (std::size_t i = 0; i < f.end; ++i) {
          ContactPoint& p = points[i];
          set_axis_row(p.normal, p.normal.axis, p.r_a, p.r_b, body(p.a, 0), body(p.b, 0), p.normal.impulse);
          bounce(p);
          q[i].impulse[l] = points[i].normal.impulse;
          totals[i].impulse[l] = points[i].total_impulse;
        }
      }
    }
    const std::size_t first = lanes_ ? point_start_[manifold_start_[ConstraintGraph::kOverflow]] : 0;
    for (std::size_t i = first; i < contacts_.size(); ++i) bounce(contacts_[i]);
  }

  // A point's friction tangents t1, t2 (unit) as write_friction_rows gave them to its friction
  // rows: t1 the warm-start cache's when warm starting (cached_tangents_), else tangent_basis's;
  // t2 = n x t1.
  void tangents(const ContactPoint& p, Vec3& t1, Vec3& t2) const {
    const Vec3& n = p.normal.axis;
    if (cached_tangents_ != nullptr) {
      t1 = cached_tangents_[static_cast<std::size_t>(p.row)];
      t2 = n.cross(t1);
    } else {
      tangent_basis(n, t1, t2);
    }
  }

  // Stage "store impulses": the bodies' momenta.
  void store_momenta(StepContext& ctx) {
    std::vector<Body>& bodies = *ctx.bodies;
    parallel_blocks(workers_, bodies.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        Body& body = bodies[i];
        if (body.is_static()) continue;
        const SolverBody& s = solver_bodies_[i];
        body.p = body.mass * s.v;
        body.l = inertia_[i] * s.w;
      }
    });
  }

  // Stage "store impulses", Box3D's warm start (b3StoreImpulses): each manifold's points' normal
  // impulses, its friction impulse as a vector and its twist, over the substep (inv_h = 1 / h,
  // 1/s), into the cache; and the rods'.
  void store_warm_start(StepContext& ctx, double inv_h) {
    WarmStartCache& cache = *ctx.warm_start;
    cache.begin_store(ctx.manifolds, &ctx.first_points);
    parallel_blocks(workers_, manifolds_.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
      std::array<double, kMaxManifoldPoints> normal{};
      for (std::size_t k = begin; k < end; ++k) {
        if (k + 2 * kManifoldsAhead < end) prefetch_manifold(ctx.manifolds[k + 2 * kManifoldsAhead]);
        if (k + kManifoldsAhead < end) prefetch_stored_lanes(ctx.manifolds, k + kManifoldsAhead);
        Vec3 friction = Vec3::Zero();
        double twist = 0.0;
        if (lanes_ && manifold_colour_[k] != ConstraintGraph::kOverflow) {
          const auto [g, l] = lane_of(k);
          const LaneGroup& group = groups_[g];
          const LanePoint* q = lane_points_.data() + group.first_point;
          const auto count = static_cast<std::size_t>(group.count[l]);
          for (std::size_t i = 0; i < count; ++i) normal[i] = q[i].impulse[l] * inv_h;
          if (sweep_.friction) {
            friction = (group.impulse1[l] * inv_h) * Vec3(group.t1.x[l], group.t1.y[l], group.t1.z[l]) +
                       (group.impulse2[l] * inv_h) * Vec3(group.t2.x[l], group.t2.y[l], group.t2.z[l]);
            twist = group.twist_impulse[l] * inv_h;
          }
        } else {
          const ManifoldFriction& f = manifolds_[slot_[k]];
          const ContactPoint* points = contacts_.data() + f.begin;
          for (std::size_t i = 0; i < f.end - f.begin; ++i) normal[i] = points[i].normal.impulse * inv_h;
          if (f.first_friction_row >= 0) {
            friction = (f.impulse.x() * inv_h) * f.t1 + (f.impulse.y() * inv_h) * f.t2;
            twist = f.twist_impulse * inv_h;
          }
        }
        cache.store_manifold(k, ctx.manifolds[k], normal.data(), friction, twist);
      }
    });
    detail::resize_with_headroom(rod_lambda_, rods_.size());
    const std::size_t first_rod = ctx.layout.first_rod();
    for (const Rod& rod : rods_) rod_lambda_[static_cast<std::size_t>(rod.row) - first_rod] = rod.impulse * inv_h;
    cache.end_store(rod_lambda_.data(), rod_lambda_.size());
  }

  // ctx.lambda (c, N): lambda = P / h per row (inv_h = 1 / h, 1/s), a manifold's friction as
  // forces at its points' friction rows (store_manifold()); shared among `workers` (or null).
  void write_lambda(StepContext& ctx, double inv_h, Workers* workers) const {
    // Every row is written below: the contact rows by their points, the friction rows (when the
    // world has friction, every manifold has them) by their manifolds, the rods' by the rods.
    detail::resize_with_headroom(ctx.lambda, ctx.rows.size());
    // In ctx's order, which writes the rows and reads the warm-start cache's tangents in order.
    parallel_blocks(workers, manifolds_.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
      ManifoldFriction f;
      std::array<ContactPoint, kMaxManifoldPoints> scratch;
      for (std::size_t k = begin; k < end; ++k) {
        if (lanes_ && manifold_colour_[k] != ConstraintGraph::kOverflow) {
          const auto [g, l] = lane_of(k);
          lane_manifold(ctx.layout, k, g, l, f, scratch.data());
          store_manifold(f, scratch.data(), inv_h, ctx.lambda);
        } else {
          const ManifoldFriction& m = manifolds_[slot_[k]];
          store_manifold(m, contacts_.data() + m.begin, inv_h, ctx.lambda);
        }
      }
    });
    for (const Rod& rod : rods_) ctx.lambda[static_cast<std::size_t>(rod.row)] = rod.impulse * inv_h;
  }

  // Manifold f's rows of `lambda` (N) from its points [points, points + count) and impulses over
  // a substep of 1 / inv_h (s). Its friction as forces at its points' friction rows: the force at
  // the centre shared equally, plus the twist as tangential forces F_i = tau (n x d_i) /
  // sum |d_j|^2 (d_i the point's offset from the centre across the normal), which sum to no
  // force and to the torque tau about the normal; each row's lambda the component along its
  // tangent. (A twist on a single point has no such forces and is dropped.)
  void store_manifold(const ManifoldFriction& f, const ContactPoint* points, double inv_h,
                      std::vector<double>& lambda) const {
    const std::size_t count = f.end - f.begin;
    for (std::size_t i = 0; i < count; ++i) {
      lambda[static_cast<std::size_t>(points[i].row)] = points[i].normal.impulse * inv_h;
    }
    if (f.first_friction_row < 0) return;
    const Vec3 share = (f.impulse.x() * f.t1 + f.impulse.y() * f.t2) * (inv_h / static_cast<double>(count));
    double spread = 0.0;  // m^2
    for (std::size_t i = 0; i < count; ++i) {
      const Vec3 d = points[i].r_a - f.center_a;
      spread += (d - f.normal.dot(d) * f.normal).squaredNorm();
    }
    const double tau = spread > 0.0 ? f.twist_impulse * inv_h / spread : 0.0;  // N / m
    for (std::size_t i = 0; i < count; ++i) {
      const Vec3 d = points[i].r_a - f.center_a;
      const Vec3 F = share + tau * f.normal.cross(d);
      const std::size_t r = static_cast<std::size_t>(f.first_friction_row) + 2 * i;
      Vec3 t1;
      Vec3 t2;
      tangents(points[i], t1, t2);
      lambda[r] = F.dot(t1);
      lambda[r + 1] = F.dot(t2);
    }
  }

  Workers* workers_ = nullptr;             // the step's threads (StepContext::workers) or one_thread_
  double inv_h_ = 0.0;                     // 1/s: 1 / the last step's substep, for write_lambda()
  std::vector<double> rod_lambda_;         // N: the rods' lambdas in the world's order (store_warm_start())
  Workers one_thread_{1};                  // the calling thread alone
  std::size_t bodies_ = 0;                 // n: the step's bodies
  std::vector<SolverBody> solver_bodies_;  // n + threads: the bodies, then each thread's static stand-in
  // The colours (constraint_graph.h): the step's rods and manifolds by colour (their indices in
  // ctx's distances and manifolds), the overflow last; colour c's are [start[c], start[c + 1])
  // of the order and of rods_ and manifolds_, which are stored in that order.
  ConstraintGraph graph_;
  std::vector<int> rod_colour_;
  std::vector<int> manifold_colour_;
  std::vector<std::size_t> rod_order_;
  std::vector<std::size_t> manifold_order_;
  ColourStarts rod_start_{};
  ColourStarts manifold_start_{};
  std::vector<std::size_t> first_row_;    // per manifold of ctx: its first contact row
  std::vector<double> restitution_targets_;  // m/s by contact row; empty where no pair may bounce
  std::vector<std::size_t> slot_;         // per manifold of ctx: its place in manifolds_
  std::vector<std::size_t> point_start_;  // per slot of manifolds_: its first point in contacts_
  std::vector<Mat3> inertia_;              // n: I (kg m^2, world frame) at the start of the step
  const Vec3* cached_tangents_ = nullptr;  // the warm-start cache's t1 per point of the step, or null
  std::vector<ContactPoint> contacts_;     // one per contact row, by manifold in colour order
  bool restitution_ = false;  // prepare(): whether some contact has a restitution target
  std::vector<ManifoldFriction> manifolds_;     // one per manifold, in colour order
  std::vector<Rod> rods_;                  // one per distance constraint, in colour order
  bool lanes_ = false;                     // the colours' manifolds are swept in lanes (soft_lanes.h)
  std::vector<LaneGroup> groups_;          // colour c's groups: [group_start_[c], group_start_[c + 1])
  std::vector<LanePoint> lane_points_;     // the groups' points
  std::vector<soft::LaneTotal> lane_totals_;  // per lane point: its total impulse (N s), when a contact has restitution
  ColourStarts group_start_{};
  soft::LaneSweep sweep_;                  // what the lanes' sweeps read
  SolverBody lane_stand_in_;               // the lanes' body for -1: zero, read only
  std::vector<std::pair<Vec3, Vec3>> saved_velocities_;  // n + threads: v, w (SoftRelax::restart)
  std::vector<double> saved_impulses_;                   // normal, then rod impulses (N s)
  Softness contact_soft_;
  Softness static_soft_;
  Softness rod_soft_;
  double slop_ = 0.0;      // m
  double max_push_ = 0.0;  // m/s
};

}  // namespace

std::unique_ptr<PushMethod> make_soft_step() { return std::make_unique<SoftStep>(); }

}  // namespace cps
