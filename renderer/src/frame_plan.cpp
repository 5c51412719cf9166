// FramePlan: from a DrawList to what each pass draws (see frame_plan.h). CPU only.

#include "frame_plan.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace cps::render {
namespace {

bool finite(float v) { return std::isfinite(v); }
bool finite(const glm::vec3& v) { return finite(v.x) && finite(v.y) && finite(v.z); }

void put(float* dst, const glm::vec3& v) {
  dst[0] = v.x;
  dst[1] = v.y;
  dst[2] = v.z;
}

BodyInstance make_instance(const glm::vec3& center, const glm::quat& q, const glm::vec3& half,
                           const glm::vec3& color, float alpha) {
  BodyInstance b{};
  put(b.center, center);
  b.orientation[0] = q.x;
  b.orientation[1] = q.y;
  b.orientation[2] = q.z;
  b.orientation[3] = q.w;
  put(b.half_extents, half);
  put(b.color, glm::clamp(color, 0.0f, 1.0f));
  b.color[3] = std::clamp(alpha, 0.0f, 1.0f);
  return b;
}

glm::quat safe_normalize(const glm::quat& q) {
  const float n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!finite(n) || n < 1e-12f) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  return glm::quat(q.w / n, q.x / n, q.y / n, q.z / n);
}

/// Projected radius (pixels) up to which icosphere level k_sphere_min_subdivisions + i keeps its
/// silhouette error within k_sphere_max_error_px; the finest level takes every larger sphere.
/// An icosphere of level L deviates from the sphere by at most r * (1 - cos(a/2)), a = the
/// longest edge's angle (63.4 deg for the icosahedron, about halved by each subdivision), so the
/// allowed projected radius of level L is k_sphere_max_error_px / (1 - cos(a_L / 2)).
std::array<float, k_sphere_lods> sphere_lod_limits_px() {
  std::array<float, k_sphere_lods> limits{};
  const float edge0 = std::atan(2.0f);  // icosahedron edge angle: 63.43 deg, in radians
  for (int i = 0; i < k_sphere_lods; ++i) {
    const float edge = edge0 / static_cast<float>(1 << (k_sphere_min_subdivisions + i));
    limits[static_cast<std::size_t>(i)] = k_sphere_max_error_px / (1.0f - std::cos(0.5f * edge));
  }
  limits.back() = std::numeric_limits<float>::max();
  return limits;
}

/// The world axis least aligned with unit vector n.
glm::vec3 least_aligned_axis(const glm::vec3& n) {
  const glm::vec3 a = glm::abs(n);
  if (a.x <= a.y && a.x <= a.z) return {1.0f, 0.0f, 0.0f};
  if (a.y <= a.z) return {0.0f, 1.0f, 0.0f};
  return {0.0f, 0.0f, 1.0f};
}

