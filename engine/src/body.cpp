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

void require_finite(const Vec3& v, const char* what) {
  if (!all_finite(v)) {
    throw std::invalid_argument(std::string(what) + " " + str(v) + " is not finite");
  }
}

}  // namespace

Shape Shape::box(const Vec3& h) {
  if (!all_finite(h) || (h.array() <= 0.0).any()) {
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
    throw std::invalid_argument("sphere radius " + num(r) + " m must be finite and > 0");
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
  if (!std::isfinite(offset)) {
    throw std::invalid_argument("plane offset " + num(offset) + " m must be finite");
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
  require_finite(def.position, "body position");
  require_finite(def.velocity, "body velocity");
  require_finite(def.angular_velocity, "body angular velocity");
  const double qn = def.orientation.norm();
  if (!std::isfinite(qn) || std::abs(qn - 1.0) > 1e-9) {
    throw std::invalid_argument("body orientation has norm " + num(qn) +
                                "; it must be a unit quaternion (norm 1 within 1e-9)");
  }
  if (!def.is_static && def.shape.kind == ShapeKind::plane) {
    throw std::invalid_argument("a plane must be a static body (set is_static)");
  }
  // A normal double, so that 1 / m is finite.
  if (!def.is_static && !(std::isfinite(def.mass) && def.mass >= std::numeric_limits<double>::min())) {
    throw std::invalid_argument("body mass " + num(def.mass) +
                                " kg must be finite and > 0 (at least 2.2e-308) for a movable body");
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
    // m v and I w must stay finite; compared in logarithms so the check itself cannot overflow.
    const auto product_overflows = [](double x, double y) {
      return x > 0.0 && y > 0.0 &&
             std::log(x) + std::log(y) > std::log(std::numeric_limits<double>::max()) - 2.0;
    };
    if (product_overflows(def.velocity.cwiseAbs().maxCoeff(), def.mass) ||
        product_overflows(def.angular_velocity.cwiseAbs().maxCoeff(), I_body.diagonal().maxCoeff())) {
      throw std::invalid_argument("body momentum overflows: mass " + num(def.mass) +
                                  " kg times its velocity is not finite in double precision");
    }
    b.p = def.mass * def.velocity;
    const Mat3 R = b.rotation();
    b.l = R * I_body * R.transpose() * def.angular_velocity;
  }
  return b;
}

}  // namespace cps
