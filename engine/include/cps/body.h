#pragma once
// Rigid bodies (paper Sec. 3.1) and their shapes.

#include "cps/math.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cps {

/// The ranges a body may be built in, chosen so that a step stays finite: with dt <= 1 s and
/// |g| <= 1e4 m/s^2 (the world parameter table) momenta, positions and the inertia tensor stay
/// far from overflow and underflow for any run of bounded length. Every one is refused with a
/// message naming the value and the range.
inline constexpr double kMinMass = 1e-6;      ///< kg: a movable body's smallest mass
inline constexpr double kMaxMass = 1e9;       ///< kg: its largest
inline constexpr double kMinSize = 1e-4;      ///< m: smallest box half extent or sphere radius
inline constexpr double kMaxSize = 1e5;       ///< m: largest
inline constexpr double kMaxCoordinate = 1e9; ///< m: largest |component| of a position, plane offset
inline constexpr double kMaxSpeed = 1e5;      ///< m/s: largest |component| of a velocity
inline constexpr double kMaxSpin = 1e5;       ///< rad/s: largest |component| of an angular velocity

/// The kinds of collision shape.
enum class ShapeKind {
  box,     ///< a cuboid given by its half extents
  sphere,  ///< a ball given by its radius
  plane,   ///< an infinite half space; static bodies only
};

/// A collision shape in body space.
/// - box: half_extents (m), each in [kMinSize, kMaxSize].
/// - sphere: radius (m) in [kMinSize, kMaxSize], centred on the body origin.
/// - plane: the half space {x : dot(normal, x) <= offset} of body space is solid; normal is a
///   unit 3-vector pointing out of the solid to the free side, offset in m.
/// Build one with Shape::box, Shape::sphere or Shape::plane, which validate their input.
struct Shape {
  ShapeKind kind = ShapeKind::box;
  Vec3 half_extents = Vec3::Constant(0.5);
  double radius = 0.5;
  Vec3 normal = Vec3::UnitY();
  double offset = 0.0;

  /// A box of half extents h (m, 3-vector). Throws std::invalid_argument naming the value if any
  /// component is outside [kMinSize, kMaxSize].
  static Shape box(const Vec3& h);
  /// A sphere of radius r (m). Throws std::invalid_argument naming the value unless it is in
  /// [kMinSize, kMaxSize].
  static Shape sphere(double r);
  /// A plane with outward normal n (any non-zero finite 3-vector; it is normalised) at signed
  /// distance offset (m) from the body origin along n. Throws std::invalid_argument on a zero or
  /// non-finite normal or an offset with |offset| > kMaxCoordinate.
  static Shape plane(const Vec3& n, double offset);
};

/// The coefficient of restitution eps (dimensionless, in [0, 1]) of a contact between bodies a
/// and b (Eq. 8.2.1 takes one eps): the larger of the two bodies' own, a body without its own
/// (NaN) taking `world` (WorldDef::restitution). The larger, as Box2D v3 mixes restitution, so
/// that a bouncy ball bounces on a dead floor; two bodies without their own give `world` exactly.
/// No errors.
inline double pair_restitution(double world, double a, double b) {
  return std::max(std::isnan(a) ? world : a, std::isnan(b) ? world : b);
}

/// The friction coefficient mu (dimensionless, >= 0) of a contact between bodies a and b (Sec.
/// 5.4 takes one mu): the geometric mean sqrt(mu_a mu_b) of the two bodies' own, a body without
/// its own (NaN) taking `world` (WorldDef::friction), as Box2D v3 mixes friction, so that an icy
/// body (0) slides on anything; two bodies without their own give `world` exactly. No errors.
inline double pair_friction(double world, double a, double b) {
  if (std::isnan(a) && std::isnan(b)) return world;
  return std::sqrt((std::isnan(a) ? world : a) * (std::isnan(b) ? world : b));
}

