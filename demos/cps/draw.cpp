#include "draw.h"

#include <algorithm>
#include <array>

namespace cps::cli {
namespace {

glm::vec3 to_glm(const Vec3& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

glm::quat to_glm(const Quat& q) {
  return {static_cast<float>(q.w()), static_cast<float>(q.x()), static_cast<float>(q.y()),
          static_cast<float>(q.z())};
}

// A palette that tells neighbouring bodies apart (linear RGB).
constexpr std::array<glm::vec3, 6> kPalette = {{{0.85f, 0.33f, 0.20f},
                                                {0.20f, 0.50f, 0.80f},
                                                {0.95f, 0.70f, 0.15f},
                                                {0.30f, 0.65f, 0.35f},
                                                {0.60f, 0.35f, 0.70f},
                                                {0.15f, 0.65f, 0.70f}}};

glm::vec3 colour_of(std::size_t body) { return kPalette[body % kPalette.size()]; }

}  // namespace

render::DrawList draw_list(const World& world, const DrawStyle& style) {
  render::DrawList list;
  list.camera = style.camera;
  const auto& bodies = world.bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    if (b.shape.kind == ShapeKind::box) {
      list.boxes.push_back({to_glm(b.x), to_glm(b.o), to_glm(b.shape.half_extents), colour_of(i)});
    } else if (b.shape.kind == ShapeKind::sphere) {
      list.spheres.push_back({to_glm(b.x), to_glm(b.o), static_cast<float>(b.shape.radius),
                              colour_of(i)});
    }
  }
  for (const DistanceConstraint& d : world.distances()) {
    Vec3 p_a;
    Vec3 p_b;
    distance_endpoints(d, bodies, p_a, p_b);
    list.lines.push_back({to_glm(p_a), to_glm(p_b), glm::vec3(0.15f), 2.0f});
  }
  glm::vec3 lo(-5.0f);
  glm::vec3 hi(5.0f);
  render::bounds(list, lo, hi);
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float extent = glm::length(hi - lo);
  for (const Body& b : bodies) {
    if (b.shape.kind != ShapeKind::plane) continue;
    const Vec3 n = b.rotation() * b.shape.normal;
    render::PlaneItem plane;
    plane.normal = to_glm(n);
    plane.offset = static_cast<float>(b.shape.offset + n.dot(b.x));
    plane.center_hint = centre;
    plane.half_size = std::max(30.0f, 3.0f * extent);
    plane.checker_m = 1.0f;
    plane.alpha = style.plane_opacity;
    list.planes.push_back(plane);
  }
  return list;
}

render::Camera frame_world(const World& world, float aspect) {
  const render::DrawList list = draw_list(world, {});
  glm::vec3 lo(-5.0f);
  glm::vec3 hi(5.0f);
  render::bounds(list, lo, hi);
  for (const render::LineItem& rod : list.lines) {
    lo = glm::min(lo, glm::min(rod.a, rod.b));
    hi = glm::max(hi, glm::max(rod.a, rod.b));
  }
  lo.y = std::min(lo.y, 0.0f);  // keep the ground (or the funnel's apex) in view
  return render::frame_bounds(lo, hi, aspect);
}

render::Camera camera_from_preset(const scenes::CameraPreset& preset) {
  render::Camera camera;
  camera.eye = to_glm(preset.eye);
  camera.target = to_glm(preset.target);
  camera.fov_y_deg = static_cast<float>(preset.fov_y_deg);
  const float distance = glm::length(camera.eye - camera.target);
  camera.near_m = distance / 50.0f;
  camera.far_m = distance * 50.0f;
  return camera;
}

}  // namespace cps::cli