/// The camera and lights of `list` for a width x height image. Guards lookAt against a
/// degenerate camera (eye on the target, or up along the view, e.g. a top-down view with
/// up = +y) by falling back to a valid direction / up vector, and a degenerate sun to
/// DrawList's default.
FrameView plan_view(const DrawList& list, int width, int height) {
  const Camera& cam = list.camera;
  FrameView v;
  v.width = width;
  v.height = height;
  glm::vec3 light_dir = list.light_direction;
  if (!finite(light_dir) || glm::length(light_dir) < 1e-6f) light_dir = DrawList{}.light_direction;
  v.light_dir = glm::normalize(light_dir);

  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const float fov = std::clamp(cam.fov_y_deg, 1.0f, 179.0f);
  v.near_m = cam.near_m > 0.0f ? cam.near_m : 0.1f;
  const float far_m = cam.far_m > v.near_m ? cam.far_m : v.near_m * 1000.0f;
  v.proj = glm::perspective(glm::radians(fov), aspect, v.near_m, far_m);
  glm::vec3 target = cam.target;
  if (!(glm::length(target - cam.eye) > 1e-6f)) target = cam.eye - glm::vec3(0.0f, 0.0f, 1.0f);
  v.eye = cam.eye;
  v.forward = glm::normalize(target - cam.eye);
  glm::vec3 up = finite(cam.up) && glm::length(cam.up) > 1e-6f ? glm::normalize(cam.up)
                                                                : glm::vec3(0.0f, 1.0f, 0.0f);
  if (glm::length(glm::cross(v.forward, up)) < 1e-4f) up = least_aligned_axis(v.forward);
  v.view = glm::lookAt(cam.eye, target, up);
  v.view_proj = v.proj * v.view;
  v.focal_px = 0.5f * static_cast<float>(height) / std::tan(0.5f * glm::radians(fov));

  v.background = glm::clamp(finite(list.background) ? list.background : glm::vec3(0.0f), 0.0f, 1.0f);
  v.background_linear = glm::pow(v.background, glm::vec3(2.2f));
  // Fill light from the camera's right, a little above and in front.
  const glm::vec3 right = glm::normalize(glm::cross(v.forward, up));
  const glm::vec3 cam_up = glm::cross(right, v.forward);
  v.fill_dir = glm::normalize(0.8f * right + 0.35f * cam_up - 0.5f * v.forward);
  // Fog only far away: starts at 4x the eye-target distance, complete at 12x.
  const float focus = std::max(glm::distance(cam.eye, target), v.near_m);
  v.fog = glm::vec2(4.0f * focus, 12.0f * focus);
  return v;
}

}  // namespace

FramePlan::FramePlan() : sphere_limits_px_(sphere_lod_limits_px()) {}

bool FramePlan::has_ghosts() const {
  return !ghost_boxes.empty() ||
         std::any_of(ghost_spheres.begin(), ghost_spheres.end(),
                     [](const std::vector<BodyInstance>& v) { return !v.empty(); });
}

// build: the view first (gather_bodies needs the eye and focal length), the planes before the
// shadow (its depth range reaches the planes) and before their scissors (each plane is clipped by
// the others).
void FramePlan::build(const DrawList& list, int width, int height) {
  view = plan_view(list, width, height);
  gather_bodies(list);
  gather_lines(list);
  gather_planes(list);
  fit_shadow(list);
  for (PlaneDraw& d : planes) {
    d.scissor = {0, 0, width, height};
    d.visible = d.alpha > 0.0f && plane_scissor(d, d.scissor);
  }
  draw_rect = {0, 0, width, height};
  plan_dynamic_rect();
}

void FramePlan::restrict_to(const PixelRect& rect) {
  const auto intersect = [](const PixelRect& a, const PixelRect& b) {
    const int x0 = std::max(a[0], b[0]);
    const int y0 = std::max(a[1], b[1]);
    const int x1 = std::min(a[0] + a[2], b[0] + b[2]);
    const int y1 = std::min(a[1] + a[3], b[1] + b[3]);
    return PixelRect{x0, y0, std::max(x1 - x0, 0), std::max(y1 - y0, 0)};
  };
  draw_rect = intersect(draw_rect, rect);
  for (PlaneDraw& d : planes) {
    if (!d.visible) continue;
    d.scissor = intersect(d.scissor, draw_rect);
    d.visible = d.scissor[2] > 0 && d.scissor[3] > 0;
  }
}

namespace {

/// Pixel bounds [lo, hi] of a set of points; `whole` once a point cannot be bounded (on or
/// behind the eye plane), then the whole frame counts.
struct ScreenBounds {
  glm::vec2 lo{std::numeric_limits<float>::max()};
  glm::vec2 hi{std::numeric_limits<float>::lowest()};
  bool whole = false;
};

}  // namespace

