#pragma once
// Collision detection (paper Sec. 4): detect whether two bodies touch and build their contact
// manifold. Box-box uses the separating axis test over 15 axes; a face contact clips the
// incident face against the side planes of the reference face, an edge contact takes the
// closest points of the two edges (as in Ericson, "Real-Time Collision Detection", 2005,
// Sec. 4.4 and 5.1.9, and Gregorius, "The Separating Axis Test", GDC 2013).

#include "cps/body.h"

#include <array>
#include <cstdint>

namespace cps {

/// Contact feature ids: which features of the two shapes a contact point comes from, so that a
/// point of the next step can be recognised as the same contact while the bodies stay in
/// contact (the idea of Box2D's b2ContactFeature; Catto, "Iterative Dynamics with Temporal
/// Coherence", GDC 2005, on matching contacts by feature for warm starting). An id is unique
/// within a manifold and says nothing across body pairs. 32 bits: the kind in bits 28..31, then
/// per kind:
/// - kFeatureSphere: 0. A sphere's contact with a plane, a sphere or a box is one point.
/// - kFeatureBoxVertex: bits 0..2, the box vertex below the plane (bit k set: the vertex on the
///   +e_k side of box axis k).
/// - kFeatureFaceA, kFeatureFaceB: a face contact of box-box, with the reference face on the
///   first (A) or the second (B) box of collide_box_box. Bits 0..2: the reference face, bits
///   3..5: the incident face of the other box (face = 2 axis + 1 if its outward normal is -axis,
///   0 if +axis). Bits 6..8 and 9..11: the two lines the clipped point lies on, the smaller
///   first: 0..3 the incident face's edges, 4..7 the reference face's side planes. A vertex of
///   the incident face is its two edges; a clipped point is an edge and a side plane; a corner
///   of the reference face inside the incident face is two side planes.
/// - kFeatureEdges: edge-edge. Bits 0..3: the edge of the first box, bits 4..7: the edge of the
///   second (edge = 4 axis + 1 if it lies on the + side of the next axis + 2 if on the + side of
///   the one after).
enum ContactFeatureKind : std::uint32_t {
  kFeatureSphere = 1,
  kFeatureBoxVertex = 2,
  kFeatureFaceA = 3,
  kFeatureFaceB = 4,
  kFeatureEdges = 5,
};

/// The id of kind `kind` with the fields `bits` (bits 0..27, see ContactFeatureKind).
constexpr std::uint32_t contact_feature(ContactFeatureKind kind, std::uint32_t bits) {
  return (static_cast<std::uint32_t>(kind) << 28) | (bits & 0x0FFFFFFFu);
}

/// The kind of a feature id.
constexpr ContactFeatureKind contact_feature_kind(std::uint32_t feature) {
  return static_cast<ContactFeatureKind>(feature >> 28);
}

/// One contact point. normal: unit 3-vector from body a to body b (the direction along which
/// b must move to separate). depth: penetration along the normal (m); negative for a
/// speculative contact, where -depth is the gap (less than the collision margin). point: world
/// position (m), midway between the two surfaces; in a recycled manifold, body a's anchor
/// (Manifold::anchor_shift). feature: which features of the two shapes it
/// comes from (ContactFeatureKind); a contact of the next step with the same body pair and the
/// same feature is the same contact.
struct Contact {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();
  double depth = 0.0;
  std::uint32_t feature = 0;
};

struct Manifold;

/// Contact c of manifold m as body b holds it: world position (m). No errors.
inline Vec3 point_on_b(const Manifold& m, const Contact& c);

/// Most points a manifold holds: clipping a quadrilateral against four planes leaves at most 8.
inline constexpr int kMaxManifoldPoints = 8;

/// The contacts between bodies a and b (indices into the world's body list, a < b), all with the
/// same normal. Fixed capacity, so collision detection does not allocate.
struct Manifold {
  int body_a = -1;
  int body_b = -1;
  int count = 0;
  std::array<Contact, kMaxManifoldPoints> contacts{};
  /// m: where body b holds the points, relative to `point`: 0 for a manifold the narrow phase
  /// made; in a recycled one (contact_recycling.h) both bodies keep the anchors of its making
  /// (world vectors from their centres) while their centres move apart by this.
  Vec3 anchor_shift = Vec3::Zero();

