// Collision dispatch and the box-plane test (paper Sec. 4).
#include "cps/collision.h"

namespace cps {
namespace {

OrientedBox oriented_box(const Body& b) { return {b.x, b.rotation(), b.shape.half_extents}; }

// World-space plane of a plane body: {x : dot(n, x) = offset}.
void world_plane(const Body& b, Vec3& n, double& offset) {
  n = b.rotation() * b.shape.normal;
  offset = b.shape.offset + n.dot(b.x);
}

void flip_normals(Manifold& m) {
  for (int i = 0; i < m.count; ++i) m.contacts[static_cast<std::size_t>(i)].normal *= -1.0;
}

}  // namespace

int collide_box_plane(const OrientedBox& box, const Vec3& n, double offset, Manifold& out) {
  const int before = out.count;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 sign((corner & 1) ? 1.0 : -1.0, (corner & 2) ? 1.0 : -1.0,
                    (corner & 4) ? 1.0 : -1.0);
    const Vec3 v = box.c + box.R * sign.cwiseProduct(box.e);
    const double separation = n.dot(v) - offset;
    if (separation < 0.0) {
      // Midway between the vertex and its projection on the plane.
      out.add({v - 0.5 * separation * n, n, -separation});
    }
  }
  return out.count - before;
}

int collide(const Body& a, const Body& b, Manifold& out) {
  out.count = 0;
  if (a.is_static() && b.is_static()) return 0;
  const ShapeKind ka = a.shape.kind;
  const ShapeKind kb = b.shape.kind;
  if (ka == ShapeKind::box && kb == ShapeKind::box) {
    return collide_box_box(oriented_box(a), oriented_box(b), out);
  }
  if (ka == ShapeKind::plane && kb == ShapeKind::box) {
    Vec3 n;
    double offset;
    world_plane(a, n, offset);
    return collide_box_plane(oriented_box(b), n, offset, out);  // normal plane -> box = a -> b
  }
  if (ka == ShapeKind::box && kb == ShapeKind::plane) {
    Vec3 n;
    double offset;
    world_plane(b, n, offset);
    collide_box_plane(oriented_box(a), n, offset, out);
    flip_normals(out);  // from the box (a) into the plane (b)
    return out.count;
  }
  return 0;  // plane-plane
}

}  // namespace cps