/// dynamic_rect: the screen bounds, widened by 2 pixels (multisample positions, rounding), of
///  - each body's axis-aligned bounding box (its mesh lies inside it), ghosts included;
///  - each line's ends, widened by its width (its quad and square caps reach width / sqrt 2);
///  - on each plane drawn, where the shadow map can darken it: the bounding box of the shadow
///    casters (the opaque bodies) carried along the light onto the plane, widened in the plane
///    by 8 texels over |cos| of the light's incidence (the 3x3 filter's reach, 2.5 texels, plus
///    lighting.glsl's normal offset, at most 3). Elsewhere every filter tap reads a texel no
///    caster covers (cleared to depth 1, or the border: lit), so the plane is lit as with no
///    shadow map at all.
/// A point on or behind the near plane (a body or line reaching behind the eye), or a plane
/// almost parallel to the light, makes it the whole frame.
void FramePlan::plan_dynamic_rect() {
  ScreenBounds b;
  const float w = static_cast<float>(view.width);
  const float h = static_cast<float>(view.height);
  const float front = glm::dot(view.forward, view.eye) + view.near_m;
  const auto add = [&](const glm::vec3& p, float margin_px) {
    if (b.whole) return;
    if (!(glm::dot(view.forward, p) > front)) {
      b.whole = true;
      return;
    }
    const glm::vec4 c = view.view_proj * glm::vec4(p, 1.0f);
    const glm::vec2 px((0.5f * c.x / c.w + 0.5f) * w, (0.5f * c.y / c.w + 0.5f) * h);
    b.lo = glm::min(b.lo, px - margin_px);
    b.hi = glm::max(b.hi, px + margin_px);
  };
  // The bounding box of the shadow casters (the opaque bodies), m.
  bool casters = false;
  glm::vec3 clo(std::numeric_limits<float>::max());
  glm::vec3 chi(std::numeric_limits<float>::lowest());
  const auto add_bodies = [&](const std::vector<BodyInstance>& list, bool cast) {
    for (const BodyInstance& i : list) {
      const glm::quat q(i.orientation[3], i.orientation[0], i.orientation[1], i.orientation[2]);
      const glm::mat3 r = glm::mat3_cast(q);
      const glm::vec3 half(i.half_extents[0], i.half_extents[1], i.half_extents[2]);
      // World half extents of the rotated box: |R| half.
      const glm::vec3 e = glm::abs(r[0]) * half.x + glm::abs(r[1]) * half.y + glm::abs(r[2]) * half.z;
      const glm::vec3 c(i.center[0], i.center[1], i.center[2]);
      if (cast) {
        casters = true;
        clo = glm::min(clo, c - e);
        chi = glm::max(chi, c + e);
      }
      for (int k = 0; k < 8; ++k) {
        add(c + glm::vec3((k & 1) ? e.x : -e.x, (k & 2) ? e.y : -e.y, (k & 4) ? e.z : -e.z), 0.0f);
      }
    }
  };
  add_bodies(boxes, true);
  add_bodies(ghost_boxes, false);
  for (const std::vector<BodyInstance>& v : spheres) add_bodies(v, true);
  for (const std::vector<BodyInstance>& v : ghost_spheres) add_bodies(v, false);
  for (const LineInstance& l : lines) {
    add(glm::vec3(l.a[0], l.a[1], l.a[2]), l.width_px);
    add(glm::vec3(l.b[0], l.b[1], l.b[2]), l.width_px);
  }
  if (shadow.enabled && casters && !b.whole) {
    for (const PlaneDraw& p : planes) {
      if (!p.visible) continue;
      const float denom = glm::dot(p.normal, view.light_dir);
      if (std::abs(denom) < 0.05f) {
        b.whole = true;
        break;
      }
      const float margin = 8.0f * shadow.texel_world / std::abs(denom);
      for (int k = 0; k < 8 && !b.whole; ++k) {
        const glm::vec3 c((k & 1) ? chi.x : clo.x, (k & 2) ? chi.y : clo.y, (k & 4) ? chi.z : clo.z);
        const glm::vec3 on_plane = c + ((p.offset - glm::dot(p.normal, c)) / denom) * view.light_dir;
        for (int m = 0; m < 4; ++m) {
          add(on_plane + ((m & 1) ? margin : -margin) * p.t1 + ((m & 2) ? margin : -margin) * p.t2,
              0.0f);
        }
      }
    }
  }
  if (b.whole) {
    dynamic_rect = {0, 0, view.width, view.height};
    return;
  }
  if (!(b.hi.x >= b.lo.x) || !(b.hi.y >= b.lo.y)) {
    dynamic_rect = {0, 0, 0, 0};
    return;
  }
  const float x0 = std::clamp(std::floor(b.lo.x) - 2.0f, 0.0f, w);
  const float y0 = std::clamp(std::floor(b.lo.y) - 2.0f, 0.0f, h);
  const float x1 = std::clamp(std::ceil(b.hi.x) + 2.0f, 0.0f, w);
  const float y1 = std::clamp(std::ceil(b.hi.y) + 2.0f, 0.0f, h);
  dynamic_rect = {static_cast<int>(x0), static_cast<int>(y0), static_cast<int>(std::max(x1 - x0, 0.0f)),
                  static_cast<int>(std::max(y1 - y0, 0.0f))};
}

