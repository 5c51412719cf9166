// Non-linear Gauss-Seidel position projection (see ngs.h).
#include "ngs.h"

#include "buffers.h"

#include <algorithm>
#include <cmath>

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
// inverse masses and inertias (ngs.h); point_a, point_b: where the constraint acts on each (m),
// C in m.
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

}  // namespace

void NgsProjection::capture(const std::vector<Manifold>& manifolds,
                            const std::vector<Body>& bodies) {
  points_.clear();
  std::size_t count = 0;
  for (const Manifold& m : manifolds) count += static_cast<std::size_t>(m.count);
  detail::reserve_with_headroom(points_, count);
  for (const Manifold& m : manifolds) {
    const Body& a = bodies[static_cast<std::size_t>(m.body_a)];
    const Body& b = bodies[static_cast<std::size_t>(m.body_b)];
    const Mat3 Ra_t = a.rotation().transpose();
    const Mat3 Rb_t = b.rotation().transpose();
    for (int i = 0; i < m.count; ++i) {
      const Contact& c = m.contacts[static_cast<std::size_t>(i)];
      if (!(c.depth > 0.0)) continue;  // a speculative contact is no overlap
      Point& p = points_.emplace_back();
      p.body_a = m.body_a;
      p.body_b = m.body_b;
      p.normal = c.normal;
      p.local_a = Ra_t * (c.point + 0.5 * c.depth * c.normal - a.x);
      p.local_b = Rb_t * (c.point - 0.5 * c.depth * c.normal - b.x);
    }
  }
}

void NgsProjection::project(const std::vector<DistanceConstraint>& distances, const WorldDef& def,
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

}  // namespace cps
