// Collision dispatch and the box-plane test (paper Sec. 4).
#include "cps/collision.h"

#include "cps/constraint.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace cps {
namespace {

OrientedBox oriented_box(const Body& b, const Mat3& R) { return {b.x, R, b.shape.half_extents}; }

// World-space plane of a plane body with rotation R: {x : dot(n, x) = offset}.
void world_plane(const Body& b, const Mat3& R, Vec3& n, double& offset) {
  n = R * b.shape.normal;
  offset = b.shape.offset + n.dot(b.x);
}

void flip_normals(Manifold& m) {
  for (int i = 0; i < m.count; ++i) m.contacts[static_cast<std::size_t>(i)].normal *= -1.0;
}

}  // namespace

int collide_box_plane(const OrientedBox& box, const Vec3& n, double offset, Manifold& out,
                      double margin) {
  const int before = out.count;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 sign((corner & 1) ? 1.0 : -1.0, (corner & 2) ? 1.0 : -1.0,
                    (corner & 4) ? 1.0 : -1.0);
    const Vec3 v = box.c + box.R * sign.cwiseProduct(box.e);
    const double separation = n.dot(v) - offset;
    if (separation < margin) {
      // Midway between the vertex and its projection on the plane.
      out.add({v - 0.5 * separation * n, n, -separation,
               contact_feature(kFeatureBoxVertex, static_cast<std::uint32_t>(corner))});
    }
  }
  return out.count - before;
}

int collide_sphere_plane(const Vec3& c, double r, const Vec3& n, double offset, Manifold& out,
                         double margin) {
  const double separation = n.dot(c) - offset - r;
  if (separation >= margin) return 0;
  // Midway between the deepest point of the sphere, c - r n, and the plane.
  out.add({c - (r + 0.5 * separation) * n, n, -separation, contact_feature(kFeatureSphere, 0)});
  return 1;
}

int collide_sphere_sphere(const Vec3& c_a, double r_a, const Vec3& c_b, double r_b, Manifold& out,
                          double margin) {
  const Vec3 d = c_b - c_a;
  const double dist = d.norm();
  const double depth = r_a + r_b - dist;
  if (depth <= -margin) return 0;
  const Vec3 n = dist > 1e-12 ? Vec3(d / dist) : Vec3(Vec3::UnitY());
  out.add({c_a + (r_a - 0.5 * depth) * n, n, depth, contact_feature(kFeatureSphere, 0)});
  return 1;
}

int collide_box_sphere(const OrientedBox& box, const Vec3& c, double r, Manifold& out,
                       double margin) {
  const Vec3 p = box.R.transpose() * (c - box.c);  // sphere centre in box space
  const Vec3 q = p.cwiseMax(-box.e).cwiseMin(box.e);  // closest point of the box
  Vec3 n_local;
  double depth;
  Vec3 surface;  // box surface point, box space
  if (q == p) {
    // The centre is inside: leave through the nearest face.
    int axis = 0;
    double nearest = kInfinity;
    for (int i = 0; i < 3; ++i) {
      const double to_face = box.e[i] - std::abs(p[i]);
      if (to_face < nearest) {
        nearest = to_face;
        axis = i;
      }
    }
    n_local = Vec3::Zero();
    n_local[axis] = p[axis] >= 0.0 ? 1.0 : -1.0;
    depth = nearest + r;
    surface = p;
    surface[axis] = n_local[axis] * box.e[axis];
  } else {
    const Vec3 delta = p - q;
    const double dist = delta.norm();
    if (dist >= r + margin) return 0;
    n_local = delta / dist;
    depth = r - dist;
    surface = q;
  }
  const Vec3 n = box.R * n_local;
  const Vec3 surface_world = box.c + box.R * surface;
  // Midway between the box surface and the deepest point of the sphere, c - r n.
  out.add({0.5 * (surface_world + c - r * n), n, depth, contact_feature(kFeatureSphere, 0)});
  return 1;
}

