#pragma once
// Private: the frame plan, what each pass of one frame draws, computed from a DrawList on the CPU
// alone (no GL call): the camera and light matrices, the valid items as instance records (the
// layouts of body.vert.glsl and line.vert.glsl), each sphere's level of detail, the planes in
// drawing order with their scissor rectangles, and the sun's shadow projection.

#include "cps/render/draw_list.h"

#include <glm/glm.hpp>

#include <array>
#include <cstddef>
#include <vector>

namespace cps::render {

constexpr int k_shadow_size = 2048;  // shadow map side, texels
// Sphere level of detail: icospheres subdivided 1..4 times (80, 320, 1280, 5120 triangles). Each
// sphere is drawn with the coarsest mesh whose silhouette stays within k_sphere_max_error_px of
// the true circle (see sphere_lod_limits_px in frame_plan.cpp).
constexpr int k_sphere_min_subdivisions = 1;
constexpr int k_sphere_lods = 4;
constexpr float k_sphere_max_error_px = 0.5f;  // pixels; typical 0.5
constexpr int k_max_clip_planes = 16;          // size of u_clip in plane.frag.glsl

/// One box or sphere instance (body.vert.glsl's per-instance attributes 2-5): centre (m),
/// orientation (unit quaternion x, y, z, w), half extents (m; the radius three times for a
/// sphere), colour (linear RGB in [0, 1], then alpha in [0, 1]).
struct BodyInstance {
  float center[3];
  float orientation[4];  // x, y, z, w
  float half_extents[3];
  float color[4];  // linear RGB, alpha
};
static_assert(sizeof(BodyInstance) == 14 * sizeof(float));

/// One line instance (line.vert.glsl's attributes 1-4): ends a and b (m), colour (RGB in
/// [0, 1]), width (pixels, in [0.5, 256]).
struct LineInstance {
  float a[3];
  float b[3];
  float color[3];
  float width_px;
};
static_assert(sizeof(LineInstance) == 10 * sizeof(float));

/// One valid plane of the draw list as plane.vert.glsl and plane.frag.glsl take it: the square
/// of side 2 half_size (m) centred on `origin`, spanned by the unit tangents t1, t2, on the plane
/// {x : dot(normal, x) = offset} (unit normal, m). Colours linear RGB clamped to [0, 1].
struct PlaneDraw {
  std::size_t index;  // position in DrawList::planes
  float offset;       // m, with the unit normal
  glm::vec3 origin;
  glm::vec3 t1;
  glm::vec3 t2;
  glm::vec3 normal;
  float half_size;
  float checker;
  glm::vec3 color_a;
  glm::vec3 color_b;
  float alpha;
  float eye_distance;  // m, from the eye to origin
  /// Drawn at all: alpha > 0 and some of it on screen (see plane_scissor in frame_plan.cpp).
  bool visible;
  std::array<int, 4> scissor;  // x, y, w, h in GL window coordinates (pixels), when visible
};

/// The sun's shadow map projection: world to light clip space, and the size of one shadow texel
/// (m). Disabled when the draw list has no box or sphere.
struct ShadowSetup {
  bool enabled = false;
  glm::mat4 view_proj{1.0f};
  float texel_world = 0.0f;  // m per shadow texel
};

/// A pixel rectangle in GL window coordinates (origin bottom left): x, y, width, height.
using PixelRect = std::array<int, 4>;

/// The camera and lights of one frame, from DrawList::camera, light_direction and background,
/// with fallbacks for degenerate values (see plan_view in frame_plan.cpp).
struct FrameView {
  int width = 1;  // pixels
  int height = 1;
  glm::mat4 view{1.0f};  // world to eye
  glm::mat4 proj{1.0f};  // eye to clip (perspective)
  glm::mat4 view_proj{1.0f};
  glm::vec3 eye{0.0f};      // m
  glm::vec3 forward{0.0f};  // unit view direction
  float near_m = 0.1f;
  float focal_px = 1.0f;        // pixels per unit of tan(angle) off the view axis, vertically
  glm::vec3 light_dir{0.0f};    // unit, along which the sun's light travels
  glm::vec3 fill_dir{0.0f};     // unit, the camera-relative fill light
  glm::vec3 background{0.0f};   // clear colour, RGB in [0, 1]
  glm::vec3 background_linear{0.0f};  // background^2.2
  glm::vec2 fog{0.0f};          // m: distances where fog starts and where it is complete
};

/// What each pass of one frame draws. Kept by the renderer across frames so that its vectors keep
/// their capacity; build() refills everything.
class FramePlan {
 public:
  FramePlan();

  /// Plans one frame of `list` for a width x height image (pixels, >= 1). Items with non-finite
  /// values or non-positive sizes (or alpha <= 0) are left out; never throws but for
  /// std::bad_alloc.
  void build(const DrawList& list, int width, int height);

  FrameView view;
  ShadowSetup shadow;
  // Opaque bodies; spheres per level of detail, coarse to fine.
  std::vector<BodyInstance> boxes;
  std::array<std::vector<BodyInstance>, k_sphere_lods> spheres;
  // Ghosts (alpha < 1), each list sorted far to near from the eye.
  std::vector<BodyInstance> ghost_boxes;
  std::array<std::vector<BodyInstance>, k_sphere_lods> ghost_spheres;
  std::vector<LineInstance> lines;
  // Opaque planes first, then translucent ones far to near; invisible (alpha 0) planes included,
  // as they still clip the others.
  std::vector<PlaneDraw> planes;
  std::size_t first_translucent = 0;  // index in planes of the first plane with alpha < 1
  /// The pixels whose colour depends on the bodies, lines and shadows: the union of the screen
  /// bounds of every body and line and of the sun's shadow-map footprint on every plane (see
  /// plan_dynamic_rect in frame_plan.cpp); every other pixel shows the planes alone, lit as
  /// without a shadow map. Width or height 0: no such pixel.
  PixelRect dynamic_rect{0, 0, 0, 0};
  /// The rectangle the main passes draw in: the whole frame unless restrict_to narrowed it.
  PixelRect draw_rect{0, 0, 1, 1};

  /// Narrows draw_rect to `rect` (inside the frame) and every plane's scissor with it (planes
  /// left with nothing become invisible).
  void restrict_to(const PixelRect& rect);

  /// Whether any ghost box or sphere is planned.
  bool has_ghosts() const;

 private:
  void gather_bodies(const DrawList& list);
  void gather_lines(const DrawList& list);
  void gather_planes(const DrawList& list);
  void fit_shadow(const DrawList& list);
  bool plane_scissor(const PlaneDraw& d, std::array<int, 4>& rect) const;
  void plan_dynamic_rect();

  std::array<float, k_sphere_lods> sphere_limits_px_;  // see sphere_lod_limits_px
};

}  // namespace cps::render
