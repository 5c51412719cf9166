// Extended position based dynamics for rigid bodies: `--push xpbd`. Sources: M. Mueller, M.
// Macklin, N. Chentanez, S. Jeschke, T.-Y. Kim, "Detailed Rigid Body Simulation with Extended
// Position Based Dynamics" (SCA 2020; Algorithm 2 the step, Sec. 3.3 the positional correction,
// Sec. 3.5 the contacts with static friction and the collection of pairs, Sec. 3.6 the velocity
// pass with dynamic friction and restitution); M. Macklin, K. Storey, M. Lu, P. Terdiman, N.
// Chentanez, S. Jeschke, M. Mueller, "Small Steps in Physics Simulation" (SCA 2019): many
// substeps of one iteration each; M. Macklin, M. Mueller, N. Chentanez, T.-Y. Kim, "Unified
// Particle Physics for Real-Time Applications" (SIGGRAPH 2014), pre-stabilisation (Sec. 4.4: the
// errors present at the start of a step corrected on positions alone, so they add no velocity)
// and the Jacobi averaging (Sec. 4.2).
//
// XPBD does not solve A lambda = b: it moves positions. One step of length dt is N =
// xpbd_substeps substeps of h = dt / N; each, with x, o the bodies' positions and orientations
// and v, w their velocities (m^-1 p, I^-1 l):
//   1. x_prev = x, o_prev = o; the momenta take f_ext h and the bodies move over h with them
//      (semi-implicit Euler, Eqs. 3.2.1-3.2.4: the paper's integration of Algorithm 2);
//   2. one Gauss-Seidel sweep over the contacts in the collide stage's order (a manifold's normal
//      corrections, then its points' static friction; or each point's static friction right
//      after its normal: the friction order below), then the rods (Sec. 3.3). A constraint C between
//      points at offsets r_a, r_b from the centres of mass, along the unit axis k (the gradient
//      of C at body b), with the generalised inverse masses
//        w_i = m_i^-1 + (r_i x k)^T I_i^-1 (r_i x k)   (1/kg; 0 for a static body or the world)
//      and the compliance alpha (m/N) as alpha~ = alpha / h^2, gets
//        Delta lambda = (-C - alpha~ lambda) / (w_a + w_b + alpha~)   (kg m; lambda = 0 at the
//      start of each substep: one iteration), applied as the positional impulse P = Delta lambda k:
//        x_b += m_b^-1 P, o_b turned by I_b^-1 (r_b x P); x_a -= m_a^-1 P, o_a by -I_a^-1 (r_a x P)
//      (the turn as Eq. 3.2.4's linear update, then normalised).
//        contact: its two witness points fixed in the bodies' frames (Contact::point is midway:
//          p_a = point + n d/2, p_b = point_on_b - n d/2, as ngs.cpp), n its normal of the start of
//          the step (a to b, kept in the world frame), C = n . (p_b - p_a) + allowed, acted on
//          when C < 0 (rigid: alpha = 0, as the paper's contacts), `allowed` the slop (or the
//          overlap the pre-stabilisation below left);
//        static friction: the tangential part Delta p_t of the points' relative motion since
//          the anchor below, (p_a - p_a,start) - (p_b - p_b,start) less its normal part, is
//          undone (C = |Delta p_t|) if the impulse it takes is below mu lambda_n (mu:
//          WorldDef::friction for both the static and the dynamic coefficient; lambda_n this
//          substep's normal one);
//        rod: u = (p_b - p_a) / |p_b - p_a|, C = |p_b - p_a| - l, alpha = xpbd_compliance;
//   3. v = (x - x_prev) / h; w = 2 vec(o o_prev^-1) / h (negated when its real part is < 0); the
//      momenta p = m v, l = I w with I of the new orientation;
//   4. the velocity pass (Sec. 3.6) over every contact that acted in 2 (lambda_n > 0), with v_n
//      = n . (u_b - u_a) the points' normal velocity (> 0: separating) and u_t their tangential
//      one: the normal velocity is set to max(-eps v~_n, 0), v~_n its pre-solve value (after
//      step 1; eps = WorldDef::restitution when -v~_n exceeds the restitution threshold, else
//      0; the paper uses 2 |g| h there), and dynamic friction applies the impulse -u_t / |u_t|
//      min(mu lambda_n / h, |u_t| / w_t) (N s; the paper's velocity change min(h mu |f_n|,
//      |u_t|), f_n = lambda_n / h^2, written as an impulse so that its units agree); each a
//      velocity impulse (N s) Delta v / (w_a + w_b) along its direction.
//   Friction order (WorldDef::xpbd_friction_order). manifold, E. Catto's reading of the paper
//   (Solver2D, solve_xpbd.c): a manifold's normal corrections first, then their friction, in 2
//   and in 4. point: in 2 each point's static friction right after its normal correction, in 4
//   both impulses of a point from the same velocities. Under point, the turn a point's friction
//   gives the body is taken back by the next points' normal corrections, which in 4 carry
//   support outside lambda_n: a cube sliding on the ground stops 11 % late, against 0.3 % under
//   manifold (docs/findings.md, "TGS and XPBD").
//   Friction anchor (WorldDef::xpbd_friction_anchor). step, Solver2D's reading: p_start is the
//   point's place at the start of the step (before the pre-stabilisation below), so each
//   substep's static friction also undoes the slip that earlier substeps' later corrections
//   left. substep: its place at the start of the substep, so that slip stays. With one sweep a
//   substep, the substep anchor lets the paper's stack walk off its column (docs/findings.md).
//
// Contacts. As the paper's Sec. 3.5, the contacts are collected once per step and followed
// through the substeps: their points stay fixed in the bodies' frames and each substep measures
// C from the current poses. The paper finds them among pairs whose bounds it grows by k dt |v|
// (k = 2); here the collide stage tests each pair with the speculative distance (m)
//   margin_a + margin_b,  margin = k dt (|v| + |w| rho + |g| dt)   (0 for a static body)
// (contact_margins; rho the body's farthest surface point from its centre, |g| dt the speed
// gravity adds in a step; plus WorldDef::contact_margin), so that a contact that closes within
// the step is there, as a speculative point (depth < 0), in the substep where it touches.
// Without it a point is found only once it overlaps: a box resting at depth 0 keeps only the
// corners that happen to overlap, rocks onto the others within the step, and every landing is
// found a step late, up to v dt deep (docs/findings.md, "TGS and XPBD").
//
// Pre-stabilisation. The paper's contacts push an overlap out in full within a substep, so an
// overlap present at the start of the step would become a velocity of depth / h (0.4 m at h =
// 1/1200 s: 480 m/s). Instead, once at the start of the step and on positions alone, every point
// deeper than max(slop, depth - max_depenetration_speed dt) (PhysX's depenetration cap) is moved
// out to that depth by N Gauss-Seidel sweeps, each followed by a sweep that holds the rods at
// their lengths of the start of the step; such a point keeps, through the substeps, the overlap
// it is then left with. The solver's own residual of the last step is pushed out at the same
// time, and new overlap made within the step is corrected in full, as the paper does. A body
// that the pre-stabilisation turns by Delta R keeps its angular momentum in its own frame (l :=
// Delta R l), so its rotational kinetic energy 1/2 l . I^-1 l, with I turned by Delta R too, is
// unchanged: at a fixed world l the turn alone changed it (up to 200 J a step in a pile of boxes
// started 1.5 m deep in each other).
//
// Solvers: PGS is the paper's Gauss-Seidel sweep, each correction applied at once. Jacobi
// computes every correction of a sweep (and of the velocity pass) from the same state and
// applies each body's sum divided by the number of constraints that moved it (Unified Particle
// Physics' constraint averaging). Not used: beta and the LCP solve's iterations (one sweep per
// substep), the friction model (the friction limit is always mu lambda_n, the source's),
// warm starting (lambda starts from 0 in every substep) and the assembly (no A is built). After
// a step, lambda holds each row's mean force over the step (N): a contact's, its friction's
// along the row's tangent, a rod's (positional impulses / h plus velocity impulses, over dt).