/// Copies the valid boxes and spheres into the instance lists, opaque or ghost by alpha. Spheres
/// are sorted by level of detail from their projected radius r * focal_px / depth (pixels; depth
/// along the view direction, m; spheres reaching behind the eye count as large).
void FramePlan::gather_bodies(const DrawList& list) {
  const glm::vec3& eye = view.eye;
  boxes.clear();
  ghost_boxes.clear();
  for (const BoxItem& b : list.boxes) {
    const glm::vec3 h = glm::abs(b.half_extents);
    if (!finite(b.center) || !finite(h) || !finite(b.color) || !(std::min({h.x, h.y, h.z}) > 0.0f)) continue;
    if (!finite(b.alpha) || !(b.alpha > 0.0f)) continue;
    (b.alpha < 1.0f ? ghost_boxes : boxes)
        .push_back(make_instance(b.center, safe_normalize(b.orientation), h, b.color, b.alpha));
  }
  for (std::vector<BodyInstance>& v : spheres) v.clear();
  for (std::vector<BodyInstance>& v : ghost_spheres) v.clear();
  for (const SphereItem& s : list.spheres) {
    const float r = std::abs(s.radius);
    if (!finite(s.center) || !finite(r) || !finite(s.color) || !(r > 0.0f)) continue;
    if (!finite(s.alpha) || !(s.alpha > 0.0f)) continue;
    const float depth = glm::dot(s.center - eye, view.forward);
    const float radius_px = depth > r ? r * view.focal_px / depth : std::numeric_limits<float>::max();
    std::size_t lod = 0;
    while (lod + 1 < sphere_limits_px_.size() && radius_px > sphere_limits_px_[lod]) ++lod;
    (s.alpha < 1.0f ? ghost_spheres : spheres)[lod].push_back(
        make_instance(s.center, safe_normalize(s.orientation), glm::vec3(r), s.color, s.alpha));
  }
  // Far to near, so that where ghosts overlap the nearer one is blended last.
  const auto far_first = [&eye](const BodyInstance& x, const BodyInstance& y) {
    const auto d2 = [&eye](const BodyInstance& b) {
      const glm::vec3 c(b.center[0], b.center[1], b.center[2]);
      return glm::dot(c - eye, c - eye);
    };
    return d2(x) > d2(y);
  };
  std::stable_sort(ghost_boxes.begin(), ghost_boxes.end(), far_first);
  for (std::vector<BodyInstance>& v : ghost_spheres) {
    std::stable_sort(v.begin(), v.end(), far_first);
  }
}

/// Copies the valid lines, colours clamped to [0, 1] and widths to [0.5, 256] pixels.
void FramePlan::gather_lines(const DrawList& list) {
  lines.clear();
  for (const LineItem& l : list.lines) {
    if (!finite(l.a) || !finite(l.b) || !finite(l.color) || !finite(l.width_px)) continue;
    LineInstance li{};
    put(li.a, l.a);
    put(li.b, l.b);
    put(li.color, glm::clamp(l.color, 0.0f, 1.0f));
    li.width_px = std::clamp(l.width_px, 0.5f, 256.0f);
    lines.push_back(li);
  }
}

