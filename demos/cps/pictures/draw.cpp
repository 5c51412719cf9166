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

// An arrow from a to b (m) in `colour`: the shaft and two barbs a fifth of its length, turned
// 25 degrees off it in the plane that faces the eye, so the head reads from the camera.
void add_arrow(const glm::vec3& a, const glm::vec3& b, const glm::vec3& colour, const glm::vec3& eye,
               render::DrawList& list) {
  const glm::vec3 shaft = b - a;
  const float length = glm::length(shaft);
  if (!(length > 0.0f)) return;
  const glm::vec3 along = shaft / length;
  glm::vec3 side = glm::cross(along, eye - b);
  if (!(glm::length(side) > 1e-6f * length)) side = glm::cross(along, glm::vec3(0.0f, 1.0f, 0.0f));
  if (!(glm::length(side) > 0.0f)) side = glm::vec3(1.0f, 0.0f, 0.0f);
  side = glm::normalize(side);
  const float barb = 0.2f * length;
  const float c = std::cos(glm::radians(25.0f));
  const float s = std::sin(glm::radians(25.0f));
  list.lines.push_back({a, b, colour, 3.0f});
  list.lines.push_back({b, b - barb * (c * along + s * side), colour, 3.0f});
  list.lines.push_back({b, b - barb * (c * along - s * side), colour, 3.0f});
}

// Velocity overlay: an arrow x -> x + v kVelocityArrow_s for every movable body, moved towards
// the eye out of the body's bounding sphere so that the body does not hide it.
void add_velocities(const World& world, const glm::vec3& eye, render::DrawList& list) {
  const glm::vec3 blue(0.05f, 0.10f, 0.55f);
  for (const Body& b : world.bodies()) {
    const Vec3 v = b.velocity();
    if (b.is_static() || !b.x.allFinite() || !v.allFinite()) continue;
    const glm::vec3 shaft = to_glm(kVelocityArrow_s * v);
    if (!(glm::length(shaft) >= 1e-3f)) continue;
    const glm::vec3 x = to_glm(b.x);
    const glm::vec3 to_eye = eye - x;
    // Out of the body's bounding sphere (a box's half diagonal), on the side facing the eye.
    const double reach = 1.05 * (b.shape.kind == ShapeKind::box ? b.shape.half_extents.norm() : body_size(b));
    const glm::vec3 start = glm::length(to_eye) > 0.0f
                                ? x + static_cast<float>(reach) * glm::normalize(to_eye)
                                : x;
    add_arrow(start, start + shaft, blue, eye, list);
  }
}

