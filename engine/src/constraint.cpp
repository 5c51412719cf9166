// Contact (Sec. 5.3) and friction (Sec. 5.4) rows.
#include "cps/constraint.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace cps {

namespace {

// axis_row written into j in place (the rows of a large scene are built straight into their
// storage, with no 96-byte copy each).
inline void write_axis_row(Vec12& j, const Vec3& n, const Vec3& r_a, const Vec3& r_b) {
  // Eq. 5.2.1 with p_b - p_a replaced by the unit axis n (Sec. 5.3, Sec. 9.2):
  //   c_dot = n . (v_b + w_b x r_b - v_a - w_a x r_a)
  //         = [-n, -(r_a x n), n, r_b x n] . [v_a, w_a, v_b, w_b]   (scalar triple product)
  j.segment<3>(0) = -n;
  j.segment<3>(3) = -r_a.cross(n);
  j.segment<3>(6) = n;
  j.segment<3>(9) = r_b.cross(n);
}

}  // namespace

Vec12 axis_row(const Vec3& n, const Vec3& r_a, const Vec3& r_b) {
  Vec12 j;
  write_axis_row(j, n, r_a, r_b);
  return j;
}

void tangent_basis(const Vec3& n, Vec3& t1, Vec3& t2) {
  // Cross n with the world axis least aligned with it, so the result is never degenerate.
  const Vec3 a = n.cwiseAbs();
  const Vec3 helper = (a.x() <= a.y() && a.x() <= a.z()) ? Vec3::UnitX()
                      : (a.y() <= a.z())                 ? Vec3::UnitY()
                                                         : Vec3::UnitZ();
  t1 = n.cross(helper).normalized();
  t2 = n.cross(t1);
}

namespace {

// j . v_ab (m/s) for body velocities v_a, w_a, v_b, w_b (m/s, rad/s).
double relative_velocity(const Vec12& j, const Vec3& v_a, const Vec3& w_a, const Vec3& v_b,
                         const Vec3& w_b) {
  return j.segment<3>(0).dot(v_a) + j.segment<3>(3).dot(w_a) + j.segment<3>(6).dot(v_b) +
         j.segment<3>(9).dot(w_b);
}

}  // namespace

BodyVelocity body_velocity(const Body& b) { return {b.velocity(), b.angular_velocity()}; }

std::optional<double> restitution_target(const Vec12& j, const Contact& c, const BodyVelocity& v_a,
                                         const BodyVelocity& v_b, double eps, double threshold, double dt) {
  // Eq. 8.2.1: v_r = -eps j . v1, for points approaching faster than the threshold that touch,
  // or will close their gap within this step.
  const double approach = relative_velocity(j, v_a.v, v_a.w, v_b.v, v_b.w);  // j . v1 (m/s)
  if (eps > 0.0 && approach < -threshold && approach * dt <= std::min(c.depth, 0.0)) return -eps * approach;
  return std::nullopt;
}

double friction_limit(double mu, const Body& a, const Body& b, int points, const Vec3& gravity, const Vec3& n) {
  // Sec. 5.4: m is the combined mass of both bodies divided over the contact points (a static
  // body has mass 0 here, so the movable body's mass remains).
  const double mass_per_point = (a.mass + b.mass) / static_cast<double>(points);
  return mu * mass_per_point * std::abs(gravity.dot(n));
}

void append_contact_rows(const Manifold& m, const std::vector<Body>& bodies,
                         const RowParams& params, std::vector<ConstraintRow>& rows) {
  if (m.count == 0) return;
  // Body velocities, once per manifold (the angular ones need I^-1 in world space).
  append_contact_rows(m, bodies, body_velocity(bodies[static_cast<std::size_t>(m.body_a)]),
                      body_velocity(bodies[static_cast<std::size_t>(m.body_b)]), params, rows);
}

void append_contact_rows(const Manifold& m, const std::vector<Body>& bodies,
                         const BodyVelocity& vel_a, const BodyVelocity& vel_b,
                         const RowParams& params, std::vector<ConstraintRow>& rows) {
  const int first_normal_row = static_cast<int>(rows.size());
  append_normal_rows(m, bodies, vel_a, vel_b, params, rows);
  append_friction_rows(m, bodies, params, first_normal_row, rows);
}

void append_normal_rows(const Manifold& m, const std::vector<Body>& bodies,
                        const BodyVelocity& vel_a, const BodyVelocity& vel_b,
                        const RowParams& params, std::vector<ConstraintRow>& rows) {
  const std::size_t first = rows.size();
  rows.resize(first + static_cast<std::size_t>(m.count));
  write_normal_rows(m, bodies, vel_a, vel_b, params, rows.data() + first);
}