  void add(const Contact& c) {
    if (count < kMaxManifoldPoints) contacts[static_cast<std::size_t>(count++)] = c;
  }
};

inline Vec3 point_on_b(const Manifold& m, const Contact& c) { return c.point + m.anchor_shift; }

/// Tests bodies a and b and writes their contacts into `out` (out.count = 0 when they are
/// further apart than `margin`). Normals point from a to b. Returns out.count. margin (m, >= 0):
/// the speculative distance; features closer than it give a contact with negative depth (0: only
/// overlapping features, as in the paper). Pairs of two planes, and pairs of static bodies, give
/// no contact. No errors are raised. Every collide_* function below takes the same margin.
int collide(const Body& a, const Body& b, Manifold& out, double margin = 0.0);

/// collide() with the rotation matrices of the bodies given: R_a = a.rotation(), R_b =
/// b.rotation() (3 x 3, body to world), for a caller that has them already (the world computes
/// them once per step for its bounds). Same result as collide(a, b, out, margin).
int collide(const Body& a, const Mat3& R_a, const Body& b, const Mat3& R_b, Manifold& out,
            double margin = 0.0);

/// Reduces a manifold of more than 4 points to 4 of them (fewer when the rest add nothing), the
/// way Box3D reduces its manifolds (erincatto/box3d src/convex_manifold.c, b3ReduceManifoldPoints;
/// the largest-area idea of Bullet's btPersistentManifold::sortCachedPoints): first the point
/// with the largest depth plus its offset (m) along a fixed direction across the normal (an
/// extreme point, the deeper the likelier); then the one farthest from it
/// across the normal (depth counting twice); then the one that spans the largest triangle with
/// the two; then the one that adds the most area outside that triangle. A later candidate
/// replaces the best so far only when its score is 5 % better, so that the choice holds from step
/// to step while the bodies barely move (Box3D's 0.95 bias). A candidate adds nothing, and the
/// reduction stops, when its distance squared or its area (m^2) is below tolerance^2 (tolerance
/// in m, >= 0; Box3D's is its speculative distance, 0.02 m). The kept points keep their normal,
/// depth and feature id. A point whose score is not a number is never chosen (a manifold where
/// no point has one is left as it is), and a manifold of at most 4 points is left as it is. No
/// errors.
void reduce_manifold(Manifold& m, double tolerance);

/// A box in world space: centre c (m), rotation R (3 x 3, columns are the box axes in world
/// space), half extents e (m).
struct OrientedBox {
  Vec3 c;
  Mat3 R;
  Vec3 e;
};

/// Box-plane contacts: every vertex of `box` below the plane {x : dot(n, x) = offset} (n unit,
/// offset in m), with normal n (from plane to box) and depth offset - dot(n, v). Returns the
/// number of contacts written to `out` (0..8), each with the feature id of its vertex
/// (kFeatureBoxVertex). The caller flips normals if the box is body a.
int collide_box_plane(const OrientedBox& box, const Vec3& n, double offset, Manifold& out,
                      double margin = 0.0);

/// Box-box contacts by the separating axis test over the 15 axes (3 face normals of each box and
/// the 9 cross products of their edge directions). Normals point from box a to box b. Returns
/// the number of contacts written to `out` (0 when a separating axis exists). Feature ids:
/// kFeatureFaceA or kFeatureFaceB (reference face, incident face and the clipped point's two
/// lines) for a face contact, kFeatureEdges (the two edges) for an edge contact.
int collide_box_box(const OrientedBox& a, const OrientedBox& b, Manifold& out,
                    double margin = 0.0);

/// Sphere-plane contact: sphere of centre c (m) and radius r (m) against the plane
/// {x : dot(n, x) = offset}; normal n (from plane to sphere), depth r - (dot(n, c) - offset).
/// Returns 0 or 1 contacts written to `out` (feature kFeatureSphere).
int collide_sphere_plane(const Vec3& c, double r, const Vec3& n, double offset, Manifold& out,
                         double margin = 0.0);

/// Sphere-sphere contact between spheres (c_a, r_a) and (c_b, r_b) (m); normal from a to b,
/// depth r_a + r_b - |c_b - c_a|. Coincident centres (closer than 1e-12 m) get the normal +y,
/// so the pair still separates. Returns 0 or 1 contacts written to `out` (feature kFeatureSphere).
int collide_sphere_sphere(const Vec3& c_a, double r_a, const Vec3& c_b, double r_b, Manifold& out,
                          double margin = 0.0);

/// Box-sphere contact by the closest point of the box to the sphere centre c (m), radius r (m)
/// (Ericson 2005, Sec. 5.1.4). Normal from the box to the sphere. A centre inside the box is
/// pushed out through the face it is nearest to (depth = distance to that face + r). Returns 0
/// or 1 contacts written to `out` (feature kFeatureSphere).
int collide_box_sphere(const OrientedBox& box, const Vec3& c, double r, Manifold& out,
                       double margin = 0.0);

}  // namespace cps
