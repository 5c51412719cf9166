// Non-linear Gauss-Seidel position projection: `--push ngs`. Sources: Box2D v2.4,
// b2ContactSolver::SolvePositionConstraints and b2DistanceJoint::SolvePositionConstraints
// (erincatto/box2d, tag v2.4.1, src/dynamics/b2_contact_solver.cpp, b2_distance_joint.cpp);
// Jolt Physics' position iterations (ContactConstraintManager::SolvePositionConstraints); E.
// Catto, "Modeling and solving constraints", GDC 2009 (the non-linear Gauss-Seidel section).
//
// Derivation. The velocity solve carries no push: A lambda = b (Eq. 6.2.9) with each row's
// target without it (restitution and speculative bias only), and both the positions and the
// stored momenta move with f_c0 = f_ext + J^T lambda (Sec. 3.2). The overlaps and rod errors
// left are then removed from the positions directly, by Gauss-Seidel over the constraints on
// their current, non-linear values (the rows are rebuilt from the moved bodies at every
// correction; the velocities are not touched):
//   contact point: its two witness points move with their bodies (fixed in each body's frame
//     from the point and depth the collision gave at the start of the step; Contact::point is
//     midway, so p_a = point + n d/2 and p_b = point_on_b - n d/2, point_on_b = point but in a
//     recycled manifold); the normal n keeps its world
//     direction (as Jolt's; Box2D 2.4 rotates it with the reference body). Separation
//     s = n . (p_b - p_a) (< 0: overlap), and
//       C = clamp(beta (s + slop), -max_correction, 0)
//     with beta the push factor constant (Box2D's b2_baumgarte, 0.2 like the paper's), slop the
//     penetration slop (WorldDef::penetration_slop; Box2D's b2_linearSlop is 0.005 m) and
//     max_correction (WorldDef::max_correction, m; b2_maxLinearCorrection 0.2 m);
//   rod: u = (p_b - p_a) / |p_b - p_a|, C = clamp(|p_b - p_a| - l, -max_correction,
//     max_correction), corrected in full (Box2D 2.4's distance joint has no factor);
// and for either, with r_a, r_b from the centres of mass to where it acts (for a contact the
// midpoint of the witness points, for both bodies, as Box2D; for a rod its two end points) and
// the axis k (n or u):
//   K = m_a^-1 + m_b^-1 + (r_a x k) . I_a^-1 (r_a x k) + (r_b x k) . I_b^-1 (r_b x k)  (1/kg)
//   P = -C / K k  (kg m)
//   x_a -= m_a^-1 P, o_a turned by -I_a^-1 (r_a x P);  x_b += m_b^-1 P, o_b by +I_b^-1 (r_b x P)
// with I^-1 of the current orientation and the turn as the linear update of Eq. 3.2.4 followed
// by normalisation. Contacts first, then rods, WorldDef::position_iterations times (Box2D 2.4:
// 3; it stops early once every separation is above -3 slop; here the count is fixed, so the
// cost per step does not depend on the state).
//
// Both solvers and both friction models act in the velocity solve (friction has no position
// part); restitution is in its bias; warm starting warm starts it; both assemblies serve it.

#include "push_method.h"

#include "../buffers.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace cps {
namespace {

// r x k and its I^-1 image for one body; zero for a static body or the world.
struct Lever {
  Vec3 rk = Vec3::Zero();
  Vec3 inv_i_rk = Vec3::Zero();
};

Lever lever(const Body* body, const Vec3& r, const Vec3& k) {
  Lever l;
  if (body == nullptr || body->is_static()) return l;
  l.rk = r.cross(k);
  l.inv_i_rk = body->inv_inertia_world() * l.rk;
  return l;
}

// Turns o by the small rotation vector theta (rad): o += 1/2 [0, theta] o, normalised (the
// linear update of Eq. 3.2.4 with w dt = theta).
void turn(Quat& o, const Vec3& theta) {
  const Quat spin(0.0, 0.5 * theta.x(), 0.5 * theta.y(), 0.5 * theta.z());
  o.coeffs() += (spin * o).coeffs();
  o.normalize();
}

// Moves a and b (either may be null: the world) along k to change C by -C, shared by their
// inverse masses and inertias (the comment at the top); point_a, point_b: where the constraint
// acts on each (m), C in m.
void correct(Body* a, Body* b, const Vec3& point_a, const Vec3& point_b, const Vec3& k, double C) {
  const Lever la = lever(a, a != nullptr ? Vec3(point_a - a->x) : Vec3::Zero(), k);
  const Lever lb = lever(b, b != nullptr ? Vec3(point_b - b->x) : Vec3::Zero(), k);
  const double inv_ma = a != nullptr ? a->inv_mass : 0.0;
  const double inv_mb = b != nullptr ? b->inv_mass : 0.0;
  const double K = inv_ma + inv_mb + la.rk.dot(la.inv_i_rk) + lb.rk.dot(lb.inv_i_rk);
  if (!(K > 0.0)) return;
  const double impulse = -C / K;  // kg m
  if (a != nullptr && !a->is_static()) {
    a->x -= inv_ma * impulse * k;
    turn(a->o, -impulse * la.inv_i_rk);
  }
  if (b != nullptr && !b->is_static()) {
    b->x += inv_mb * impulse * k;
    turn(b->o, impulse * lb.inv_i_rk);
  }
}


class NgsProjection final : public PushMethod {
 public:
  // The velocity solve without the push moves positions and momenta; then the positions are
  // projected.
  void step(StepContext& ctx) override {
    ctx.lambda_second.clear();
    ctx.solve(TargetTerms::bias_only, ctx.lambda, ctx.f_cv, ctx.warm_guess());
    ctx.store_warm_start();
    capture(ctx.manifolds, *ctx.bodies);  // the contact points where the step found them
    ctx.integrate(ctx.f_cv, ctx.f_cv, ctx.def->dt);
    project(*ctx.distances, *ctx.def, *ctx.bodies);
  }