namespace {

// collide() with the rotations given (R_a, R_b), or computed here when needed (nullptr).
int collide_bodies(const Body& a, const Mat3* R_a, const Body& b, const Mat3* R_b, Manifold& out,
                   double margin) {
  out.count = 0;
  if (a.is_static() && b.is_static()) return 0;
  // Order the pair as (box, sphere, plane) by kind; flip the normals back if it was swapped.
  const auto rank = [](ShapeKind k) { return k == ShapeKind::box ? 0 : k == ShapeKind::sphere ? 1 : 2; };
  const bool swapped = rank(a.shape.kind) > rank(b.shape.kind);
  const Body& first = swapped ? b : a;
  const Body& second = swapped ? a : b;
  const Mat3* given_1 = swapped ? R_b : R_a;
  const Mat3* given_2 = swapped ? R_a : R_b;
  const auto R1 = [&] { return given_1 != nullptr ? *given_1 : first.rotation(); };
  const auto R2 = [&] { return given_2 != nullptr ? *given_2 : second.rotation(); };
  const ShapeKind k1 = first.shape.kind;
  const ShapeKind k2 = second.shape.kind;
  Vec3 n;
  double offset;
  if (k2 == ShapeKind::plane) {
    if (k1 == ShapeKind::plane) return 0;
    world_plane(second, R2(), n, offset);
    // Contacts come from the plane to the shape: from `second` to `first`.
    if (k1 == ShapeKind::box) {
      collide_box_plane(oriented_box(first, R1()), n, offset, out, margin);
    } else {
      collide_sphere_plane(first.x, first.shape.radius, n, offset, out, margin);
    }
    if (!swapped) flip_normals(out);  // a = first: normals must point from first to the plane
    return out.count;
  }
  if (k1 == ShapeKind::box && k2 == ShapeKind::box) {
    collide_box_box(oriented_box(first, R1()), oriented_box(second, R2()), out, margin);
  } else if (k1 == ShapeKind::box) {
    collide_box_sphere(oriented_box(first, R1()), second.x, second.shape.radius, out, margin);
  } else {
    collide_sphere_sphere(first.x, first.shape.radius, second.x, second.shape.radius, out,
                          margin);
  }
  if (swapped) flip_normals(out);
  return out.count;
}

}  // namespace

int collide(const Body& a, const Body& b, Manifold& out, double margin) {
  return collide_bodies(a, nullptr, b, nullptr, out, margin);
}

int collide(const Body& a, const Mat3& R_a, const Body& b, const Mat3& R_b, Manifold& out,
            double margin) {
  return collide_bodies(a, &R_a, b, &R_b, out, margin);
}

void reduce_manifold(Manifold& m, double tolerance) {
  if (m.count <= 4) return;
  constexpr double kSlack = 0.05;  // a later candidate must score 5 % better (Box3D's 0.95 bias)
  const auto better = [](double score, double best) { return score > best + kSlack * std::abs(best); };
  const Vec3 n = m.contacts[0].normal;
  Vec3 t1;
  Vec3 t2;
  tangent_basis(n, t1, t2);
  const Vec3 across = 0.6 * t1 + 0.8 * t2;  // a fixed direction across the normal
  const double tol2 = tolerance * tolerance;
  std::array<Contact, kMaxManifoldPoints> left = m.contacts;
  int count = m.count;
  int kept = 0;
  // Moves candidate i of `left` into m.contacts[kept].
  const auto keep = [&](int i) {
    m.contacts[static_cast<std::size_t>(kept++)] = left[static_cast<std::size_t>(i)];
    left[static_cast<std::size_t>(i)] = left[static_cast<std::size_t>(--count)];
  };
  // Picks the best of `left` by score(c), or -1 when none scores above `floor`.
  const auto pick = [&](auto&& score, double floor) {
    int best = -1;
    double best_score = floor;
    for (int i = 0; i < count; ++i) {
      const double s = score(left[static_cast<std::size_t>(i)]);
      if (best < 0 ? s > floor : better(s, best_score)) {
        best = i;
        best_score = s;
      }
    }
    return best;
  };
  const Vec3 origin = m.contacts[0].point;
  const int extreme = pick([&](const Contact& c) { return c.depth + across.dot(c.point - origin); }, -kInfinity);
  if (extreme < 0) return;  // a score that is not finite: left as it is
  keep(extreme);
  const Vec3 a = m.contacts[0].point;
  const auto plane = [&n](const Vec3& d) { return Vec3(d - d.dot(n) * n); };
  int i = pick([&](const Contact& c) {
    const double depth = std::max(c.depth, 0.0);
    return plane(c.point - a).squaredNorm() + 4.0 * depth * depth;
  }, tol2);
  if (i < 0) {
    m.count = kept;
    return;
  }
  keep(i);
  const Vec3 ab = m.contacts[1].point - a;
  i = pick([&](const Contact& c) { return std::abs(n.dot(ab.cross(c.point - a))); }, tol2);
  if (i < 0) {
    m.count = kept;
    return;
  }
  keep(i);
  const Vec3 b = m.contacts[1].point;
  const Vec3 c3 = m.contacts[2].point;
  const double sign = n.dot(ab.cross(c3 - a)) < 0.0 ? -1.0 : 1.0;
  // The area a point adds outside triangle a, b, c: the largest of its signed areas beyond the
  // triangle's three edges.
  i = pick([&](const Contact& c) {
    const Vec3& p = c.point;
    const double u1 = sign * n.dot((p - a).cross(ab));
    const double u2 = sign * n.dot((p - b).cross(c3 - b));
    const double u3 = sign * n.dot((p - c3).cross(a - c3));
    return std::max(u1, std::max(u2, u3));
  }, tol2);
  if (i >= 0) keep(i);
  m.count = kept;
}

}  // namespace cps