/// Copies the valid planes, normalised, with a tangent basis, opaque first and then translucent
/// from far to near; the scissors are left to build().
void FramePlan::gather_planes(const DrawList& list) {
  planes.clear();
  for (const PlaneItem& p : list.planes) {
    const float len = glm::length(p.normal);
    if (!finite(p.normal) || !(len > 1e-6f) || !finite(p.offset) || !finite(p.center_hint) ||
        !(p.half_size > 0.0f) || !finite(p.half_size) || !(p.checker_m > 0.0f) ||
        !finite(p.checker_m) || !finite(p.alpha)) {
      continue;
    }
    PlaneDraw d{};
    d.index = static_cast<std::size_t>(&p - list.planes.data());
    d.normal = p.normal / len;
    d.offset = p.offset / len;
    d.origin = p.center_hint - (glm::dot(d.normal, p.center_hint) - d.offset) * d.normal;
    const glm::vec3 a = least_aligned_axis(d.normal);
    d.t1 = glm::normalize(a - glm::dot(a, d.normal) * d.normal);
    d.t2 = glm::cross(d.normal, d.t1);
    d.half_size = p.half_size;
    d.checker = p.checker_m;
    d.color_a = glm::clamp(p.color_a, 0.0f, 1.0f);
    d.color_b = glm::clamp(p.color_b, 0.0f, 1.0f);
    d.alpha = std::clamp(p.alpha, 0.0f, 1.0f);
    d.eye_distance = glm::distance(view.eye, d.origin);
    planes.push_back(d);  // invisible (alpha 0) planes still clip the others
  }
  std::stable_sort(planes.begin(), planes.end(), [](const PlaneDraw& x, const PlaneDraw& y) {
    const bool xo = x.alpha >= 1.0f;
    const bool yo = y.alpha >= 1.0f;
    if (xo != yo) return xo;
    if (xo) return false;
    return x.eye_distance > y.eye_distance;
  });
  first_translucent = static_cast<std::size_t>(
      std::find_if(planes.begin(), planes.end(), [](const PlaneDraw& d) { return d.alpha < 1.0f; }) -
      planes.begin());
}

/// Orthographic sun projection fitted to the bodies' bounds; its depth range is extended to the
/// planes under them (along the light) so that every shadow receiver lies inside it.
void FramePlan::fit_shadow(const DrawList& list) {
  shadow = ShadowSetup{};
  const glm::vec3& light_dir = view.light_dir;
  glm::vec3 lo;
  glm::vec3 hi;
  if (!bounds(list, lo, hi)) return;
  const glm::vec3 center = 0.5f * (lo + hi);
  const float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
  const glm::vec3 light_eye = center - light_dir * (2.0f * radius + 1.0f);
  const glm::mat4 light_view = glm::lookAt(light_eye, center, least_aligned_axis(light_dir));
  glm::vec3 llo(std::numeric_limits<float>::max());
  glm::vec3 lhi(std::numeric_limits<float>::lowest());
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
    const glm::vec3 q = glm::vec3(light_view * glm::vec4(corner, 1.0f));
    llo = glm::min(llo, q);
    lhi = glm::max(lhi, q);
  }
  const float extent = std::max(lhi.x - llo.x, lhi.y - llo.y);
  const float pad = 0.02f * extent + 0.01f;
  llo.x -= pad;
  llo.y -= pad;
  lhi.x += pad;
  lhi.y += pad;
  float near_d = -lhi.z - pad;  // the light looks down -z
  float far_d = -llo.z + pad;
  const float far_cap = near_d + 20.0f * radius + 1.0f;
  const glm::mat4 inv_view = glm::inverse(light_view);
  for (const PlaneDraw& p : planes) {
    const float denom = glm::dot(p.normal, light_dir);
    if (std::abs(denom) < 0.05f) continue;  // plane almost parallel to the light
    for (int i = 0; i < 4; ++i) {
      const glm::vec3 o(inv_view * glm::vec4((i & 1) ? lhi.x : llo.x, (i & 2) ? lhi.y : llo.y, 0.0f, 1.0f));
      const float t = (p.offset - glm::dot(p.normal, o)) / denom;  // depth along the light
      if (t > far_d) far_d = std::min(t + pad, far_cap);
    }
  }
  const glm::mat4 proj = glm::ortho(llo.x, lhi.x, llo.y, lhi.y, near_d, far_d);
  shadow.enabled = true;
  shadow.view_proj = proj * light_view;
  shadow.texel_world = std::max(lhi.x - llo.x, lhi.y - llo.y) / static_cast<float>(k_shadow_size);
}