/// What a body is made from. mass (kg): finite and > 0 for a movable body; ignored when
/// is_static. position (m), orientation (unit quaternion, body to world; |o| within 1e-9 of 1),
/// velocity (m/s) and angular_velocity (rad/s) are the initial state, all in world space.
/// restitution: the body's own coefficient of restitution eps (dimensionless, in [0, 1]; typical
/// 0.5 for a ball), or NaN, the default, for the world's (WorldDef::restitution); see
/// pair_restitution. friction: the body's own friction coefficient mu (dimensionless, in
/// [0, 1e6]; typical 0.1 for ice, 1 for rubber), or NaN, the default, for the world's
/// (WorldDef::friction); see pair_friction.
struct BodyDef {
  Shape shape;
  bool is_static = false;
  double mass = 1.0;
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();
  Vec3 velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();
  double restitution = std::numeric_limits<double>::quiet_NaN();
  double friction = std::numeric_limits<double>::quiet_NaN();
};

/// A rigid body as the paper keeps it (Sec. 3.1): position x (m), orientation o (unit
/// quaternion), linear momentum p = m v (N s), angular momentum l = I w (N m s), inverse mass
/// m^-1 (1/kg) and body-space inverse inertia I_body^-1 (1/(kg m^2), 3 x 3). Static bodies have
/// m^-1 = 0 and I^-1 = 0.
struct Body {
  Shape shape;
  Vec3 x = Vec3::Zero();
  Quat o = Quat::Identity();
  Vec3 p = Vec3::Zero();
  Vec3 l = Vec3::Zero();
  double mass = 0.0;      ///< kg; 0 for a static body
  double inv_mass = 0.0;  ///< 1/kg
  Mat3 inv_inertia_body = Mat3::Zero();
  /// Its own coefficient of restitution (BodyDef::restitution): in [0, 1], or NaN for the world's.
  double restitution = std::numeric_limits<double>::quiet_NaN();
  /// Its own friction coefficient (BodyDef::friction): in [0, 1e6], or NaN for the world's.
  double friction = std::numeric_limits<double>::quiet_NaN();

  bool is_static() const { return inv_mass == 0.0; }
  /// Rotation matrix R of o (3 x 3, body to world).
  Mat3 rotation() const { return o.toRotationMatrix(); }
  /// World-space inverse inertia I^-1 = R I_body^-1 R^T (1/(kg m^2), 3 x 3). An isotropic
  /// I_body^-1 (c times the identity: a sphere, a cube) is returned as it is, since R c R^T = c.
  Mat3 inv_inertia_world() const;
  /// Linear velocity v = m^-1 p (m/s).
  Vec3 velocity() const { return inv_mass * p; }
  /// Angular velocity w = I^-1 l (rad/s).
  Vec3 angular_velocity() const { return inv_inertia_world() * l; }
  /// Kinetic energy 1/2 (p.v + l.w) (J).
  double kinetic_energy() const;
};

/// Body-space inertia tensor (kg m^2, 3 x 3) of a solid box of the given mass (kg) and half
/// extents (m): I = m/3 diag(hy^2 + hz^2, hx^2 + hz^2, hx^2 + hy^2).
Mat3 box_inertia(double mass, const Vec3& half_extents);

/// Body-space inertia tensor (kg m^2, 3 x 3) of a solid ball: I = 2/5 m r^2 D.
Mat3 sphere_inertia(double mass, double radius);

/// Body-space inertia tensor (kg m^2, 3 x 3) of a movable body of the given shape and mass (kg).
Mat3 shape_inertia(const Shape& shape, double mass);

/// Builds a Body from a definition. Throws std::invalid_argument naming the bad value and the
/// allowed range for a movable body's mass outside [kMinMass, kMaxMass], a movable plane, a shape
/// outside its range (Shape), a position component beyond kMaxCoordinate, a velocity component
/// beyond kMaxSpeed, an angular velocity component beyond kMaxSpin (all also when not finite), or
/// an orientation whose norm differs from 1 by more than 1e-9.
Body make_body(const BodyDef& def);

}  // namespace cps