void write_normal_rows(const Manifold& m, const std::vector<Body>& bodies,
                       const BodyVelocity& vel_a, const BodyVelocity& vel_b,
                       const RowParams& params, ConstraintRow* out) {
  const Body& a = bodies[static_cast<std::size_t>(m.body_a)];
  const Body& b = bodies[static_cast<std::size_t>(m.body_b)];
  const double eps = pair_restitution(params.restitution, a.restitution, b.restitution);
  for (int i = 0; i < m.count; ++i) {
    const Contact& c = m.contacts[static_cast<std::size_t>(i)];
    ConstraintRow& contact = out[i];
    contact = ConstraintRow{};
    contact.kind = RowKind::contact;
    contact.body_a = m.body_a;
    contact.body_b = m.body_b;
    write_axis_row(contact.j, c.normal, c.point - a.x, point_on_b(m, c) - b.x);
    if (c.depth >= 0.0) {
      // Eq. 5.3.1 (docs/conventions.md, Sec. 3): C = -d, v = -beta C / dt = beta d / dt > 0 opens
      // it; with a penetration slop s, C = -max(d - s, 0) (s = 0: the paper's push).
      contact.push = params.beta * std::max(c.depth - params.penetration_slop, 0.0) / params.dt;
    } else {
      // Speculative contact (gap -d within the margin): the points may approach by the gap in this
      // step, no further. This is a limit on the velocity, not a correction, so it stays in both
      // solves of Sec. 8.1.
      contact.bias = c.depth / params.dt;
    }
    if (eps > 0.0) {
      if (const std::optional<double> target =
              restitution_target(contact.j, c, vel_a, vel_b, eps, params.restitution_threshold, params.dt)) {
        contact.bias = *target;
        contact.restitution = *target;
      }
    }
    // Split impulse (push/split_impulse.cpp): a shallow contact's push stays in the velocity solve.
    if (c.depth <= params.velocity_push_depth) {
      contact.bias += contact.push;
      contact.push = 0.0;
    }
    contact.c_min = 0.0;
    contact.c_max = kInfinity;
  }
}

void append_friction_rows(const Manifold& m, const std::vector<Body>& bodies,
                          const RowParams& params, int first_normal_row,
                          std::vector<ConstraintRow>& rows, const Vec3* tangents) {
  if ((params.friction <= 0.0 && !params.body_friction) || m.count == 0) return;
  const std::size_t first = rows.size();
  rows.resize(first + 2 * static_cast<std::size_t>(m.count));
  write_friction_rows(m, bodies, params, first_normal_row, rows.data() + first, tangents);
}

void write_friction_rows(const Manifold& m, const std::vector<Body>& bodies,
                         const RowParams& params, int first_normal_row, ConstraintRow* out,
                         const Vec3* tangents) {
  if ((params.friction <= 0.0 && !params.body_friction) || m.count == 0) return;
  const Body& a = bodies[static_cast<std::size_t>(m.body_a)];
  const Body& b = bodies[static_cast<std::size_t>(m.body_b)];
  const double mu = pair_friction(params.friction, a.friction, b.friction);
  for (int i = 0; i < m.count; ++i) {
    const Contact& c = m.contacts[static_cast<std::size_t>(i)];
    const Vec3 r_a = c.point - a.x;
    const Vec3 r_b = point_on_b(m, c) - b.x;
    const double limit = friction_limit(mu, a, b, m.count, params.gravity, c.normal);
    Vec3 t[2];
    if (tangents != nullptr) {
      t[0] = tangents[i];
      t[1] = c.normal.cross(t[0]);
    } else {
      tangent_basis(c.normal, t[0], t[1]);
    }
    for (const Vec3& tangent : t) {
      ConstraintRow& friction = *out++;
      friction = ConstraintRow{};
      friction.kind = RowKind::friction;
      friction.body_a = m.body_a;
      friction.body_b = m.body_b;
      write_axis_row(friction.j, tangent, r_a, r_b);
      friction.c_min = -limit;
      friction.c_max = limit;
      friction.normal_row = first_normal_row + i;
      friction.mu = mu;
    }
  }
}

void distance_endpoints(const DistanceConstraint& d, const std::vector<Body>& bodies, Vec3& p_a,
                        Vec3& p_b) {
  const Body& a = bodies[static_cast<std::size_t>(d.body_a)];
  p_a = a.x + a.rotation() * d.local_a;
  if (d.body_b == kWorldBody) {
    p_b = d.local_b;
  } else {
    const Body& b = bodies[static_cast<std::size_t>(d.body_b)];
    p_b = b.x + b.rotation() * d.local_b;
  }
}

void append_distance_row(const DistanceConstraint& d, const std::vector<Body>& bodies,
                         const RowParams& params, std::vector<ConstraintRow>& rows) {
  Vec3 p_a;
  Vec3 p_b;
  distance_endpoints(d, bodies, p_a, p_b);
  const Vec3 p_ab = p_b - p_a;
  const double dist = p_ab.norm();
  const Vec3 n = dist > 1e-12 ? Vec3(p_ab / dist) : Vec3(Vec3::UnitY());
  const Vec3 r_a = p_a - bodies[static_cast<std::size_t>(d.body_a)].x;
  const Vec3 r_b = d.body_b == kWorldBody ? Vec3::Zero()
                                          : Vec3(p_b - bodies[static_cast<std::size_t>(d.body_b)].x);
  ConstraintRow row;
  row.kind = RowKind::distance;
  row.body_a = d.body_a;
  row.body_b = d.body_b;
  row.j = axis_row(n, r_a, r_b);
  // C = |p_ab| - l; target v = -beta C / dt: a stretched rod shrinks (docs/conventions.md, Sec. 3;
  // Eq. 5.2.3 prints the opposite sign).
  row.push = -params.beta * (dist - d.length) / params.dt;
  row.c_min = -kInfinity;
  row.c_max = kInfinity;
  rows.push_back(row);
}

}  // namespace cps
