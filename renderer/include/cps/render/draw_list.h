#pragma once
// A plain snapshot of what to draw: the only thing the renderer knows about a world.
//
// The renderer never includes the engine and never steps it: the demos copy body poses into a
// DrawList (the way MuJoCo separates mjv_updateScene from mjr_render) and hand it over.
// All lengths are in metres, in the engine's world frame (y up).

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <vector>

namespace cps::render {

/// A box: centre (m), orientation (unit quaternion, body to world), half extents (m, all > 0),
/// linear RGB colour in [0, 1], opacity alpha in [0, 1] (1: opaque, the default; below 1: a
/// ghost, see Renderer::draw; 0: not drawn).
struct BoxItem {
  glm::vec3 center{0.0f};
  glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 half_extents{0.5f};
  glm::vec3 color{0.8f};
  float alpha = 1.0f;
};

/// A sphere: centre (m), orientation (unit quaternion, so that its spin can be seen on its
/// shading pattern), radius (m, > 0), colour in [0, 1], opacity alpha in [0, 1] as for a box.
struct SphereItem {
  glm::vec3 center{0.0f};
  glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};
  float radius = 0.5f;
  glm::vec3 color{0.8f};
  float alpha = 1.0f;
};

/// An infinite plane {x : dot(normal, x) = offset}, drawn as a square of side 2 * half_size (m)
/// centred on the point of the plane nearest to `center_hint` (m). normal: unit 3-vector pointing
/// to the free side. `checker_m` is the side of the checker squares (m, > 0); alpha in [0, 1]
/// (1 = opaque; below 1 the plane is blended so bodies behind it stay visible). Planes are drawn
/// as the boundaries of solid half spaces: the part of a plane that lies inside another plane's
/// solid side (dot(other.normal, x) < other.offset) is not drawn, so four crossing planes show
/// as a clean funnel. At most 16 other planes clip each plane; a plane with alpha 0 is not drawn
/// but still clips the others.
struct PlaneItem {
  glm::vec3 normal{0.0f, 1.0f, 0.0f};
  float offset = 0.0f;
  glm::vec3 center_hint{0.0f};
  float half_size = 50.0f;
  float checker_m = 1.0f;
  glm::vec3 color_a{0.78f, 0.78f, 0.76f};
  glm::vec3 color_b{0.55f, 0.56f, 0.58f};
  float alpha = 1.0f;
};

/// A line segment from a to b (m), e.g. a distance constraint (rod). width_px: on-screen width
/// in pixels (typical 2).
struct LineItem {
  glm::vec3 a{0.0f};
  glm::vec3 b{0.0f};
  glm::vec3 color{0.1f};
  float width_px = 2.0f;
};

/// Pinhole camera. eye and target in m; vertical field of view in degrees (typical 45);
/// near/far clip distances in m (0 < near < far).
struct Camera {
  glm::vec3 eye{0.0f, 5.0f, 20.0f};
  glm::vec3 target{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_y_deg = 45.0f;
  float near_m = 0.1f;
  float far_m = 500.0f;
};

/// Everything one frame shows. light_direction: unit 3-vector along which the sun's light
/// travels (pointing down, e.g. (-0.4, -1, -0.3) normalised). background: RGB in [0, 1].
struct DrawList {
  std::vector<BoxItem> boxes;
  std::vector<SphereItem> spheres;
  std::vector<PlaneItem> planes;
  std::vector<LineItem> lines;
  Camera camera;
  glm::vec3 light_direction = glm::normalize(glm::vec3(-0.4f, -1.0f, -0.3f));
  glm::vec3 background{0.86f, 0.90f, 0.95f};
};

/// Axis-aligned bounds (m) of the boxes and spheres of a draw list (planes and lines ignored).
/// Returns false and leaves lo/hi untouched when there is nothing with finite extent.
bool bounds(const DrawList& list, glm::vec3& lo, glm::vec3& hi);

/// A camera that looks at the box [lo, hi] (m) from the front (+z), a little above and to the
/// side, far enough that the whole box fits in a view of the given aspect ratio (width/height,
/// > 0). Throws std::invalid_argument if lo > hi on any axis or aspect <= 0.
Camera frame_bounds(const glm::vec3& lo, const glm::vec3& hi, float aspect);

}  // namespace cps::render