/// The pixel rectangle {x, y, w, h} (GL window coordinates) holding every fragment of plane d
/// that plane.frag.glsl keeps: its square clipped (Sutherland-Hodgman) by the solid sides of
/// the other planes it is clipped by and by the near plane, projected, widened by 1 pixel. The
/// shader's discard stays exact; the scissor only spares llvmpipe the fragments it would
/// discard (and the sky beyond a ground plane's far edge). Returns false if nothing is left;
/// leaves rect as it is when the square reaches the eye plane.
bool FramePlan::plane_scissor(const PlaneDraw& d, std::array<int, 4>& rect) const {
  std::vector<glm::vec3> poly = {d.origin + d.half_size * (-d.t1 - d.t2),
                                 d.origin + d.half_size * (d.t1 - d.t2),
                                 d.origin + d.half_size * (d.t1 + d.t2),
                                 d.origin + d.half_size * (-d.t1 + d.t2)};
  std::vector<glm::vec3> next;
  // Keeps the part of poly where dot(n, x) >= m.
  const auto clip = [&](const glm::vec3& n, float m) {
    next.clear();
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const glm::vec3& a = poly[i];
      const glm::vec3& b = poly[(i + 1) % poly.size()];
      const float da = glm::dot(n, a) - m;
      const float db = glm::dot(n, b) - m;
      if (da >= 0.0f) next.push_back(a);
      if ((da >= 0.0f) != (db >= 0.0f)) next.push_back(a + (da / (da - db)) * (b - a));
    }
    poly.swap(next);
  };
  int n_clip = 0;
  for (const PlaneDraw& other : planes) {
    if (other.index == d.index || n_clip == k_max_clip_planes) continue;
    ++n_clip;
    clip(other.normal, other.offset - 1e-3f);  // a little wider than the shader's 1e-4 m
    if (poly.empty()) return false;
  }
  clip(view.forward, glm::dot(view.forward, view.eye) + view.near_m);
  if (poly.empty()) return false;
  const auto width = static_cast<float>(view.width);
  const auto height = static_cast<float>(view.height);
  glm::vec2 lo(std::numeric_limits<float>::max());
  glm::vec2 hi(std::numeric_limits<float>::lowest());
  for (const glm::vec3& p : poly) {
    const glm::vec4 c = view.view_proj * glm::vec4(p, 1.0f);
    if (!(c.w > 0.0f)) return true;  // numerically on the eye plane: keep the whole viewport
    const glm::vec2 px((0.5f * c.x / c.w + 0.5f) * width, (0.5f * c.y / c.w + 0.5f) * height);
    lo = glm::min(lo, px);
    hi = glm::max(hi, px);
  }
  const float x0 = std::clamp(std::floor(lo.x) - 1.0f, 0.0f, width);
  const float y0 = std::clamp(std::floor(lo.y) - 1.0f, 0.0f, height);
  const float x1 = std::clamp(std::ceil(hi.x) + 1.0f, 0.0f, width);
  const float y1 = std::clamp(std::ceil(hi.y) + 1.0f, 0.0f, height);
  if (!(x1 > x0) || !(y1 > y0)) return false;
  rect = {static_cast<int>(x0), static_cast<int>(y0), static_cast<int>(x1 - x0),
          static_cast<int>(y1 - y0)};
  return true;
}

}  // namespace cps::render
