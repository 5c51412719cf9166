#pragma once
// Constraint rows (paper Sec. 5). Each row is j (12 numbers: linear and angular part for body a,
// then for body b), a target velocity v (the push factor and any other bias, m/s) and force
// limits [c_min, c_max] (N). With a unit axis (Sec. 9.2; docs/conventions.md) lambda is in
// newtons.

#include "cps/collision.h"

#include <optional>
#include <vector>

namespace cps {

/// What a row constrains.
enum class RowKind {
  contact,   ///< Sec. 5.3: non-penetration along the contact normal
  friction,  ///< Sec. 5.4: no sliding along a tangent
  distance,  ///< Sec. 5.2: two points at a fixed distance (a rod)
};

/// Body index that stands for the static world (a fixed point) in a row or distance constraint.
inline constexpr int kWorldBody = -1;

/// One row of J with its right-hand side terms.
/// - j: 12-vector [-n, -(r_a x n), n, r_b x n] for a unit axis n (no unit / m).
/// - push: the Baumgarte part of the target velocity, beta d / dt for a contact (m/s, Eq. 5.3.1);
///   the single frame push factor (Sec. 8.1) drops it from the second solve.
/// - bias: the part of the target velocity that must add velocity, e.g. restitution (m/s,
///   Eq. 8.2.1); kept in both solves. Target v = push + bias.
/// - c_min, c_max: force limits (N), c_min <= 0 <= c_max, possibly infinite.
/// - normal_row: for a friction row, the index of its contact row (for the coupled friction
///   limit mu lambda_n); -1 otherwise.
/// - mu: for a friction row, the friction coefficient (dimensionless).
/// - restitution: for a contact row that bounces (Eq. 8.2.1), its target -eps j . v1 (m/s), also
///   in bias; 0 otherwise. The soft step (engine/src/push/soft_step.cpp) recomputes every target each substep and
///   applies this one at the end of the step, as Box2D v3 does.
/// body_a or body_b may be kWorldBody (a fixed world point): that half of j then acts on nothing.
struct ConstraintRow {
  RowKind kind = RowKind::contact;
  int body_a = -1;
  int body_b = -1;
  Vec12 j = Vec12::Zero();
  double push = 0.0;
  double bias = 0.0;
  double restitution = 0.0;
  double c_min = -kInfinity;
  double c_max = kInfinity;
  int normal_row = -1;
  double mu = 0.0;
};

/// The 12-vector j = [-n, -(r_a x n), n, r_b x n] of a row along unit axis n between the points
/// at offsets r_a, r_b (m) from the centres of mass of bodies a and b (Eq. 5.2.1 with a unit axis,
/// Sec. 9.2). j . v_ab is the rate (m/s) at which the points separate along n.
Vec12 axis_row(const Vec3& n, const Vec3& r_a, const Vec3& r_b);

/// Two unit tangents t1, t2 with (n, t1, t2) a right-handed orthonormal basis; n must be unit.
/// Deterministic: depends on n only.
void tangent_basis(const Vec3& n, Vec3& t1, Vec3& t2);

/// Parameters of the row builder. beta: push factor constant (dimensionless, [0, 1], typical
/// 0.2); dt: time step (s); friction: the world's coefficient mu (dimensionless, >= 0, typical
/// 0.5; 0 builds no friction rows unless body_friction); gravity: (m/s^2) for the friction limit mu m |g . n|; restitution:
/// coefficient eps (dimensionless, [0, 1], typical 0 to 0.5); restitution_threshold: approach
/// speed (m/s, >= 0, typical 1) below which a contact gets no restitution, so resting contacts
/// do not bounce.
struct RowParams {
  double beta = 0.2;
  double dt = 1.0 / 60.0;
  double friction = 0.5;
  Vec3 gravity = Vec3(0.0, -10.0, 0.0);
  double restitution = 0.0;
  double restitution_threshold = 1.0;
  double penetration_slop = 0.0;  ///< m, >= 0: depth the push leaves (WorldDef::penetration_slop)
  /// Some body has its own friction coefficient (Body::friction): friction rows are built even
  /// when `friction` (the world's) is 0, each with its pair's mu (pair_friction).
  bool body_friction = false;
  /// m: contacts no deeper than this keep their push in the velocity solve (it is moved into
  /// bias). The split impulse (engine/src/push/split_impulse.cpp) sets it to WorldDef::split_impulse_threshold;
  /// -inf (the default) moves nothing.
  double velocity_push_depth = -kInfinity;
};

/// Appends the rows of one manifold to `rows`: first its contact rows, one per point in point
/// order (append_normal_rows), then its friction rows, two per point in point order
/// (append_friction_rows, only when friction > 0). A world step puts the contact rows of every
/// manifold before the friction rows of any (World::step); for a single manifold the order is
/// the same.
void append_contact_rows(const Manifold& m, const std::vector<Body>& bodies,
                         const RowParams& params, std::vector<ConstraintRow>& rows);

/// A body's velocities in world space: linear v = m^-1 p (m/s) and angular w = I^-1 l (rad/s)
/// with I^-1 = R I_body^-1 R^T (Sec. 3.1), as Body::velocity and Body::angular_velocity give.
struct BodyVelocity {
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();
};

/// BodyVelocity of one body (the same numbers as b.velocity(), b.angular_velocity()).
BodyVelocity body_velocity(const Body& b);

/// The same rows as append_contact_rows above, with the two bodies' velocities given (v_a of
/// body m.body_a, v_b of body m.body_b), so that a step that builds many manifolds per body
/// computes each body's I^-1 once instead of once per manifold.
void append_contact_rows(const Manifold& m, const std::vector<Body>& bodies,
                         const BodyVelocity& v_a, const BodyVelocity& v_b,
                         const RowParams& params, std::vector<ConstraintRow>& rows);

/// Appends one contact row per point of m (Sec. 5.3), in point order: j about the normal n (from
/// a to b), c_min = 0, c_max = +inf, push = beta d / dt for a depth d >= 0 (Eq. 5.3.1); for a
/// speculative contact (d < 0) instead bias = d / dt (m/s), which lets the points close the gap
/// within the step and no further. With restitution > 0 a contact whose points approach faster
/// than the threshold (j . v1 < -threshold) and touch or close their gap within the step gets
/// the bias v_r = -eps j . v1 instead (Eq. 8.2.1). v_a, v_b: the velocities of m.body_a and
/// m.body_b (m/s, rad/s). No errors.
void append_normal_rows(const Manifold& m, const std::vector<Body>& bodies,
                        const BodyVelocity& v_a, const BodyVelocity& v_b,
                        const RowParams& params, std::vector<ConstraintRow>& rows);

/// The rows of append_normal_rows written to out[0, m.count) instead (each row replaced whole),
/// so that threads may build the rows of different manifolds into one vector. No errors.
void write_normal_rows(const Manifold& m, const std::vector<Body>& bodies,
                       const BodyVelocity& v_a, const BodyVelocity& v_b,
                       const RowParams& params, ConstraintRow* out);

/// The restitution target v_r = -eps j . v1 (m/s, Eq. 8.2.1) of contact c with row j (its
/// contact row's j: axis_row of c's normal and its offsets from the two centres of mass), when
/// its points approach faster than `threshold` (j . v1 < -threshold, m/s) and touch or close
/// their gap within the step (j . v1 dt <= min(d, 0), dt in s); none otherwise. eps: the pair's
/// coefficient (pair_restitution, dimensionless, [0, 1]); v_a, v_b: the two bodies' velocities.
/// No errors.
std::optional<double> restitution_target(const Vec12& j, const Contact& c, const BodyVelocity& v_a,
                                         const BodyVelocity& v_b, double eps, double threshold, double dt);

/// The friction rows' limit mu m |g . n| (N, Sec. 5.4) on a manifold of `points` (>= 1) points
/// between bodies a and b with normal n: m (kg) the two bodies' mass shared equally over the
/// points (a static body counts 0), mu the pair's (dimensionless), gravity in m/s^2. No errors.
double friction_limit(double mu, const Body& a, const Body& b, int points, const Vec3& gravity, const Vec3& n);

/// Appends two friction rows per point of m (Sec. 5.4), in point order, along t1 and t2 of
/// tangent_basis(n): target 0, limits +-mu m |g . n| (N), mu the pair's (pair_friction of
/// params.friction and the two bodies' own), where m (kg) is the combined mass of
/// the two bodies divided over the manifold's points (the movable body's mass when the other is
/// static). normal_row of point i's rows is first_normal_row + i: the index in `rows` of that
/// point's contact row (append_normal_rows), for the coupled limit mu lambda_n. Appends nothing
/// when params.friction is 0 and params.body_friction is false. tangents: nullptr (the paper's directions), or m.count unit
/// vectors t1 perpendicular to each point's normal, with t2 = n x t1 (the warm start keeps a
/// persisting contact's directions so its friction lambdas carry over). No errors.
void append_friction_rows(const Manifold& m, const std::vector<Body>& bodies,
                          const RowParams& params, int first_normal_row,
                          std::vector<ConstraintRow>& rows, const Vec3* tangents = nullptr);

/// The rows of append_friction_rows written to out[0, 2 m.count) instead (each row replaced
/// whole; nothing when append_friction_rows appends nothing). No errors.
void write_friction_rows(const Manifold& m, const std::vector<Body>& bodies,
                         const RowParams& params, int first_normal_row, ConstraintRow* out,
                         const Vec3* tangents = nullptr);

/// A distance constraint (Sec. 5.2): point local_a of body_a and point local_b of body_b stay
/// `length` apart (m, >= 0). local_a, local_b are in body space (m); when body_b is kWorldBody,
/// local_b is a fixed world point (m). The row is unbounded (c_min = -inf, c_max = +inf).
/// collide: whether body_a and body_b still get contacts with each other (true, the paper's);
/// false leaves the pair out of the broad phase, as joined bodies are in the AVBD 3D demo and in
/// most engines (no effect with the world).
struct DistanceConstraint {
  int body_a = 0;
  Vec3 local_a = Vec3::Zero();
  int body_b = kWorldBody;
  Vec3 local_b = Vec3::Zero();
  double length = 1.0;
  bool collide = true;
};

/// World positions (m) of the two end points of a distance constraint.
void distance_endpoints(const DistanceConstraint& d, const std::vector<Body>& bodies, Vec3& p_a,
                        Vec3& p_b);

/// Appends the row of one distance constraint: unit axis n = (p_b - p_a) / |p_b - p_a| (Sec. 9.2;
/// +y if the points coincide), j = [-n, -(r_a x n), n, r_b x n] and, with C = |p_b - p_a| - l
/// (m), push = -beta C / dt (docs/conventions.md, Sec. 3: a stretched rod gets a negative target
/// and shrinks; Eq. 5.2.3 prints the opposite sign).
void append_distance_row(const DistanceConstraint& d, const std::vector<Body>& bodies,
                         const RowParams& params, std::vector<ConstraintRow>& rows);

}  // namespace cps
