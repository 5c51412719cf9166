#include "draw.h"

#include "scene_file.h"

#include "options.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

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

// The colour of body `body`: the scene's own (style.body_colours) if it has one, else the palette's.
glm::vec3 colour_of(std::size_t body, const DrawStyle& style) {
  if (body < style.body_colours.size() && style.body_colours[body]) {
    const Vec3& c = *style.body_colours[body];
    return {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())};
  }
  return kPalette[body % kPalette.size()];
}

// A length (m) that says how big a movable body is: its largest half extent or its radius;
// 0 for planes and static bodies.
double body_size(const Body& b) {
  if (b.is_static()) return 0.0;
  if (b.shape.kind == ShapeKind::box) return b.shape.half_extents.maxCoeff();
  if (b.shape.kind == ShapeKind::sphere) return b.shape.radius;
  return 0.0;
}

// Contact overlay: for each contact point of the last step, a small sphere at the point and a
// segment of length about one body size along the normal (from a towards b).
void add_contacts(const World& world, render::DrawList& list) {
  const glm::vec3 red(0.85f, 0.05f, 0.05f);
  const auto& bodies = world.bodies();
  for (const Manifold& m : world.manifolds()) {
    const double sa = body_size(bodies[static_cast<std::size_t>(m.body_a)]);
    const double sb = body_size(bodies[static_cast<std::size_t>(m.body_b)]);
    double size = sa > 0.0 && sb > 0.0 ? std::min(sa, sb) : std::max(sa, sb);
    if (!(size > 0.0)) size = 0.5;
    for (int k = 0; k < m.count; ++k) {
      const Contact& c = m.contacts[static_cast<std::size_t>(k)];
      list.spheres.push_back({to_glm(c.point), glm::quat(1.0f, 0.0f, 0.0f, 0.0f),
                              static_cast<float>(0.25 * size), red});
      list.lines.push_back({to_glm(c.point), to_glm(c.point + size * c.normal), red, 3.0f});
    }
  }
}

// `camera` turned about the vertical axis through its target by `deg` degrees.
render::Camera orbit(render::Camera camera, double deg) {
  const float a = static_cast<float>(deg * 3.14159265358979323846 / 180.0);
  const glm::vec3 r = camera.eye - camera.target;
  const float c = std::cos(a);
  const float s = std::sin(a);
  camera.eye = camera.target + glm::vec3(c * r.x + s * r.z, r.y, -s * r.x + c * r.z);
  return camera;
}


}  // namespace

render::DrawList draw_list(const World& world, const DrawStyle& style) {
  render::DrawList list;
  list.camera = style.overlays.orbit_deg_per_s == 0.0
                    ? style.camera
                    : orbit(style.camera, style.overlays.orbit_deg_per_s * world.time());
  const auto& bodies = world.bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    const glm::vec3 colour = style.body_colour.value_or(colour_of(i, style));
    if (b.shape.kind == ShapeKind::box) {
      list.boxes.push_back({to_glm(b.x), to_glm(b.o), to_glm(b.shape.half_extents), colour,
                            style.body_alpha});
    } else if (b.shape.kind == ShapeKind::sphere) {
      list.spheres.push_back({to_glm(b.x), to_glm(b.o), static_cast<float>(b.shape.radius),
                              colour, style.body_alpha});
    }
  }
  for (const DistanceConstraint& d : world.distances()) {
    if (!style.overlays.rods) break;
    Vec3 p_a;
    Vec3 p_b;
    distance_endpoints(d, bodies, p_a, p_b);
    list.lines.push_back(
        {to_glm(p_a), to_glm(p_b), style.body_colour ? 0.5f * *style.body_colour : glm::vec3(0.15f), 2.0f});
  }
  glm::vec3 lo(-5.0f);
  glm::vec3 hi(5.0f);
  render::bounds(list, lo, hi);  // the bodies only: contact markers do not move the planes
  if (style.overlays.contacts) add_contacts(world, list);
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

namespace {

// A camera that frames the movable bodies and the fixed rod ends of `world` as they are now,
// with the ground level y = 0 in view (aspect = width / height, > 0).
render::Camera frame_world(const World& world, float aspect) {
  DrawStyle all;
  all.overlays = Overlays{};  // rods on, no contacts, no orbit: framing ignores the flags
  const render::DrawList list = draw_list(world, all);
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

// The renderer camera of a preset (near/far clip planes from the eye-target distance).
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

constexpr std::array<std::string_view, 5> kCameraNames = {"preset", "auto", "front", "side",
                                                          "top"};

// The camera preset called `name` (see camera_names()) given the scene's preset `own` (none:
// the scene has none); nullopt means "frame the world automatically" (frame_world). `world` is
// the scene as built, framed when there is no preset. Throws UsageError listing the names for an
// unknown one.
std::optional<scenes::CameraPreset> camera_preset(const std::optional<scenes::CameraPreset>& own,
                                                  const World& world, std::string_view name,
                                                  float aspect) {
  if (name == "preset") return own;
  if (name == "auto") return std::nullopt;
  scenes::CameraPreset base;
  if (own) {
    base = *own;
  } else {
    const render::Camera framed = frame_world(world, aspect);
    base.eye = Vec3(framed.eye.x, framed.eye.y, framed.eye.z);
    base.target = Vec3(framed.target.x, framed.target.y, framed.target.z);
    base.fov_y_deg = framed.fov_y_deg;
  }
  const double distance = (base.eye - base.target).norm();
  scenes::CameraPreset view = base;
  if (name == "front") {
    view.eye = base.target + Vec3(0.0, 0.15 * distance, distance);
  } else if (name == "side") {
    view.eye = base.target + Vec3(distance, 0.15 * distance, 0.0);
  } else if (name == "top") {
    // Straight down would make the up vector (0, 1, 0) degenerate: tilt a little towards +z.
    view.eye = base.target + Vec3(0.0, distance, 0.05 * distance);
  } else {
    std::string known;
    for (std::string_view n : kCameraNames) known += (known.empty() ? "" : ", ") + std::string(n);
    throw UsageError("--camera " + std::string(name) + ": allowed are " + known);
  }
  return view;
}

}  // namespace

std::span<const std::string_view> camera_names() { return kCameraNames; }

DrawStyle resolve_style(const scenes::Scene& scene, const World& as_built, const View& view,
                        float aspect) {
  const std::optional<scenes::CameraPreset> preset =
      camera_preset(view.preset ? view.preset : scene.camera, as_built, view.camera, aspect);
  return {preset ? camera_from_preset(*preset) : frame_world(as_built, aspect),
          static_cast<float>(scene.plane_opacity), view.overlays, scenes::body_colours(scene)};
}

}  // namespace cps::cli
