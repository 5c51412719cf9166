// Contact recycling (see contact_recycling.h).
#include "contact_recycling.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cps {
namespace {

// A body's bounding radius about its centre (m): how far a point of it moves per radian of
// turn. A plane is static and never turns.
double bounding_radius(const Body& body) {
  switch (body.shape.kind) {
    case ShapeKind::box: return body.shape.half_extents.norm();
    case ShapeKind::sphere: return body.shape.radius;
    default: return 0.0;
  }
}

// cos^2 of half the largest turn a body may make and keep its manifold: 10 degrees (Box3D's
// B3_CONTACT_RECYCLE_ANGULAR_DISTANCE, 0.99240388 = cos^2(5 deg)).
const double kMinCosHalfTurnSquared = std::pow(std::cos(5.0 * std::numbers::pi / 180.0), 2);

bool pair_below(int a, int b, int c, int d) { return a < c || (a == c && b < d); }

}  // namespace

void ContactRecycler::begin_step() { next_count_ = 0; }

ContactRecycler::Cursor ContactRecycler::cursor_at(int a, int b) const {
  const auto first = std::lower_bound(last_.begin(), last_.end(), std::pair{a, b},
                                      [](const Cached& c, const std::pair<int, int>& p) {
                                        return pair_below(c.a, c.b, p.first, p.second);
                                      });
  return Cursor{static_cast<std::size_t>(first - last_.begin()), kNone};
}

bool ContactRecycler::recycle(int a, int b, const std::vector<Body>& bodies, double distance,
                              Manifold& out, Cursor& cursor) const {
  cursor.found = kNone;
  std::size_t& at = cursor.at;
  while (at < last_.size() && pair_below(last_[at].a, last_[at].b, a, b)) ++at;
  if (at == last_.size() || last_[at].a != a || last_[at].b != b) return false;
  const Cached& c = last_[at];
  const Body& body_a = bodies[static_cast<std::size_t>(a)];
  const Body& body_b = bodies[static_cast<std::size_t>(b)];
  // Each body's own turn since caching: the quaternion dot product is cos of half the angle.
  const double turn_a = body_a.o.dot(c.o_a);
  const double turn_b = body_b.o.dot(c.o_b);
  if (std::min(turn_a * turn_a, turn_b * turn_b) <= kMinCosHalfTurnSquared) return false;
  // The relative pose of b in a's frame, then and now: any point within the bounding radius r
  // has moved relative to a by at most |dp| + 2 |sin(theta / 2)| r (theta the relative turn).
  const Vec3 p_then = c.o_a.conjugate() * (c.x_b - c.x_a);
  const Vec3 p_now = body_a.o.conjugate() * (body_b.x - body_a.x);
  const Quat q_then = c.o_a.conjugate() * c.o_b;
  const Quat q_now = body_a.o.conjugate() * body_b.o;
  const double moved = (p_now - p_then).norm();
  const Quat turn = q_then.conjugate() * q_now;
  const double radius = std::max(bounding_radius(body_a), bounding_radius(body_b));
  if (moved + 2.0 * turn.vec().norm() * radius >= distance) return false;
  // The points, fixed to the bodies since caching: their separation along the cached normal
  // changes by n . (motion of b's point - motion of a's point). The anchors used to apply
  // impulses stay as cached (world vectors from each centre), as Box3D keeps them
  // (b3CollideTask); so a point is a's anchor and b's lies anchor_shift from it.
  const Mat3 dR_a = (body_a.o * c.o_a.conjugate()).toRotationMatrix();
  const Mat3 dR_b = (body_b.o * c.o_b.conjugate()).toRotationMatrix();
  out.body_a = a;
  out.body_b = b;
  out.count = c.count;
  out.anchor_shift = (body_b.x - c.x_b) - (body_a.x - c.x_a);
  for (int i = 0; i < c.count; ++i) {
    const CachedPoint& p = c.points[static_cast<std::size_t>(i)];
    const Vec3 r_a = dR_a * p.r_a;
    const Vec3 r_b = dR_b * p.r_b;
    const Vec3 moved_a = (body_a.x - c.x_a) + (r_a - p.r_a);
    const Vec3 moved_b = (body_b.x - c.x_b) + (r_b - p.r_b);
    Contact& contact = out.contacts[static_cast<std::size_t>(i)];
    contact.point = body_a.x + p.r_a;
    contact.normal = c.normal;
    contact.depth = p.depth - c.normal.dot(moved_b - moved_a);
    contact.feature = p.feature;
  }
  cursor.found = at;
  return true;
}

void ContactRecycler::keep(const Manifold& m, const std::vector<Body>& bodies, std::size_t found) {
  if (next_count_ == next_.size()) {
    detail::reserve_with_headroom(next_, next_count_ + 1);
    next_.emplace_back();
  }
  keep_at(next_count_++, m, bodies, found);
}

void ContactRecycler::resize_kept(std::size_t count) {
  if (next_.size() < count) detail::resize_with_headroom(next_, count);
  next_count_ = count;
}

void ContactRecycler::copy_used(const Cached& from, Cached& to) {
  to.a = from.a;
  to.b = from.b;
  to.normal = from.normal;
  to.x_a = from.x_a;
  to.x_b = from.x_b;
  to.o_a = from.o_a;
  to.o_b = from.o_b;
  to.count = from.count;
  std::copy_n(from.points.begin(), from.count, to.points.begin());
}

void ContactRecycler::keep_at(std::size_t at, const Manifold& m, const std::vector<Body>& bodies,
                              std::size_t found) {
  if (found != kNone && last_[found].a == m.body_a && last_[found].b == m.body_b) {
    copy_used(last_[found], next_[at]);  // the poses of its caching, so that motion adds up
    return;
  }
  const Body& body_a = bodies[static_cast<std::size_t>(m.body_a)];
  const Body& body_b = bodies[static_cast<std::size_t>(m.body_b)];
  Cached& c = next_[at];
  c.a = m.body_a;
  c.b = m.body_b;
  c.normal = m.contacts[0].normal;
  c.x_a = body_a.x;
  c.x_b = body_b.x;
  c.o_a = body_a.o;
  c.o_b = body_b.o;
  c.count = m.count;
  for (int i = 0; i < m.count; ++i) {
    const Contact& contact = m.contacts[static_cast<std::size_t>(i)];
    CachedPoint& p = c.points[static_cast<std::size_t>(i)];
    p.r_a = contact.point - body_a.x;
    p.r_b = point_on_b(m, contact) - body_b.x;
    p.depth = contact.depth;
    p.feature = contact.feature;
  }
}

void ContactRecycler::end_step() {
  next_.resize(next_count_);  // never grows here: drops the entries past this step's
  last_.swap(next_);
}

}  // namespace cps