#include "push_method.h"

#include "../buffers.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace cps {
namespace {

// Mueller et al.'s safety multiplier k of the collection bounds (Sec. 3.5: they grow a body's
// bounds by k dt |v| "accounting for potential accelerations during the time step"; they use
// k = 2). Dimensionless.
constexpr double kMarginFactor = 2.0;

// Turns o by the small rotation vector theta (rad): o += 1/2 [0, theta] o, normalised.
void turn(Quat& o, const Vec3& theta) {
  const Quat spin(0.0, 0.5 * theta.x(), 0.5 * theta.y(), 0.5 * theta.z());
  o.coeffs() += (spin * o).coeffs();
  o.normalize();
}

class Xpbd final : public PushMethod {
 public:
  // The collection margin of each body (m): k dt (|v| + |w| rho + |g| dt), rho the distance from
  // its centre to its farthest surface point; 0 for a static body.
  bool contact_margins(const WorldDef& def, const std::vector<Body>& bodies,
                       std::vector<double>& margins) const override {
    margins.resize(bodies.size());
    const double gravity_speed = def.gravity.norm() * def.dt;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const Body& b = bodies[i];
      if (b.is_static()) {
        margins[i] = 0.0;
        continue;
      }
      const double rho =
          b.shape.kind == ShapeKind::box ? b.shape.half_extents.norm() : b.shape.radius;
      const double reach = b.velocity().norm() + b.angular_velocity().norm() * rho + gravity_speed;
      margins[i] = std::isfinite(reach) ? kMarginFactor * def.dt * reach : 0.0;
    }
    return true;
  }

