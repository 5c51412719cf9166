#include "cps/body.h"

#include <cmath>
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

void require_finite(const Vec3& v, const char* what) {
  if (!v.allFinite()) {
    throw std::invalid_argument(std::string(what) + " " + str(v) + " is not finite");
  }
}

}  // namespace

Shape Shape::box(const Vec3& h) {
  if (!h.allFinite() || (h.array() <= 0.0).any()) {
    throw std::invalid_argument("box half extents " + str(h) +
                                " must be finite and > 0 m in every component");
  }
  Shape s;
  s.kind = ShapeKind::box;
  s.half_extents = h;
  return s;
}

Shape Shape::sphere(double r) {
  if (!(std::isfinite(r) && r > 0.0)) {
    throw std::invalid_argument("sphere radius " + std::to_string(r) + " m must be finite and > 0");
  }
  Shape s;
  s.kind = ShapeKind::sphere;
  s.radius = r;
  return s;
}

Shape Shape::plane(const Vec3& n, double offset) {
  const double len = n.norm();
  if (!n.allFinite() || !(len > 0.0)) {
    throw std::invalid_argument("plane normal " + str(n) + " must be finite and non-zero");
  }
  if (!std::isfinite(offset)) {
    throw std::invalid_argument("plane offset " + std::to_string(offset) + " m must be finite");
  }
  Shape s;
  s.kind = ShapeKind::plane;
  s.normal = n / len;
  s.offset = offset;
  return s;
}

Mat3 Body::inv_inertia_world() const {
  if (is_static()) return Mat3::Zero();
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
  require_finite(def.position, "body position");
  require_finite(def.velocity, "body velocity");
  require_finite(def.angular_velocity, "body angular velocity");
  const double qn = def.orientation.norm();
  if (!std::isfinite(qn) || std::abs(qn - 1.0) > 1e-9) {
    throw std::invalid_argument("body orientation has norm " + std::to_string(qn) +
                                "; it must be a unit quaternion (norm 1 within 1e-9)");
  }
  if (!def.is_static && def.shape.kind == ShapeKind::plane) {
    throw std::invalid_argument("a plane must be a static body (set is_static)");
  }
  if (!def.is_static && !(std::isfinite(def.mass) && def.mass > 0.0)) {
    throw std::invalid_argument("body mass " + std::to_string(def.mass) +
                                " kg must be finite and > 0 for a movable body");
  }
  if (def.shape.kind == ShapeKind::box) Shape::box(def.shape.half_extents);  // validates
  if (def.shape.kind == ShapeKind::sphere) Shape::sphere(def.shape.radius);    // validates

  Body b;
  b.shape = def.shape;
  b.x = def.position;
  b.o = def.orientation.normalized();
  if (!def.is_static) {
    b.mass = def.mass;
    b.inv_mass = 1.0 / def.mass;
    const Mat3 I_body = shape_inertia(def.shape, def.mass);
    b.inv_inertia_body = I_body.inverse();
    b.p = def.mass * def.velocity;
    const Mat3 R = b.rotation();
    b.l = R * I_body * R.transpose() * def.angular_velocity;
  }
  return b;
}

}  // namespace cps
