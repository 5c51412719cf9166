// Writing a world as a scene file (scene_file_json): every parameter, body and rod as the world
// holds them, the initial state written so that make_body rebuilds the same bits where it can.
#include "scene_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace cps::scenes {

// ---- Writing a world as a scene file --------------------------------------------------------

namespace {

using nlohmann::json;

json json_of(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

json parameter_json(const Parameter& p, const ParameterValue& v) {
  switch (p.type) {
    case ParameterType::real:
      return std::get<double>(v);
    case ParameterType::integer:
      return std::get<int>(v);
    case ParameterType::boolean:
      return std::get<bool>(v);
    case ParameterType::vector3:
      return json_of(std::get<Vec3>(v));
    case ParameterType::choice:
      return std::string(p.choice_name(std::get<int>(v)));
  }
  return nullptr;
}

// The value next to x by `steps` units in the last place (steps may be negative).
double ulps_away(double x, int steps) {
  for (; steps > 0; --steps) x = std::nextafter(x, kInfinity);
  for (; steps < 0; ++steps) x = std::nextafter(x, -kInfinity);
  return x;
}

// A velocity v (m/s) with mass * v == p in every bit, near p / mass; p / mass if none is found.
Vec3 velocity_for(const Body& b) {
  Vec3 v;
  for (int k = 0; k < 3; ++k) {
    const double guess = b.p[k] / b.mass;
    v[k] = guess;
    for (const int s : {0, 1, -1, 2, -2, 3, -3}) {
      if (b.mass * ulps_away(guess, s) == b.p[k]) {
        v[k] = ulps_away(guess, s);
        break;
      }
    }
  }
  return v;
}

// An angular velocity w (rad/s) from which make_body rebuilds l = R I R^T w in every bit, near
// I^-1 l; I^-1 l if none is found within 2 units in the last place per component.
Vec3 angular_velocity_for(const Body& b) {
  const Vec3 guess = b.angular_velocity();
  if (b.l == Vec3::Zero()) return Vec3::Zero();
  const Mat3 R = b.rotation();
  const Mat3 I = shape_inertia(b.shape, b.mass);
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) {
      for (int k = -2; k <= 2; ++k) {
        const Vec3 w(ulps_away(guess.x(), i), ulps_away(guess.y(), j), ulps_away(guess.z(), k));
        if (R * I * R.transpose() * w == b.l) return w;
      }
    }
  }
  return guess;
}

// A quaternion q with q.normalized() == o in every bit (make_body normalises what it is given).
Quat orientation_for(const Quat& o) {
  for (int a = -1; a <= 1; ++a) {
    for (int b = -1; b <= 1; ++b) {
      for (int c = -1; c <= 1; ++c) {
        for (int d = -1; d <= 1; ++d) {
          const Quat q(ulps_away(o.w(), a), ulps_away(o.x(), b), ulps_away(o.y(), c), ulps_away(o.z(), d));
          if (q.normalized().coeffs() == o.coeffs()) return q;
        }
      }
    }
  }
  return o;
}

// A normal n with n / |n| == `unit` in every bit (Shape::plane normalises what it is given).
Vec3 normal_for(const Vec3& unit) {
  for (int a = -1; a <= 1; ++a) {
    for (int b = -1; b <= 1; ++b) {
      for (int c = -1; c <= 1; ++c) {
        const Vec3 n(ulps_away(unit.x(), a), ulps_away(unit.y(), b), ulps_away(unit.z(), c));
        if (n / n.norm() == unit) return n;
      }
    }
  }
  return unit;
}

std::string hex_colour(const Vec3& linear) {
  char text[8];
  int c[3];
  for (int k = 0; k < 3; ++k) {
    const double l = std::clamp(linear[k], 0.0, 1.0);
    const double srgb = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
    c[k] = static_cast<int>(std::lround(srgb * 255.0));
  }
  std::snprintf(text, sizeof text, "#%02x%02x%02x", c[0], c[1], c[2]);
  return text;
}

}  // namespace

nlohmann::json scene_file_json(const Scene& scene, const World& as_built) {
  json j = json::object();
  j["$schema"] = "https://github.com/cps/assets/schemas/scene.schema.json";
  j["name"] = std::string(scene.name);
  j["description"] = std::string(scene.summary);
  j["seconds"] = scene.default_seconds;
  if (scene.plane_opacity != 1.0) j["plane_opacity"] = scene.plane_opacity;
  json world = json::object();
  for (const Parameter& p : world_parameters()) {
    world[std::string(p.json_key)] = parameter_json(p, p.get(as_built.def()));
  }
  j["world"] = world;
  json bodies = json::array();
  const auto& all = as_built.bodies();
  const std::span<const std::optional<Vec3>> colours = body_colours(scene);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Body& b = all[i];
    json body = json::object();
    switch (b.shape.kind) {
      case ShapeKind::box:
        body["shape"] = "box";
        body["half_extents_m"] = json_of(b.shape.half_extents);
        break;
      case ShapeKind::sphere:
        body["shape"] = "sphere";
        body["radius_m"] = b.shape.radius;
        break;
      case ShapeKind::plane:
        body["shape"] = "plane";
        body["normal"] = json_of(normal_for(b.shape.normal));
        body["offset_m"] = b.shape.offset;
        break;
    }
    if (b.is_static()) {
      if (b.shape.kind != ShapeKind::plane) body["static"] = true;
    } else {
      body["mass_kg"] = b.mass;
    }
    body["position_m"] = json_of(b.x);
    const Quat q = orientation_for(b.o);
    if (!(q.w() == 1.0 && q.vec() == Vec3::Zero())) body["orientation_wxyz"] = {q.w(), q.x(), q.y(), q.z()};
    if (!b.is_static()) {
      const Vec3 v = velocity_for(b);
      const Vec3 w = angular_velocity_for(b);
      if (v != Vec3::Zero()) body["velocity_mps"] = json_of(v);
      if (w != Vec3::Zero()) body["angular_velocity_radps"] = json_of(w);
    }
    if (!std::isnan(b.restitution)) body["restitution"] = b.restitution;
    if (!std::isnan(b.friction)) body["friction"] = b.friction;
    if (i < colours.size() && colours[i]) body["color"] = hex_colour(*colours[i]);
    bodies.push_back(body);
  }
  j["bodies"] = bodies;
  if (!as_built.distances().empty()) {
    json rods = json::array();
    for (const DistanceConstraint& d : as_built.distances()) {
      json rod = {{"body_a", d.body_a},
                  {"point_a_m", json_of(d.local_a)},
                  {"body_b", d.body_b == kWorldBody ? json(nullptr) : json(d.body_b)},
                  {"point_b_m", json_of(d.local_b)},
                  {"length_m", d.length}};
      if (!d.collide) rod["collide"] = false;
      rods.push_back(rod);
    }
    j["rods"] = rods;
  }
  if (scene.camera) {
    j["camera"] = {{"eye_m", json_of(scene.camera->eye)},
                   {"target_m", json_of(scene.camera->target)},
                   {"fov_deg", scene.camera->fov_y_deg}};
  }
  return j;
}

}  // namespace cps::scenes
