#include "pictures/draw.h"

#include "scene_file.h"

#include "usage_error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
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

}  // namespace

glm::vec3 body_colour(std::size_t body, const DrawStyle& style) {
  if (body < style.body_colours.size() && style.body_colours[body]) {
    const Vec3& c = *style.body_colours[body];
    return {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())};
  }
  return kPalette[body % kPalette.size()];
}

namespace {

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


std::string vec_text(const glm::vec3& v) {
  char text[96];
  std::snprintf(text, sizeof text, "%g, %g, %g", static_cast<double>(v.x),
                static_cast<double>(v.y), static_cast<double>(v.z));
  return text;
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
    const glm::vec3 colour = style.body_colour.value_or(body_colour(i, style));
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
  if (style.overlays.contacts) add_contacts(world, list);
  for (const Body& b : bodies) {
    if (b.shape.kind != ShapeKind::plane) continue;
    const Vec3 n = b.rotation() * b.shape.normal;
    render::PlaneItem plane;
    plane.normal = to_glm(n);
    plane.offset = static_cast<float>(b.shape.offset + n.dot(b.x));
    plane.center_hint = style.plane_centre;
    plane.half_size = style.plane_half_size_m;
    plane.checker_m = 1.0f;
    plane.alpha = style.plane_opacity;
    list.planes.push_back(plane);
  }
  return list;
}

void Bounds::add(const Vec3& a, const Vec3& b) {
  if (!a.allFinite() || !b.allFinite()) return;
  if (!any) {
    lo = a;
    hi = b;
    any = true;
  } else {
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  }
}

void Bounds::add(const Bounds& other) {
  if (other.any) add(other.lo, other.hi);
}

Bounds world_bounds(const World& world) {
  Bounds out;
  const auto& bodies = world.bodies();
  for (const Body& b : bodies) {
    if (b.shape.kind == ShapeKind::box) {
      // World half extents of the oriented box: e_i = sum_j |R_ij| h_j (Ericson 4.2.6).
      const Vec3 e = b.rotation().cwiseAbs() * b.shape.half_extents;
      out.add(b.x - e, b.x + e);
    } else if (b.shape.kind == ShapeKind::sphere) {
      const Vec3 e = Vec3::Constant(b.shape.radius);
      out.add(b.x - e, b.x + e);
    }
  }
  for (const DistanceConstraint& d : world.distances()) {
    Vec3 p_a;
    Vec3 p_b;
    distance_endpoints(d, bodies, p_a, p_b);
    out.add(p_a, p_a);
    out.add(p_b, p_b);
  }
  return out;
}

Bounds run_bounds(std::span<const World* const> worlds, double seconds) {
  Bounds out;
  for (const World* w : worlds) {
    World copy = *w;
    out.add(world_bounds(copy));
    while (scenes::short_of(copy, seconds)) {
      copy.step();
      out.add(world_bounds(copy));
    }
  }
  return out;
}

void plane_extent(const Bounds& b, glm::vec3& centre, float& half_size_m) {
  centre = b.any ? to_glm(0.5 * (b.lo + b.hi)) : glm::vec3(0.0f);
  const float extent = b.any ? static_cast<float>((b.hi - b.lo).norm()) : 0.0f;
  half_size_m = std::max(30.0f, 3.0f * extent);
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

constexpr std::array<std::string_view, 6> kCameraNames = {"preset", "auto", "fit",
                                                          "front", "side", "top"};

// The camera preset called `name` (see camera_names()) given the scene's preset `own` (none:
// the scene has none); nullopt means "frame the world automatically" (frame_world). `world` is
// the scene as built, framed when there is no preset. Throws UsageError listing the names for an
// unknown one.
std::optional<scenes::CameraPreset> camera_preset(const std::optional<scenes::CameraPreset>& own,
                                                  const World& world, std::string_view name,
                                                  float aspect) {
  if (name == "preset" || name == "fit") return own;
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

nlohmann::json camera_json(const render::Camera& c) {
  return {{"eye_m", {c.eye.x, c.eye.y, c.eye.z}},
          {"target_m", {c.target.x, c.target.y, c.target.z}},
          {"fov_y_deg", c.fov_y_deg}};
}

std::span<const std::string_view> camera_names() { return kCameraNames; }

View scene_view(const scenes::Scene& scene, View view) {
  if (view.camera == "preset" && !view.preset && !scene.camera && scenes::is_file_scene(scene)) {
    view.camera = "fit";
  }
  return view;
}

DrawStyle resolve_style(const scenes::Scene& scene, const World& as_built, const View& view,
                        float aspect) {
  const World* worlds[] = {&as_built};
  return resolve_style(scene, worlds, view, aspect, 0.0);
}

DrawStyle resolve_style(const scenes::Scene& scene, std::span<const World* const> as_built,
                        const View& view, float aspect, double seconds) {
  if (as_built.empty()) throw std::invalid_argument("resolve_style: no world");
  const World& first = *as_built.front();
  const std::optional<scenes::CameraPreset> preset =
      camera_preset(view.preset ? view.preset : scene.camera, first, view.camera, aspect);
  DrawStyle style;
  style.camera = preset ? camera_from_preset(*preset) : frame_world(first, aspect);
  style.plane_opacity = static_cast<float>(scene.plane_opacity);
  style.overlays = view.overlays;
  style.body_colours = scenes::body_colours(scene);
  if (view.fov_y_deg) style.camera.fov_y_deg = static_cast<float>(*view.fov_y_deg);
  Bounds bounds;
  if (view.camera == "fit") {
    bounds = run_bounds(as_built, seconds);
    if (bounds.any) {
      // The bounding sphere of the run's bounds, seen along the named camera's direction.
      const glm::vec3 lo = to_glm(bounds.lo);
      const glm::vec3 hi = to_glm(bounds.hi);
      const float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
      const float half_v = glm::radians(0.5f * style.camera.fov_y_deg);
      const float half_h = std::atan(std::tan(half_v) * aspect);
      const float distance = 1.1f * radius / std::sin(std::min(half_v, half_h));
      const glm::vec3 dir = glm::normalize(style.camera.eye - style.camera.target);
      style.camera.target = 0.5f * (lo + hi);
      style.camera.eye = style.camera.target + distance * dir;
      style.camera.near_m = distance / 50.0f;
      style.camera.far_m = distance * 50.0f;
    }
  } else {
    for (const World* w : as_built) bounds.add(world_bounds(*w));
  }
  if (view.eye || view.target) {
    if (view.eye) style.camera.eye = to_glm(*view.eye);
    if (view.target) style.camera.target = to_glm(*view.target);
    const float distance = glm::length(style.camera.eye - style.camera.target);
    if (!(distance > 1e-6f)) {
      throw UsageError("--eye and --target: the eye (" + vec_text(style.camera.eye) +
                       ") equals the target; give points at least 1e-6 m apart");
    }
    style.camera.near_m = distance / 50.0f;
    style.camera.far_m = distance * 50.0f;
    // Looking straight up or down makes the up vector (0, 1, 0) degenerate: tilt it.
    const glm::vec3 d = (style.camera.target - style.camera.eye) / distance;
    if (std::abs(d.y) > 0.999f) style.camera.up = glm::vec3(0.0f, 0.0f, -1.0f);
  }
  plane_extent(bounds, style.plane_centre, style.plane_half_size_m);
  // Far enough that the planes' edges lie near the far clip plane (50 eye-target distances),
  // so the ground reaches the horizon instead of ending as a visible square.
  const float view_distance = glm::length(style.camera.eye - style.camera.target);
  style.plane_half_size_m = std::max(style.plane_half_size_m,
                                     40.0f * view_distance + glm::length(style.camera.target - style.plane_centre));
  return style;
}

}  // namespace cps::cli
