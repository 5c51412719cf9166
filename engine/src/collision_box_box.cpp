// Box-box collision: separating axis test over 15 axes and manifold construction (paper Sec. 4).
//
// SAT: two convex bodies are disjoint iff some axis separates their projections. For two boxes
// the candidates are the 3 face normals of each box and the 9 cross products of an edge
// direction of one with an edge direction of the other (Gottschalk et al. 1996; Ericson 2005,
// Sec. 4.4.1). The axis of least penetration decides the manifold:
// - a face axis: that face is the reference face; the face of the other box most anti-parallel
//   to it is the incident face. The incident face is clipped against the four side planes of the
//   reference face (Sutherland-Hodgman), and every clipped point below the reference face is a
//   contact (paper Sec. 4: "clipping the most penetrating face ... to the volume below the
//   corresponding anti-parallel face").
// - an edge-edge axis: one contact midway between the closest points of the two supporting
//   edges (Ericson 2005, Sec. 5.1.9).
#include "cps/collision.h"

#include <array>
#include <algorithm>
#include <cmath>

namespace cps {
namespace {

// Cross products shorter than this (unit edge directions, so it is sin of their angle) mean
// parallel edges: their axis is a face axis already tested, or is degenerate.
constexpr double kParallelSin = 1e-6;
// A later candidate axis replaces the current best only if its separation is larger by these
// margins (relative, and absolute as a fraction of the smallest half extent). Face axes of box a
// are preferred, then of box b, then edges, so that nearly tied axes do not flip between steps.
constexpr double kRelativeTolerance = 0.95;
constexpr double kAbsoluteTolerance = 0.01;

struct Axis {
  double separation = -kInfinity;  // m; < 0 means overlap along the axis
  int index = -1;                  // face: 0..2; edge: 3 * i + k
  Vec3 n = Vec3::Zero();           // unit, from box a to box b
};

// Half length (m) of the projection of box b on the unit axis L.
double projected_radius(const OrientedBox& b, const Vec3& L) {
  return b.e.x() * std::abs(b.R.col(0).dot(L)) + b.e.y() * std::abs(b.R.col(1).dot(L)) +
         b.e.z() * std::abs(b.R.col(2).dot(L));
}

// Tests unit axis L; returns false if it separates the boxes. d = b.c - a.c.
bool test_axis(const OrientedBox& a, const OrientedBox& b, const Vec3& d, const Vec3& L, int index,
               double margin, Axis& best) {
  const double dist = d.dot(L);
  const double separation = std::abs(dist) - (projected_radius(a, L) + projected_radius(b, L));
  if (separation > margin) return false;
  if (separation > best.separation) {
    best.separation = separation;
    best.index = index;
    best.n = dist >= 0.0 ? L : Vec3(-L);
  }
  return true;
}

using Polygon = std::array<Vec3, 16>;

// Keeps the part of polygon `in` (n_in vertices) with dot(m, x) <= offset. Returns the count.
int clip(const Polygon& in, int n_in, const Vec3& m, double offset, Polygon& out) {
  int n_out = 0;
  for (int i = 0; i < n_in; ++i) {
    const Vec3& prev = in[static_cast<std::size_t>((i + n_in - 1) % n_in)];
    const Vec3& cur = in[static_cast<std::size_t>(i)];
    const double d_prev = m.dot(prev) - offset;
    const double d_cur = m.dot(cur) - offset;
    if ((d_prev <= 0.0) != (d_cur <= 0.0)) {
      const double t = d_prev / (d_prev - d_cur);
      out[static_cast<std::size_t>(n_out++)] = prev + t * (cur - prev);
    }
    if (d_cur <= 0.0) out[static_cast<std::size_t>(n_out++)] = cur;
  }
  return n_out;
}

// Face contact with reference face `axis` of `ref` whose outward normal is n_ref (pointing at
// `inc`). normal_ab is the manifold normal from box a to box b.
void face_contact(const OrientedBox& ref, int axis, const Vec3& n_ref, const OrientedBox& inc,
                  const Vec3& normal_ab, double margin, Manifold& out) {
  // Incident face: the face of inc whose outward normal is most anti-parallel to n_ref.
  int k = 0;
  double best = -1.0;
  for (int c = 0; c < 3; ++c) {
    const double alignment = std::abs(inc.R.col(c).dot(n_ref));
    if (alignment > best) {
      best = alignment;
      k = c;
    }
  }
  const Vec3 inc_n = inc.R.col(k).dot(n_ref) > 0.0 ? Vec3(-inc.R.col(k)) : Vec3(inc.R.col(k));
  const Vec3 face_centre = inc.c + inc.e[k] * inc_n;
  const Vec3 u = inc.e[(k + 1) % 3] * inc.R.col((k + 1) % 3);
  const Vec3 v = inc.e[(k + 2) % 3] * inc.R.col((k + 2) % 3);
  Polygon poly{};
  poly[0] = face_centre + u + v;
  poly[1] = face_centre - u + v;
  poly[2] = face_centre - u - v;
  poly[3] = face_centre + u - v;
  int count = 4;

  // Side planes of the reference face.
  Polygon scratch{};
  for (int s : {(axis + 1) % 3, (axis + 2) % 3}) {
    for (double sign : {1.0, -1.0}) {
      const Vec3 m = sign * ref.R.col(s);
      count = clip(poly, count, m, m.dot(ref.c) + ref.e[s], scratch);
      poly = scratch;
      if (count == 0) return;
    }
  }

  const double ref_offset = n_ref.dot(ref.c) + ref.e[axis];
  for (int i = 0; i < count; ++i) {
    const Vec3& p = poly[static_cast<std::size_t>(i)];
    const double separation = n_ref.dot(p) - ref_offset;
    if (separation <= margin) out.add({p - 0.5 * separation * n_ref, normal_ab, -separation});
  }
}

// Closest points of segments p1 + s u1 (|s| <= h1) and p2 + t u2 (|t| <= h2), u1, u2 unit and
// not parallel (Ericson 2005, Sec. 5.1.9, clamped one parameter at a time).
void closest_points_of_edges(const Vec3& p1, const Vec3& u1, double h1, const Vec3& p2,
                             const Vec3& u2, double h2, Vec3& c1, Vec3& c2) {
  const Vec3 r = p1 - p2;
  const double b = u1.dot(u2);
  const double c = u1.dot(r);
  const double f = u2.dot(r);
  const double denom = 1.0 - b * b;
  double s = denom > 0.0 ? (b * f - c) / denom : 0.0;
  s = std::clamp(s, -h1, h1);
  double t = std::clamp(f + s * b, -h2, h2);
  s = std::clamp(t * b - c, -h1, h1);
  c1 = p1 + s * u1;
  c2 = p2 + t * u2;
}

void edge_contact(const OrientedBox& a, const OrientedBox& b, const Axis& axis, Manifold& out) {
  const int i = axis.index / 3;
  const int k = axis.index % 3;
  const Vec3& n = axis.n;
  // Supporting edge of a along +n and of b along -n.
  Vec3 pa = a.c;
  Vec3 pb = b.c;
  for (int m = 0; m < 3; ++m) {
    if (m != i) pa += (a.R.col(m).dot(n) > 0.0 ? 1.0 : -1.0) * a.e[m] * a.R.col(m);
    if (m != k) pb += (b.R.col(m).dot(n) > 0.0 ? -1.0 : 1.0) * b.e[m] * b.R.col(m);
  }
  Vec3 ca;
  Vec3 cb;
  closest_points_of_edges(pa, a.R.col(i), a.e[i], pb, b.R.col(k), b.e[k], ca, cb);
  out.add({0.5 * (ca + cb), n, -axis.separation});
}

}  // namespace

int collide_box_box(const OrientedBox& a, const OrientedBox& b, Manifold& out, double margin) {
  const int before = out.count;
  const Vec3 d = b.c - a.c;
  Axis face_a;
  Axis face_b;
  Axis edge;
  for (int i = 0; i < 3; ++i) {
    if (!test_axis(a, b, d, a.R.col(i), i, margin, face_a)) return 0;
  }
  for (int k = 0; k < 3; ++k) {
    if (!test_axis(a, b, d, b.R.col(k), k, margin, face_b)) return 0;
  }
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) {
      Vec3 L = a.R.col(i).cross(b.R.col(k));
      const double len = L.norm();
      if (len < kParallelSin) continue;
      if (!test_axis(a, b, d, L / len, 3 * i + k, margin, edge)) return 0;
    }
  }

  const double abs_tol = kAbsoluteTolerance * std::min(a.e.minCoeff(), b.e.minCoeff());
  const auto clearly_better = [abs_tol](double candidate, double current) {
    return candidate > current + (1.0 - kRelativeTolerance) * std::abs(current) + abs_tol;
  };
  const bool use_b = clearly_better(face_b.separation, face_a.separation);
  const Axis& face = use_b ? face_b : face_a;
  if (edge.index >= 0 && clearly_better(edge.separation, face.separation)) {
    edge_contact(a, b, edge, out);
  } else if (use_b) {
    face_contact(b, face_b.index, -face_b.n, a, face_b.n, margin, out);
  } else {
    face_contact(a, face_a.index, face_a.n, b, face_a.n, margin, out);
  }
  return out.count - before;
}

}  // namespace cps