// Force overlay: at each contact point an arrow of its force on b (contact_forces), scaled to
// the lighter movable body of the pair: its weight is as long as its size.
void add_forces(const World& world, const glm::vec3& eye, render::DrawList& list) {
  const std::vector<Vec3> forces = contact_forces(world);
  if (forces.empty()) return;
  const glm::vec3 orange(0.95f, 0.45f, 0.0f);
  const double g = world.def().gravity.norm();
  const auto& bodies = world.bodies();
  std::size_t k = 0;
  for (const Manifold& m : world.manifolds()) {
    const Body& a = bodies[static_cast<std::size_t>(m.body_a)];
    const Body& b = bodies[static_cast<std::size_t>(m.body_b)];
    // The lighter movable body (a static one has mass 0 here).
    const Body& light = a.is_static() ? b : b.is_static() ? a : (a.mass <= b.mass ? a : b);
    const double weight = light.mass * g;
    const double size = body_size(light);
    for (int i = 0; i < m.count; ++i, ++k) {
      if (!(weight > 0.0) || !(size > 0.0) || k >= forces.size()) continue;
      const Vec3 arrow = forces[k] * (size / weight);
      if (!arrow.allFinite() || arrow.norm() < 1e-3) continue;
      const Vec3& p = m.contacts[static_cast<std::size_t>(i)].point;
      add_arrow(to_glm(p), to_glm(p + arrow), orange, eye, list);
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

std::vector<Vec3> contact_forces(const World& world) {
  std::size_t points = 0;
  for (const Manifold& m : world.manifolds()) points += static_cast<std::size_t>(m.count);
  const std::vector<ConstraintRow>& rows = world.rows();
  const std::vector<double>& lambda = world.lambda();
  if (points == 0 || rows.size() < points || lambda.size() != rows.size()) return {};
  for (std::size_t r = 0; r < points; ++r) {
    if (rows[r].kind != RowKind::contact) return {};
  }
  std::vector<Vec3> forces(points, Vec3::Zero());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const ConstraintRow& row = rows[r];
    // j = [-n, -(r_a x n), n, r_b x n]: its third block is the row's direction on b.
    const Vec3 on_b = row.j.segment<3>(6);
    if (row.kind == RowKind::contact && r < points) {
      forces[r] += lambda[r] * on_b;
    } else if (row.kind == RowKind::friction && row.normal_row >= 0 &&
               static_cast<std::size_t>(row.normal_row) < points) {
      forces[static_cast<std::size_t>(row.normal_row)] += lambda[r] * on_b;
    }
  }
  return forces;
}

render::Camera camera_at(const DrawStyle& style, std::size_t run, double t) {
  render::Camera camera = style.camera;
  if (style.paths.empty()) return camera;
  const CameraPath& path = style.paths[std::min(run, style.paths.size() - 1)];
  if (path.time_s.empty()) return camera;
  // The last keyframe at or before t, and the share of the way to the next.
  const auto next = std::upper_bound(path.time_s.begin(), path.time_s.end(), t);
  const std::size_t k1 = static_cast<std::size_t>(next - path.time_s.begin());
  const std::size_t k0 = k1 == 0 ? 0 : k1 - 1;
  const std::size_t k = std::min(k1, path.time_s.size() - 1);
  float w = 0.0f;
  if (k != k0 && path.time_s[k] > path.time_s[k0]) {
    w = static_cast<float>((t - path.time_s[k0]) / (path.time_s[k] - path.time_s[k0]));
  }
  const glm::vec3 target = glm::mix(path.target_m[k0], path.target_m[k], w);
  const float distance = glm::mix(path.distance_m[k0], path.distance_m[k], w);
  const glm::vec3 dir = glm::normalize(camera.eye - camera.target);
  camera.target = target;
  camera.eye = target + distance * dir;
  camera.near_m = distance / 50.0f;
  camera.far_m = distance * 50.0f;
  return camera;
}

render::DrawList draw_list(const World& world, const DrawStyle& style, std::size_t run) {
  render::DrawList list;
  const render::Camera camera = camera_at(style, run, world.time());
  list.camera = style.overlays.orbit_deg_per_s == 0.0
                    ? camera
                    : orbit(camera, style.overlays.orbit_deg_per_s * world.time());
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
    const glm::vec3 rod_colour = style.body_colour ? 0.5f * *style.body_colour : glm::vec3(0.15f);
    list.lines.push_back({to_glm(p_a), to_glm(p_b), rod_colour, 2.0f});
    // A fixed end (the world, or a static body) as a pin: a small sphere in the rod's colour,
    // a quarter of the size of the body the rod holds, at most 5 % of the rod's length (3 % if
    // it holds no sized body).
    const auto fixed = [&](int body) {
      return body == kWorldBody || bodies[static_cast<std::size_t>(body)].is_static();
    };
    const auto size_of = [&](int body) {
      return body == kWorldBody ? 0.0 : body_size(bodies[static_cast<std::size_t>(body)]);
    };
    const double held = std::max(size_of(d.body_a), size_of(d.body_b));
    const float pin = static_cast<float>(held > 0.0 ? std::min(0.25 * held, 0.05 * d.length) : 0.03 * d.length);
    for (const auto& [body, p] : {std::pair{d.body_a, p_a}, std::pair{d.body_b, p_b}}) {
      if (fixed(body) && p.allFinite()) {
        list.spheres.push_back({to_glm(p), glm::quat(1.0f, 0.0f, 0.0f, 0.0f), pin, rod_colour, style.body_alpha});
      }
    }
  }
  if (style.overlays.contacts) add_contacts(world, list);
  if (style.overlays.velocities) add_velocities(world, list.camera.eye, list);
  if (style.overlays.forces) add_forces(world, list.camera.eye, list);
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

namespace {

// Grows `out` to hold body b if it is a box or a sphere.
void add_extent(const Body& b, Bounds& out) {
  if (b.shape.kind == ShapeKind::box) {
    // World half extents of the oriented box: e_i = sum_j |R_ij| h_j (Ericson 4.2.6).
    const Vec3 e = b.rotation().cwiseAbs() * b.shape.half_extents;
    out.add(b.x - e, b.x + e);
  } else if (b.shape.kind == ShapeKind::sphere) {
    const Vec3 e = Vec3::Constant(b.shape.radius);
    out.add(b.x - e, b.x + e);
  }
}

}  // namespace

Bounds world_bounds(const World& world) {
  Bounds out;
  const auto& bodies = world.bodies();
  for (const Body& b : bodies) add_extent(b, out);
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

namespace {

// The movable boxes' and spheres' centres of `world` (m), non-finite ones skipped.
std::vector<Vec3> body_centres(const World& world) {
  std::vector<Vec3> centres;
  for (const Body& b : world.bodies()) {
    const bool solid = b.shape.kind == ShapeKind::box || b.shape.kind == ShapeKind::sphere;
    if (solid && !b.is_static() && b.x.allFinite()) centres.push_back(b.x);
  }
  return centres;
}

// The median of v (the upper one for an even count); v is reordered. v is not empty.
double median(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The per-axis median of `points` (not empty).
Vec3 median_point(const std::vector<Vec3>& points) {
  Vec3 m;
  std::vector<double> axis(points.size());
  for (int a = 0; a < 3; ++a) {
    for (std::size_t i = 0; i < points.size(); ++i) axis[i] = points[i][a];
    m[a] = median(axis);
  }
  return m;
}

// The farthest a movable body's centre or a distance constraint's end lies from the median of
// the centres (m): action_bounds' floor for a world as built, so that all of it is kept.
double action_floor(const World& world) {
  const std::vector<Vec3> centres = body_centres(world);
  if (centres.empty()) return 0.0;
  const Vec3 m = median_point(centres);
  double floor_m = 0.0;
  for (const Vec3& c : centres) floor_m = std::max(floor_m, (c - m).norm());
  for (const DistanceConstraint& d : world.distances()) {
    Vec3 p_a;
    Vec3 p_b;
    distance_endpoints(d, world.bodies(), p_a, p_b);
    if (p_a.allFinite()) floor_m = std::max(floor_m, (p_a - m).norm());
    if (p_b.allFinite()) floor_m = std::max(floor_m, (p_b - m).norm());
  }
  return floor_m;
}

}  // namespace

Bounds action_bounds(const World& world, double floor_m) {
  const std::vector<Vec3> centres = body_centres(world);
  if (centres.empty()) return world_bounds(world);
  const Vec3 m = median_point(centres);
  std::vector<double> d(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) d[i] = (centres[i] - m).norm();
  const double radius = std::max(2.5 * median(d), floor_m);
  Bounds out;
  for (const Body& b : world.bodies()) {
    if (!b.is_static() && b.x.allFinite() && (b.x - m).norm() <= radius) add_extent(b, out);
  }
  for (const DistanceConstraint& dc : world.distances()) {
    Vec3 p_a;
    Vec3 p_b;
    distance_endpoints(dc, world.bodies(), p_a, p_b);
    for (const Vec3& p : {p_a, p_b}) {
      if ((p - m).norm() <= radius) out.add(p, p);
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

constexpr std::array<std::string_view, 9> kCameraNames = {
    "preset", "auto", "fit", "fit:panel", "fit:frame", "front", "side", "top", "track:BODY"};

// What is wrong with --camera `name`: the allowed names and the nearest of them.
std::string camera_name_error(std::string_view name) {
  std::string known;
  std::vector<std::string> candidates;
  for (std::string_view n : kCameraNames) {
    known += (known.empty() ? "" : ", ") + std::string(n);
    candidates.emplace_back(n);
  }
  return "--camera " + std::string(name) + ": allowed are " + known + " (BODY a body's name or " +
         "index); did you mean '" + nearest_name(name, candidates) + "'?";
}

// The camera preset called `name` (see camera_names()) given the scene's preset `own` (none:
// the scene has none); nullopt means "frame the world automatically" (frame_world). `world` is
// the scene as built, framed when there is no preset. Throws UsageError listing the names for an
// unknown one.
std::optional<scenes::CameraPreset> camera_preset(const std::optional<scenes::CameraPreset>& own,
                                                  const World& world, std::string_view name,
                                                  float aspect) {
  if (name == "preset" || name == "fit" || name.starts_with("fit:") || name.starts_with("track:")) {
    return own;
  }
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
    throw UsageError(camera_name_error(name));
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
  if (view.camera == "preset" && !view.preset) {
    if (!scene.camera && scenes::is_file_scene(scene)) {
      view.camera = "fit";
    } else if (!view.camera_given) {
      view.camera = scene.default_camera;
    }
  }
  return view;
}

DrawStyle resolve_style(const scenes::Scene& scene, const World& as_built, const View& view,
                        float aspect) {
  const World* worlds[] = {&as_built};
  return resolve_style(scene, worlds, view, aspect, 0.0);
}

namespace {

// What a headless pre-run of one world saw, one entry per step (and one as built).
struct RunSamples {
  std::vector<double> time_s;
  std::vector<Bounds> action;  // action_bounds, with the floor of the world as built
  std::vector<Vec3> tracked;   // the tracked body's centre (m), if one is tracked
  Bounds all;                  // world_bounds over the whole run
};

RunSamples sample_run(const World& as_built, double seconds, std::optional<std::size_t> tracked) {
  World copy = as_built;
  const double floor_m = action_floor(copy);
  RunSamples s;
  const auto take = [&] {
    s.time_s.push_back(copy.time());
    s.action.push_back(action_bounds(copy, floor_m));
    if (tracked) s.tracked.push_back(copy.bodies()[*tracked].x);
    s.all.add(world_bounds(copy));
  };
  take();
  while (scenes::short_of(copy, seconds)) {
    copy.step();
    take();
  }
  return s;
}

// The eye-target distance (m) at which a sphere of `radius` (m) fits a picture of vertical field
// of view fov_y_deg and aspect (width / height) with a 10 % margin.
float fit_distance(float radius, float fov_y_deg, float aspect) {
  const float half_v = glm::radians(0.5f * fov_y_deg);
  const float half_h = std::atan(std::tan(half_v) * aspect);
  return 1.1f * std::max(radius, 1e-3f) / std::sin(std::min(half_v, half_h));
}

// The bounding sphere of `b` (centre and radius, m).
std::pair<glm::vec3, float> sphere_of(const Bounds& b) {
  const glm::vec3 lo = to_glm(b.lo);
  const glm::vec3 hi = to_glm(b.hi);
  return {0.5f * (lo + hi), 0.5f * glm::length(hi - lo)};
}

// For each k, the first and last index of the samples within kCameraSmoothing_s / 2 of time k.
std::vector<std::pair<std::size_t, std::size_t>> windows(const std::vector<double>& t) {
  std::vector<std::pair<std::size_t, std::size_t>> out(t.size());
  const double half = 0.5 * kCameraSmoothing_s;
  std::size_t lo = 0;
  std::size_t hi = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    while (t[lo] < t[k] - half) ++lo;
    while (hi + 1 < t.size() && t[hi + 1] <= t[k] + half) ++hi;
    out[k] = {lo, hi};
  }
  return out;
}

// fit:frame: at each time the sphere that holds every sample's bounding sphere within the window
// around its smoothed centre (the mean of their centres), fitted to the picture. Times whose
// bounds are empty hold the sphere before them (a unit sphere at the origin at the start).
CameraPath frame_path(const std::vector<double>& t, const std::vector<Bounds>& bounds,
                      float fov_y_deg, float aspect) {
  std::vector<std::pair<glm::vec3, float>> spheres;
  std::pair<glm::vec3, float> last{glm::vec3(0.0f), 1.0f};
  for (const Bounds& b : bounds) {
    if (b.any) last = sphere_of(b);
    spheres.push_back(last);
  }
  CameraPath path;
  for (std::size_t k = 0; const auto& [lo, hi] : windows(t)) {
    glm::vec3 centre(0.0f);
    for (std::size_t j = lo; j <= hi; ++j) centre += spheres[j].first;
    centre /= static_cast<float>(hi - lo + 1);
    float radius = 0.0f;
    for (std::size_t j = lo; j <= hi; ++j) {
      radius = std::max(radius, spheres[j].second + glm::length(spheres[j].first - centre));
    }
    path.time_s.push_back(t[k]);
    path.target_m.push_back(centre);
    path.distance_m.push_back(fit_distance(radius, fov_y_deg, aspect));
    ++k;
  }
  return path;
}

// track:BODY: the body's centre averaged over the window, at a fixed distance (m).
CameraPath track_path(const RunSamples& s, float distance) {
  CameraPath path;
  for (std::size_t k = 0; const auto& [lo, hi] : windows(s.time_s)) {
    Vec3 centre = Vec3::Zero();
    int n = 0;
    for (std::size_t j = lo; j <= hi; ++j) {
      if (!s.tracked[j].allFinite()) continue;
      centre += s.tracked[j];
      ++n;
    }
    path.time_s.push_back(s.time_s[k]);
    path.target_m.push_back(n > 0 ? to_glm(centre / n)
                                  : (path.target_m.empty() ? glm::vec3(0.0f) : path.target_m.back()));
    path.distance_m.push_back(distance);
    ++k;
  }
  return path;
}

// The index of the body that --camera track:`text` names in `world`: a scene file's body name,
// else an index from 0. Throws UsageError naming the bodies.
std::size_t tracked_body(const scenes::Scene& scene, const World& world, const std::string& text) {
  const std::vector<std::string> names = scenes::body_names(scene);
  for (std::size_t i = 0; i < names.size() && i < world.bodies().size(); ++i) {
    if (!names[i].empty() && names[i] == text) return i;
  }
  const std::size_t n = world.bodies().size();
  if (!text.empty() && text.size() < 10 &&
      std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    const std::size_t index = std::stoul(text);
    if (index < n) return index;
  }
  std::string message = "--camera track:" + text + ": ";
  std::vector<std::string> named;
  for (const std::string& name : names) {
    if (!name.empty()) named.push_back(name);
  }
  const std::string range = n == 0 ? std::string("the world has no body")
                                    : "give a body index from 0 to " + std::to_string(n - 1);
  if (named.empty()) {
    message += "no body of " + std::string(scene.name) + " is named or numbered so (its bodies have no names); " + range;
  } else {
    message += "no body is named so; did you mean '" + nearest_name(text, named) + "'? (or " + range + ")";
  }
  throw UsageError(message);
}

}  // namespace

std::string check_camera_name(std::string_view name) {
  for (std::string_view n : kCameraNames) {
    if (n == name && n != "track:BODY") return {};
  }
  if (name.starts_with("track:") && name.size() > 6) return {};
  return camera_name_error(name);
}

DrawStyle resolve_style(const scenes::Scene& scene, std::span<const World* const> as_built,
                        const View& view, float aspect, double seconds) {
  if (as_built.empty()) throw std::invalid_argument("resolve_style: no world");
  if (const std::string error = check_camera_name(view.camera); !error.empty()) throw UsageError(error);
  const World& first = *as_built.front();
  const std::string& name = view.camera;
  const bool fit = name.starts_with("fit");
  const bool per_run = name == "fit:panel" && !view.one_picture;
  const bool per_frame = name == "fit:frame";
  std::optional<std::size_t> tracked;
  if (name.starts_with("track:")) tracked = tracked_body(scene, first, name.substr(6));

  const std::optional<scenes::CameraPreset> preset =
      camera_preset(view.preset ? view.preset : scene.camera, first, name, aspect);
  DrawStyle style;
  style.camera = preset ? camera_from_preset(*preset) : frame_world(first, aspect);
  style.plane_opacity = static_cast<float>(scene.plane_opacity);
  style.overlays = view.overlays;
  style.body_colours = scenes::body_colours(scene);
  if (view.fov_y_deg) style.camera.fov_y_deg = static_cast<float>(*view.fov_y_deg);
  const glm::vec3 dir = glm::normalize(style.camera.eye - style.camera.target);

  Bounds bounds;  // what the planes are drawn around
  if (fit || tracked) {
    std::vector<RunSamples> samples;
    for (const World* w : as_built) samples.push_back(sample_run(*w, seconds, tracked));
    Bounds action;  // over every run and time
    for (const RunSamples& s : samples) {
      bounds.add(s.all);
      for (const Bounds& b : s.action) action.add(b);
    }
    if (fit && action.any) {
      // The bounding sphere of the action over the whole run, seen along the named camera's direction.
      const auto [centre, radius] = sphere_of(action);
      const float distance = fit_distance(radius, style.camera.fov_y_deg, aspect);
      style.camera.target = centre;
      style.camera.eye = centre + distance * dir;
      style.camera.near_m = distance / 50.0f;
      style.camera.far_m = distance * 50.0f;
    }
    if (per_run) {
      for (const RunSamples& s : samples) {
        Bounds run_action;
        for (const Bounds& b : s.action) run_action.add(b);
        if (!run_action.any) run_action = action;
        const auto [centre, radius] = sphere_of(run_action);
        style.paths.push_back({{0.0}, {centre}, {fit_distance(radius, style.camera.fov_y_deg, aspect)}});
      }
    } else if (per_frame) {
      if (view.one_picture) {
        // One picture: at each time of the first run, the union of every run's bounds at the
        // latest of its own times not after it.
        std::vector<Bounds> merged = samples.front().action;
        for (std::size_t r = 1; r < samples.size(); ++r) {
          std::size_t j = 0;
          for (std::size_t k = 0; k < merged.size(); ++k) {
            const double t = samples.front().time_s[k];
            while (j + 1 < samples[r].time_s.size() && samples[r].time_s[j + 1] <= t) ++j;
            merged[k].add(samples[r].action[j]);
          }
        }
        style.paths.push_back(frame_path(samples.front().time_s, merged, style.camera.fov_y_deg, aspect));
      } else {
        for (const RunSamples& s : samples) {
          style.paths.push_back(frame_path(s.time_s, s.action, style.camera.fov_y_deg, aspect));
        }
      }
    } else if (tracked) {
      const float distance = glm::length(style.camera.eye - style.camera.target);
      for (const RunSamples& s : samples) style.paths.push_back(track_path(s, distance));
      if (view.one_picture) style.paths.resize(1);
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
  // so the ground reaches the horizon instead of ending as a visible square, for every camera
  // of every path.
  float reach = glm::length(style.camera.eye - style.camera.target) * 40.0f +
                glm::length(style.camera.target - style.plane_centre);
  for (const CameraPath& path : style.paths) {
    for (std::size_t k = 0; k < path.time_s.size(); ++k) {
      reach = std::max(reach, 40.0f * path.distance_m[k] + glm::length(path.target_m[k] - style.plane_centre));
    }
  }
  style.plane_half_size_m = std::max(style.plane_half_size_m, reach);
  return style;
}

}  // namespace cps::cli