 private:
  struct Point {
    int body_a = 0;
    int body_b = 0;
    Vec3 local_a = Vec3::Zero();  // witness point on a, in a's frame (m)
    Vec3 local_b = Vec3::Zero();  // witness point on b, in b's frame (m)
    Vec3 normal = Vec3::UnitY();  // world direction from a to b
  };

  // Records each contact point that overlaps (depth > 0) as two witness points fixed in the
  // frames of its bodies (as they are before the integration) and its normal (unit, a to b).
  void capture(const std::vector<Manifold>& manifolds, const std::vector<Body>& bodies) {
    points_.clear();
    detail::reserve_with_headroom(points_, contact_point_count(manifolds));
    for_each_contact_point(manifolds, bodies, [this](const Manifold& m, const Contact& c,
                                                     const Body& a, const Body& b,
                                                     const Mat3& Ra_t, const Mat3& Rb_t) {
      if (!(c.depth > 0.0)) return;  // a speculative contact is no overlap
      Point& p = points_.emplace_back();
      p.body_a = m.body_a;
      p.body_b = m.body_b;
      p.normal = c.normal;
      p.local_a = Ra_t * (c.point + 0.5 * c.depth * c.normal - a.x);
      p.local_b = Rb_t * (point_on_b(m, c) - 0.5 * c.depth * c.normal - b.x);
    });
  }

  // Moves the bodies' positions and orientations (not their momenta) by def.position_iterations
  // sweeps over the captured contact points and then the rods (the comment at the top).
  void project(const std::vector<DistanceConstraint>& distances, const WorldDef& def,
               std::vector<Body>& bodies) const {
    for (int it = 0; it < def.position_iterations; ++it) {
      for (const Point& p : points_) {
        Body& a = bodies[static_cast<std::size_t>(p.body_a)];
        Body& b = bodies[static_cast<std::size_t>(p.body_b)];
        const Vec3 pa = a.x + a.rotation() * p.local_a;
        const Vec3 pb = b.x + b.rotation() * p.local_b;
        const double separation = p.normal.dot(pb - pa);
        const double C = std::clamp(def.beta * (separation + def.penetration_slop),
                                    -def.max_correction, 0.0);
        if (C == 0.0) continue;
        const Vec3 point = 0.5 * (pa + pb);  // one point for both, as Box2D's
        correct(&a, &b, point, point, p.normal, C);
      }
      for (const DistanceConstraint& d : distances) {
        Vec3 pa;
        Vec3 pb;
        distance_endpoints(d, bodies, pa, pb);
        const Vec3 ab = pb - pa;
        const double length = ab.norm();
        if (!(length > 1e-12)) continue;  // no axis: left to the velocity solve
        const double C = std::clamp(length - d.length, -def.max_correction, def.max_correction);
        Body* a = &bodies[static_cast<std::size_t>(d.body_a)];
        Body* b = d.body_b == kWorldBody ? nullptr : &bodies[static_cast<std::size_t>(d.body_b)];
        correct(a, b, pa, pb, ab / length, C);
      }
    }
  }

  std::vector<Point> points_;
};

}  // namespace

std::unique_ptr<PushMethod> make_ngs() { return std::make_unique<NgsProjection>(); }

}  // namespace cps