  void step(StepContext& ctx) override {
    const WorldDef& def = *ctx.def;
    std::vector<Body>& bodies = *ctx.bodies;
    const int substeps = def.xpbd_substeps;
    const double h = def.dt / static_cast<double>(substeps);
    jacobi_ = def.solver == SolverKind::jacobi;
    ctx.lambda_second.clear();
    detail::assign_with_headroom(ctx.lambda, ctx.rows.size(), 0.0);
    capture(ctx.manifolds, bodies, def);
    detail::resize_with_headroom(state_, bodies.size());
    detail::resize_with_headroom(delta_, bodies.size());
    detail::resize_with_headroom(step_start_, bodies.size());
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      step_start_[i].x = bodies[i].x;
      step_start_[i].R = bodies[i].rotation();
    }
    prestabilise(bodies, *ctx.distances, def, substeps);
    for (int k = 0; k < substeps; ++k) {
      for (std::size_t i = 0; i < bodies.size(); ++i) {
        state_[i].x = bodies[i].x;
        state_[i].o = bodies[i].o;
        state_[i].R = bodies[i].rotation();
      }
      ctx.integrate(ctx.f_ext, ctx.f_ext, h);
      for (std::size_t i = 0; i < bodies.size(); ++i) {
        state_[i].v = bodies[i].velocity();
        state_[i].w = bodies[i].angular_velocity();
      }
      solve_positions(bodies, *ctx.distances, def, h);
      update_velocities(bodies, h);
      solve_velocities(bodies, def, h);
      accumulate_forces(ctx.rows, ctx.layout, ctx.lambda, h, def.dt);
    }
    ctx.store_warm_start();
  }

 private:
  struct Point {
    int body_a = 0;
    int body_b = 0;
    Vec3 local_a = Vec3::Zero();  // witness point on a, in a's frame (m)
    Vec3 local_b = Vec3::Zero();  // witness point on b, in b's frame (m)
    Vec3 normal = Vec3::UnitY();  // world direction from a to b
    double target = 0.0;   // m: the overlap the pre-stabilisation moves it out to
    double allowed = 0.0;  // m: the overlap the substeps leave it (slop, or more: above)
    // This substep's results: the normal positional impulse (kg m), the static friction one on b
    // (kg m), the velocity pass's impulse on b (N s).
    double lambda_n = 0.0;
    bool first = false;  // the first point of its manifold
    Vec3 friction = Vec3::Zero();
    Vec3 velocity_impulse = Vec3::Zero();
  };
  // A body at the start of the substep (x, o) and after the integration (v, w: the pre-solve
  // velocities of the velocity pass).
  struct Saved {
    Vec3 x = Vec3::Zero();
    Quat o = Quat::Identity();
    Mat3 R = Mat3::Identity();  // o's rotation matrix
    Vec3 v = Vec3::Zero();
    Vec3 w = Vec3::Zero();
  };
  // A body's pending changes in a Jacobi pass: position (m) and rotation (rad), or momenta (N s,
  // N m s) in the velocity pass, and how many constraints contributed.
  struct Delta {
    Vec3 linear = Vec3::Zero();
    Vec3 angular = Vec3::Zero();
    int count = 0;
  };

  // Records each contact point's witness points in its bodies' frames, its normal and its
  // pre-stabilisation target (speculative points, depth < 0, get the slop and act once they
  // touch).
  void capture(const std::vector<Manifold>& manifolds, const std::vector<Body>& bodies,
               const WorldDef& def) {
    points_.clear();
    detail::reserve_with_headroom(points_, contact_point_count(manifolds));
    const double cap = def.max_depenetration_speed * def.dt;
    for_each_contact_point(manifolds, bodies, [&](const Manifold& m, const Contact& c,
                                                  const Body& a, const Body& b,
                                                  const Mat3& Ra_t, const Mat3& Rb_t) {
      Point& p = points_.emplace_back();
      p.body_a = m.body_a;
      p.body_b = m.body_b;
      p.normal = c.normal;
      p.first = &c == m.contacts.data();
      p.local_a = Ra_t * (c.point + 0.5 * c.depth * c.normal - a.x);
      p.local_b = Rb_t * (point_on_b(m, c) - 0.5 * c.depth * c.normal - b.x);
      p.target = std::max(c.depth - cap, def.penetration_slop);
      p.allowed = def.penetration_slop;
    });
  }

  static Vec3 world_point(const Body& body, const Vec3& local) { return body.x + body.rotation() * local; }

  // The overlap of point p now (m; < 0: apart).
  static double overlap(const std::vector<Body>& bodies, const Point& p) {
    const Body& a = bodies[static_cast<std::size_t>(p.body_a)];
    const Body& b = bodies[static_cast<std::size_t>(p.body_b)];
    return -p.normal.dot(world_point(b, p.local_b) - world_point(a, p.local_a));
  }

  // Generalised inverse mass of `body` for a correction along unit k at offset r (1/kg).
  static double inverse_mass(const Body* body, const Vec3& r, const Vec3& k) {
    if (body == nullptr || body->is_static()) return 0.0;
    const Vec3 rk = r.cross(k);
    return body->inv_mass + rk.dot(body->inv_inertia_world() * rk);
  }

  // Applies the positional impulse P (kg m) at offset r to `body`, at once (Gauss-Seidel) or
  // into its Jacobi delta.
  void move(Body* body, std::size_t index, const Vec3& r, const Vec3& P) {
    if (body == nullptr || body->is_static()) return;
    const Vec3 dx = body->inv_mass * P;
    const Vec3 dtheta = body->inv_inertia_world() * r.cross(P);
    if (jacobi_) {
      delta_[index].linear += dx;
      delta_[index].angular += dtheta;
      ++delta_[index].count;
    } else {
      body->x += dx;
      turn(body->o, dtheta);
    }
  }

  // Applies the velocity impulse J (N s) at offset r to `body`.
  void push(Body* body, std::size_t index, const Vec3& r, const Vec3& J) {
    if (body == nullptr || body->is_static()) return;
    if (jacobi_) {
      delta_[index].linear += J;
      delta_[index].angular += r.cross(J);
      ++delta_[index].count;
    } else {
      body->p += J;
      body->l += r.cross(J);
    }
  }

  // Jacobi: applies each body's averaged delta (positions, or momenta when `momenta`).
  void flush(std::vector<Body>& bodies, bool momenta) {
    if (!jacobi_) return;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      Delta& d = delta_[i];
      if (d.count == 0) continue;
      const double share = 1.0 / static_cast<double>(d.count);
      if (momenta) {
        bodies[i].p += share * d.linear;
        bodies[i].l += share * d.angular;
      } else {
        bodies[i].x += share * d.linear;
        turn(bodies[i].o, share * d.angular);
      }
      d = Delta{};
    }
  }

  // One correction of C (m) along unit k between points pa on a and pb on b (either body may be
  // null: the world), compliance alpha~ (kg^-1); returns Delta lambda (kg m).
  double correct(Body* a, std::size_t ia, Body* b, std::size_t ib, const Vec3& pa, const Vec3& pb,
                 const Vec3& k, double C, double alpha_tilde) {
    const Vec3 ra = a != nullptr ? Vec3(pa - a->x) : Vec3::Zero();
    const Vec3 rb = b != nullptr ? Vec3(pb - b->x) : Vec3::Zero();
    const double w = inverse_mass(a, ra, k) + inverse_mass(b, rb, k) + alpha_tilde;
    if (!(w > 0.0)) return 0.0;
    const double dlambda = -C / w;
    move(b, ib, rb, dlambda * k);
    move(a, ia, ra, -dlambda * k);
    return dlambda;
  }

  // One sweep over the rods toward the lengths `lengths` (m, one per rod), or their own length
  // when null, compliance alpha~; each rod's Delta lambda into `out` when given.
  void sweep_rods(std::vector<Body>& bodies, const std::vector<DistanceConstraint>& distances,
                  const std::vector<double>* lengths, double alpha_tilde,
                  std::vector<double>* out) {
    for (std::size_t r = 0; r < distances.size(); ++r) {
      const DistanceConstraint& d = distances[r];
      Vec3 pa;
      Vec3 pb;
      distance_endpoints(d, bodies, pa, pb);
      const Vec3 ab = pb - pa;
      const double length = ab.norm();
      double dlambda = 0.0;
      if (length > 1e-12) {  // else no axis
        Body* a = &bodies[static_cast<std::size_t>(d.body_a)];
        Body* b = d.body_b == kWorldBody ? nullptr : &bodies[static_cast<std::size_t>(d.body_b)];
        const double goal = lengths != nullptr ? (*lengths)[r] : d.length;
        dlambda = correct(a, static_cast<std::size_t>(d.body_a), b,
                          b != nullptr ? static_cast<std::size_t>(d.body_b) : 0, pa, pb,
                          ab / length, length - goal, alpha_tilde);
      }
      if (out != nullptr) (*out)[r] = dlambda;
    }
    flush(bodies, false);
  }

  // Pre-stabilisation, once at the start of the step and on positions alone: `sweeps` Gauss-
  // Seidel sweeps move every point deeper than its target out to it, each followed by a sweep
  // that holds the rods at the lengths they had at the start of the step (so that what the
  // contacts move does not become rod error, which the substeps would turn into velocity). Then
  // every point may keep, through the substeps, the overlap it is left with (a point that the
  // others pushed deeper too: the substeps would turn that into velocity). Each body turned by
  // Delta R keeps its angular momentum in its own frame (l := Delta R l): no kinetic energy is
  // added. Uses state_ (n) for the orientations before.
  void prestabilise(std::vector<Body>& bodies, const std::vector<DistanceConstraint>& distances,
                    const WorldDef& def, int sweeps) {
    if (std::none_of(points_.begin(), points_.end(),
                     [&](const Point& p) { return overlap(bodies, p) > p.target; })) {
      return;  // nothing to move (the usual case)
    }
    for (std::size_t i = 0; i < bodies.size(); ++i) state_[i].o = bodies[i].o;
    detail::resize_with_headroom(rod_lengths_, distances.size());
    for (std::size_t r = 0; r < distances.size(); ++r) {
      Vec3 pa;
      Vec3 pb;
      distance_endpoints(distances[r], bodies, pa, pb);
      rod_lengths_[r] = (pb - pa).norm();
    }
    for (int s = 0; s < sweeps; ++s) {
      for (const Point& p : points_) {
        const auto ia = static_cast<std::size_t>(p.body_a);
        const auto ib = static_cast<std::size_t>(p.body_b);
        const Vec3 pa = world_point(bodies[ia], p.local_a);
        const Vec3 pb = world_point(bodies[ib], p.local_b);
        const double C = p.normal.dot(pb - pa) + p.target;
        if (C < 0.0) correct(&bodies[ia], ia, &bodies[ib], ib, pa, pb, p.normal, C, 0.0);
      }
      flush(bodies, false);
      sweep_rods(bodies, distances, &rod_lengths_, 0.0, nullptr);
    }
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (bodies[i].is_static()) continue;
      bodies[i].l = (bodies[i].o * state_[i].o.conjugate()).toRotationMatrix() * bodies[i].l;
    }
    for (Point& p : points_) p.allowed = std::max(overlap(bodies, p), def.penetration_slop);
  }

  // Step 2: one sweep over the contacts, in runs of WorldDef::xpbd_friction_order (a point, or
  // a manifold: the run's normals, then its static friction), then the rods.
  void solve_positions(std::vector<Body>& bodies, const std::vector<DistanceConstraint>& distances,
                       const WorldDef& def, double h) {
    for (Point& p : points_) {
      p.lambda_n = 0.0;
      p.friction.setZero();
    }
    for (std::size_t begin = 0; begin < points_.size();) {
      const std::size_t end = friction_run_end(begin, def);
      for (std::size_t i = begin; i < end; ++i) apply_normal(bodies, points_[i]);
      for (std::size_t i = begin; i < end; ++i) apply_static_friction(bodies, def, points_[i]);
      begin = end;
    }
    flush(bodies, false);
    detail::resize_with_headroom(rod_lambda_, distances.size());
    sweep_rods(bodies, distances, nullptr, def.xpbd_compliance / (h * h), &rod_lambda_);
  }

  // One past the last point whose normal comes before the friction of the point at `begin`:
  // that point alone, or the rest of its manifold (WorldDef::xpbd_friction_order).
  std::size_t friction_run_end(std::size_t begin, const WorldDef& def) const {
    std::size_t end = begin + 1;
    if (def.xpbd_friction_order == XpbdFrictionOrder::point) return end;
    while (end < points_.size() && !points_[end].first) ++end;
    return end;
  }

  // Contact (Sec. 3.5): moves a point that overlaps by more than it may keep out to that
  // overlap, and sets lambda_n.
  void apply_normal(std::vector<Body>& bodies, Point& p) {
    const auto ia = static_cast<std::size_t>(p.body_a);
    const auto ib = static_cast<std::size_t>(p.body_b);
    Body& a = bodies[ia];
    Body& b = bodies[ib];
    const Vec3 pa = world_point(a, p.local_a);
    const Vec3 pb = world_point(b, p.local_b);
    const double C = p.normal.dot(pb - pa) + p.allowed;
    if (!(C < 0.0)) return;
    p.lambda_n = correct(&a, ia, &b, ib, pa, pb, p.normal, C, 0.0);
  }

  // Static friction (Sec. 3.5) of a point that acted: the points' tangential motion since the
  // start of the step or of the substep (WorldDef::xpbd_friction_anchor), undone when the
  // impulse it takes stays within mu lambda_n. Gauss-Seidel reads the points after the normal
  // corrections before it (friction_run_end); Jacobi the state of the sweep.
  void apply_static_friction(std::vector<Body>& bodies, const WorldDef& def, Point& p) {
    if (!(p.lambda_n > 0.0)) return;
    const auto ia = static_cast<std::size_t>(p.body_a);
    const auto ib = static_cast<std::size_t>(p.body_b);
    Body& a = bodies[ia];
    Body& b = bodies[ib];
    const double mu = pair_friction(def.friction, a.friction, b.friction);
    if (!(mu > 0.0)) return;
    const Vec3 qa = world_point(a, p.local_a);
    const Vec3 qb = world_point(b, p.local_b);
    const std::vector<Saved>& start =
        def.xpbd_friction_anchor == XpbdFrictionAnchor::step ? step_start_ : state_;
    const Vec3 pa_prev = start[ia].x + start[ia].R * p.local_a;
    const Vec3 pb_prev = start[ib].x + start[ib].R * p.local_b;
    const Vec3 dp = (qa - pa_prev) - (qb - pb_prev);
    const Vec3 dp_t = dp - p.normal.dot(dp) * p.normal;
    const double slip = dp_t.norm();
    if (!(slip > 0.0)) return;
    const Vec3 t = dp_t / slip;  // a's motion relative to b
    const double w = inverse_mass(&a, qa - a.x, t) + inverse_mass(&b, qb - b.x, t);
    if (!(w > 0.0) || !(slip / w < mu * p.lambda_n)) return;
    // -C along t moves b by +slip/w t and a by -slip/w t: the relative motion cancelled.
    correct(&a, ia, &b, ib, qa, qb, t, -slip, 0.0);
    p.friction = (slip / w) * t;
  }

  // Step 3: velocities from the change of position and orientation over the substep.
  void update_velocities(std::vector<Body>& bodies, double h) const {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      Body& body = bodies[i];
      if (body.is_static()) continue;
      const Quat dq = body.o * state_[i].o.conjugate();
      Vec3 w = 2.0 / h * dq.vec();
      if (dq.w() < 0.0) w = -w;
      body.p = body.mass * (body.x - state_[i].x) / h;
      body.l = body.inv_inertia_world().inverse() * w;
    }
  }

  // Step 4: restitution and dynamic friction on the contacts that acted. Point order: both from
  // the velocities before the point's impulse, applied together. Manifold order: each
  // manifold's restitution, then its friction from the velocities that leaves (Jacobi: all
  // restitution, then all friction).
  void solve_velocities(std::vector<Body>& bodies, const WorldDef& def, double h) {
    for (Point& p : points_) p.velocity_impulse.setZero();
    if (def.xpbd_friction_order == XpbdFrictionOrder::point) {
      for (Point& p : points_) apply_velocity_impulse(bodies, def, h, p, true, true);
      flush(bodies, true);
      return;
    }
    if (jacobi_) {
      for (Point& p : points_) apply_velocity_impulse(bodies, def, h, p, true, false);
      flush(bodies, true);
      for (Point& p : points_) apply_velocity_impulse(bodies, def, h, p, false, true);
      flush(bodies, true);
      return;
    }
    for (std::size_t begin = 0; begin < points_.size();) {
      const std::size_t end = friction_run_end(begin, def);
      for (std::size_t i = begin; i < end; ++i) {
        apply_velocity_impulse(bodies, def, h, points_[i], true, false);
      }
      for (std::size_t i = begin; i < end; ++i) {
        apply_velocity_impulse(bodies, def, h, points_[i], false, true);
      }
      begin = end;
    }
  }

  // The velocity pass's impulse on b (N s) at a point that acted, from the bodies' momenta now
  // (Sec. 3.6): with `normal`, the one that sets the normal velocity to max(-eps v~_n, 0); with
  // `friction`, dynamic friction's -u_t / |u_t| min(mu lambda_n / h, |u_t| / w_t).
  void apply_velocity_impulse(std::vector<Body>& bodies, const WorldDef& def, double h, Point& p,
                              bool normal, bool friction) {
    if (!(p.lambda_n > 0.0)) return;
    const auto ia = static_cast<std::size_t>(p.body_a);
    const auto ib = static_cast<std::size_t>(p.body_b);
    Body& a = bodies[ia];
    Body& b = bodies[ib];
    const Vec3 ra = world_point(a, p.local_a) - a.x;
    const Vec3 rb = world_point(b, p.local_b) - b.x;
    const Vec3 u = (b.velocity() + b.angular_velocity().cross(rb)) -
                   (a.velocity() + a.angular_velocity().cross(ra));
    const double vn = p.normal.dot(u);
    Vec3 impulse = Vec3::Zero();
    const double mu = pair_friction(def.friction, a.friction, b.friction);
    const Vec3 ut = u - vn * p.normal;
    const double slide = ut.norm();
    if (friction && mu > 0.0 && slide > 0.0) {
      const Vec3 t = ut / slide;
      const double w = inverse_mass(&a, ra, t) + inverse_mass(&b, rb, t);
      if (w > 0.0) impulse -= std::min(mu * p.lambda_n / h, slide / w) * t;
    }
    if (normal) {
      const Vec3 u_before = (state_[ib].v + state_[ib].w.cross(rb)) - (state_[ia].v + state_[ia].w.cross(ra));
      const double vn_before = p.normal.dot(u_before);
      const double eps = -vn_before > def.restitution_threshold
                             ? pair_restitution(def.restitution, a.restitution, b.restitution)
                             : 0.0;
      const double target = std::max(-eps * vn_before, 0.0);
      const double wn = inverse_mass(&a, ra, p.normal) + inverse_mass(&b, rb, p.normal);
      if (wn > 0.0) impulse += (target - vn) / wn * p.normal;
    }
    push(&b, ib, rb, impulse);
    push(&a, ia, ra, -impulse);
    p.velocity_impulse += impulse;
  }

  // Adds this substep's share of each row's mean force over the step (N) to `lambda` (c) at the
  // rows' places (`layout`: each point's contact row and, with friction, its two friction rows;
  // each rod's row): positional impulses / h and velocity impulses, over dt.
  void accumulate_forces(const std::vector<ConstraintRow>& rows, const RowLayout& layout,
                         std::vector<double>& lambda, double h, double dt) const {
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Point& p = points_[i];
      lambda[i] += (p.lambda_n / h + p.normal.dot(p.velocity_impulse)) / dt;
      if (!layout.friction) continue;
      const Vec3 tangential = p.friction / h + p.velocity_impulse;
      for (std::size_t t = 0; t < 2; ++t) {
        const std::size_t row = layout.friction_row(i) + t;
        lambda[row] += tangential.dot(rows[row].j.segment<3>(6)) / dt;
      }
    }
    for (std::size_t r = 0; r < rod_lambda_.size(); ++r) lambda[layout.rod_row(r)] += rod_lambda_[r] / h / dt;
  }

  std::vector<Point> points_;
  std::vector<Saved> state_;        // n: each body at the start of the substep
  std::vector<Saved> step_start_;   // n: each body's x and R at the start of the step
  std::vector<Delta> delta_;        // n: Jacobi's pending changes
  std::vector<double> rod_lambda_;  // one per rod: this substep's Delta lambda (kg m)
  std::vector<double> rod_lengths_; // one per rod: its length at the start of the step (m)
  bool jacobi_ = false;
};

}  // namespace

std::unique_ptr<PushMethod> make_xpbd() { return std::make_unique<Xpbd>(); }

}  // namespace cps
