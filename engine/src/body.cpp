#include "cps/body.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace cps {
namespace {

std::string str(const Vec3& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// x finite and in [lo, hi] (isfinite first: no floating point exception on NaN).
bool in_range(double x, double lo, double hi) { return std::isfinite(x) && x >= lo && x <= hi; }

void require_within(const Vec3& v, double limit, const char* what, const char* unit) {
  for (int k = 0; k < 3; ++k) {
    if (!in_range(v[k], -limit, limit)) {
      throw std::invalid_argument(std::string(what) + " " + str(v) + " " + unit +
                                  " is not allowed: each component must be finite and within +-" +
                                  num(limit) + " " + unit);
    }
  }
}

}  // namespace

Shape Shape::box(const Vec3& h) {
  for (int k = 0; k < 3; ++k) {
    if (!in_range(h[k], kMinSize, kMaxSize)) {
      throw std::invalid_argument("box half extents " + str(h) + " m are not allowed: each must be in [" +
                                  num(kMinSize) + ", " + num(kMaxSize) + "] m");
    }
  }
  Shape s;
  s.kind = ShapeKind::box;
  s.half_extents = h;
  return s;
}

Shape Shape::sphere(double r) {
  if (!in_range(r, kMinSize, kMaxSize)) {
    throw std::invalid_argument("sphere radius " + num(r) + " m is not allowed: it must be in [" +
                                num(kMinSize) + ", " + num(kMaxSize) + "] m");
  }
  Shape s;
  s.kind = ShapeKind::sphere;
  s.radius = r;
  return s;
}

Shape Shape::plane(const Vec3& n, double offset) {
  const double len = n.norm();
  if (!all_finite(n) || !(len > 0.0)) {
    throw std::invalid_argument("plane normal " + str(n) + " must be finite and non-zero");
  }
  if (!in_range(offset, -kMaxCoordinate, kMaxCoordinate)) {
    throw std::invalid_argument("plane offset " + num(offset) + " m is not allowed: it must be within +-" +
                                num(kMaxCoordinate) + " m");
  }
  Shape s;
  s.kind = ShapeKind::plane;
  s.normal = n / len;
  s.offset = offset;
  return s;
}

Mat3 Body::inv_inertia_world() const {
  if (is_static()) return Mat3::Zero();
  // An isotropic tensor (c times the identity: a sphere, a cube) is the same in every frame,
  // R c R^T = c: returned as it is, without the rounding of the two products.
  const Mat3& t = inv_inertia_body;
  if (t(0, 0) == t(1, 1) && t(1, 1) == t(2, 2) && t(0, 1) == 0.0 && t(0, 2) == 0.0 &&
      t(1, 0) == 0.0 && t(1, 2) == 0.0 && t(2, 0) == 0.0 && t(2, 1) == 0.0) {
    return t;
  }
  const Mat3 R = rotation();
  return R * inv_inertia_body * R.transpose();
}

double Body::kinetic_energy() const { return 0.5 * (p.dot(velocity()) + l.dot(angular_velocity())); }

Mat3 box_inertia(double mass, const Vec3& h) {
  const Vec3 s = h.cwiseProduct(h);
  return (mass / 3.0) * Vec3(s.y() + s.z(), s.x() + s.z(), s.x() + s.y()).asDiagonal();
}

Mat3 sphere_inertia(double mass, double radius) {
  return Mat3::Identity() * (0.4 * mass * radius * radius);
}

Mat3 shape_inertia(const Shape& shape, double mass) {
  switch (shape.kind) {
    case ShapeKind::box:
      return box_inertia(mass, shape.half_extents);
    case ShapeKind::sphere:
      return sphere_inertia(mass, shape.radius);
    case ShapeKind::plane:
      break;
  }
  throw std::invalid_argument("a plane has no inertia: it must be a static body");
}

Body make_body(const BodyDef& def) {
  require_within(def.position, kMaxCoordinate, "body position", "m");
  require_within(def.velocity, kMaxSpeed, "body velocity", "m/s");
  require_within(def.angular_velocity, kMaxSpin, "body angular velocity", "rad/s");
  const double qn = def.orientation.norm();
  if (!std::isfinite(qn) || std::abs(qn - 1.0) > 1e-9) {
    throw std::invalid_argument("body orientation has norm " + num(qn) +
                                "; it must be a unit quaternion (norm 1 within 1e-9)");
  }
  if (!def.is_static && def.shape.kind == ShapeKind::plane) {
    throw std::invalid_argument("a plane must be a static body (set is_static)");
  }
  if (!def.is_static && !in_range(def.mass, kMinMass, kMaxMass)) {
    throw std::invalid_argument("body mass " + num(def.mass) + " kg is not allowed: a movable body's mass must be in [" +
                                num(kMinMass) + ", " + num(kMaxMass) + "] kg");
  }
  if (def.shape.kind == ShapeKind::box) Shape::box(def.shape.half_extents);  // validates
  if (def.shape.kind == ShapeKind::sphere) Shape::sphere(def.shape.radius);    // validates

  if (!std::isnan(def.restitution) && !in_range(def.restitution, 0.0, 1.0)) {
    throw std::invalid_argument("body restitution " + num(def.restitution) +
                                " is not allowed: it must be in [0, 1] (or NaN for the world's)");
  }

  if (!std::isnan(def.friction) && !in_range(def.friction, 0.0, 1.0e6)) {
    throw std::invalid_argument("body friction " + num(def.friction) +
                                " is not allowed: it must be in [0, 1e6] (or NaN for the world's)");
  }

  Body b;
  b.shape = def.shape;
  b.restitution = def.restitution;
  b.friction = def.friction;
  b.x = def.position;
  b.o = def.orientation.normalized();
  if (!def.is_static) {
    b.mass = def.mass;
    b.inv_mass = 1.0 / def.mass;
    const Mat3 I_body = shape_inertia(def.shape, def.mass);
    // The tensor is diagonal: invertible in double precision iff each entry is a normal number
    // whose reciprocal is finite.
    const bool invertible = all_finite(I_body) &&
                            I_body.diagonal().minCoeff() >= std::numeric_limits<double>::min();
    if (invertible) b.inv_inertia_body = I_body.diagonal().cwiseInverse().asDiagonal();
    if (!invertible || !all_finite(b.inv_inertia_body)) {
      throw std::invalid_argument("body of mass " + num(def.mass) +
                                  " kg and this size has an inertia tensor that is zero or not "
                                  "finite in double precision; use a mass and size nearer 1");
    }
    b.p = def.mass * def.velocity;
    const Mat3 R = b.rotation();
    b.l = R * I_body * R.transpose() * def.angular_velocity;
  }
  return b;
}

}  // namespace cps
