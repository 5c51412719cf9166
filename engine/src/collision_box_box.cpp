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
#include <cstdint>

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

// A clipped polygon: its vertices, and for each the two lines it lies on (the edge into it and
// the edge out of it: 0..3 an incident-face edge, 4..7 a side plane of the reference face), from
// which its feature id is made.
struct Polygon {
  std::array<Vec3, 16> p;
  std::array<unsigned char, 16> in;
  std::array<unsigned char, 16> out;
};

// Keeps the part of polygon `in` (n_in vertices) with dot(m, x) <= offset (Sutherland-Hodgman).
// A vertex made where an edge crosses the plane lies on that edge and on the plane, `line`.
// Returns the count.
int clip(const Polygon& in, int n_in, const Vec3& m, double offset, unsigned char line,
         Polygon& out) {
  int n_out = 0;
  for (int i = 0; i < n_in; ++i) {
    const auto ip = static_cast<std::size_t>((i + n_in - 1) % n_in);
    const auto ic = static_cast<std::size_t>(i);
    const Vec3& prev = in.p[ip];
    const Vec3& cur = in.p[ic];
    const double d_prev = m.dot(prev) - offset;
    const double d_cur = m.dot(cur) - offset;
    if ((d_prev <= 0.0) != (d_cur <= 0.0)) {
      const double t = d_prev / (d_prev - d_cur);
      const auto k = static_cast<std::size_t>(n_out++);
      out.p[k] = prev + t * (cur - prev);
      const unsigned char edge = in.out[ip];  // the line from prev to cur
      // Leaving the kept side: along the edge, then the plane; entering: the other way round.
      out.in[k] = d_prev <= 0.0 ? edge : line;
      out.out[k] = d_prev <= 0.0 ? line : edge;
    }
    if (d_cur <= 0.0) {
      const auto k = static_cast<std::size_t>(n_out++);
      out.p[k] = cur;
      out.in[k] = in.in[ic];
      out.out[k] = in.out[ic];
    }
  }
  return n_out;
}

// Face index of a box's face with outward normal +-R.col(axis): 2 axis, +1 for the - side.
std::uint32_t face_index(int axis, bool negative) {
  return static_cast<std::uint32_t>(2 * axis + (negative ? 1 : 0));
}

// Face contact with reference face `axis` of `ref` whose outward normal is n_ref (pointing at
// `inc`). normal_ab is the manifold normal from box a to box b; kind says which box is `ref`.
void face_contact(const OrientedBox& ref, int axis, const Vec3& n_ref, const OrientedBox& inc,
                  const Vec3& normal_ab, double margin, ContactFeatureKind kind, Manifold& out) {
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
  const bool inc_negative = inc.R.col(k).dot(n_ref) > 0.0;
  const Vec3 inc_n = inc_negative ? Vec3(-inc.R.col(k)) : Vec3(inc.R.col(k));
  const Vec3 face_centre = inc.c + inc.e[k] * inc_n;
  const Vec3 u = inc.e[(k + 1) % 3] * inc.R.col((k + 1) % 3);
  const Vec3 v = inc.e[(k + 2) % 3] * inc.R.col((k + 2) % 3);
  Polygon poly{};
  poly.p[0] = face_centre + u + v;
  poly.p[1] = face_centre - u + v;
  poly.p[2] = face_centre - u - v;
  poly.p[3] = face_centre + u - v;
  for (unsigned char i = 0; i < 4; ++i) {
    poly.in[i] = static_cast<unsigned char>((i + 3) % 4);  // edge i joins vertex i to i + 1
    poly.out[i] = i;
  }
  int count = 4;

  // Side planes of the reference face, lines 4..7.
  Polygon scratch{};
  unsigned char line = 4;
  for (int s : {(axis + 1) % 3, (axis + 2) % 3}) {
    for (double sign : {1.0, -1.0}) {
      const Vec3 m = sign * ref.R.col(s);
      count = clip(poly, count, m, m.dot(ref.c) + ref.e[s], line++, scratch);
      poly = scratch;
      if (count == 0) return;
    }
  }

  const std::uint32_t faces =
      face_index(axis, n_ref.dot(ref.R.col(axis)) < 0.0) | (face_index(k, inc_negative) << 3);
  const double ref_offset = n_ref.dot(ref.c) + ref.e[axis];
  for (int i = 0; i < count; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    const Vec3& p = poly.p[ii];
    const double separation = n_ref.dot(p) - ref_offset;
    if (separation > margin) continue;
    const std::uint32_t lo = std::min(poly.in[ii], poly.out[ii]);
    const std::uint32_t hi = std::max(poly.in[ii], poly.out[ii]);
    out.add({p - 0.5 * separation * n_ref, normal_ab, -separation,
             contact_feature(kind, faces | (lo << 6) | (hi << 9))});
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
  // Edge ids (collision.h): 4 axis + 1 for the + side of the next axis + 2 for the one after.
  std::uint32_t edge_a = static_cast<std::uint32_t>(4 * i);
  std::uint32_t edge_b = static_cast<std::uint32_t>(4 * k);
  for (int m = 0; m < 3; ++m) {
    if (m != i) {
      const bool plus = a.R.col(m).dot(n) > 0.0;
      pa += (plus ? 1.0 : -1.0) * a.e[m] * a.R.col(m);
      if (plus) edge_a |= (m == (i + 1) % 3) ? 1u : 2u;
    }
    if (m != k) {
      const bool plus = !(b.R.col(m).dot(n) > 0.0);
      pb += (plus ? 1.0 : -1.0) * b.e[m] * b.R.col(m);
      if (plus) edge_b |= (m == (k + 1) % 3) ? 1u : 2u;
    }
  }
  Vec3 ca;
  Vec3 cb;
  closest_points_of_edges(pa, a.R.col(i), a.e[i], pb, b.R.col(k), b.e[k], ca, cb);
  out.add({0.5 * (ca + cb), n, -axis.separation,
           contact_feature(kFeatureEdges, edge_a | (edge_b << 4))});
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
    face_contact(b, face_b.index, -face_b.n, a, face_b.n, margin, kFeatureFaceB, out);
  } else {
    face_contact(a, face_a.index, face_a.n, b, face_a.n, margin, kFeatureFaceA, out);
  }
  return out.count - before;
}

}  // namespace cps
