// bounds() and frame_bounds(): the camera framing helpers of draw_list.h.

#include "cps/render/draw_list.h"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cps::render {
namespace {

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void grow(bool& any, glm::vec3& lo, glm::vec3& hi, const glm::vec3& a, const glm::vec3& b) {
  if (!any) {
    lo = a;
    hi = b;
    any = true;
  } else {
    lo = glm::min(lo, a);
    hi = glm::max(hi, b);
  }
}

}  // namespace

// bounds: world AABB (m) of boxes (oriented boxes bounded with |R| h, as in Ericson, Real-Time
// Collision Detection 4.2.6) and spheres (centre +- radius); items with non-finite values are
// skipped. Returns false and leaves lo/hi untouched when nothing remains.
bool bounds(const DrawList& list, glm::vec3& lo, glm::vec3& hi) {
  bool any = false;
  glm::vec3 l(0.0f);
  glm::vec3 h(0.0f);
  for (const BoxItem& box : list.boxes) {
    // World half extents of the oriented box: e_i = sum_j |R_ij| h_j.
    const glm::mat3 r = glm::mat3_cast(glm::normalize(box.orientation));
    glm::vec3 e(0.0f);
    for (int j = 0; j < 3; ++j) e += glm::abs(r[j]) * std::abs(box.half_extents[j]);
    if (!finite(box.center) || !finite(e)) continue;
    grow(any, l, h, box.center - e, box.center + e);
  }
  for (const SphereItem& s : list.spheres) {
    const glm::vec3 e(std::abs(s.radius));
    if (!finite(s.center) || !finite(e)) continue;
    grow(any, l, h, s.center - e, s.center + e);
  }
  if (any) {
    lo = l;
    hi = h;
  }
  return any;
}

// frame_bounds: lo, hi in m (lo <= hi per axis, finite), aspect = width / height > 0, else
// std::invalid_argument. Eye at elevation 20 deg and azimuth 25 deg (towards +x) from +z around
// the box centre, at the distance where the bounding sphere of the box (radius r = |hi - lo| / 2)
// fits the narrower of the vertical (45 deg) and horizontal fields of view with 10% margin:
// d = 1.1 r / sin(min(fov_y, fov_x) / 2). near = d / 20, far = 25 d.
Camera frame_bounds(const glm::vec3& lo, const glm::vec3& hi, float aspect) {
  if (!finite(lo) || !finite(hi)) throw std::invalid_argument("frame_bounds: non-finite bounds");
  for (int i = 0; i < 3; ++i) {
    if (lo[i] > hi[i]) {
      throw std::invalid_argument("frame_bounds: lo > hi on axis " + std::to_string(i) + " (" +
                                  std::to_string(lo[i]) + " > " + std::to_string(hi[i]) + ")");
    }
  }
  if (!(aspect > 0.0f) || !std::isfinite(aspect)) {
    throw std::invalid_argument("frame_bounds: aspect must be > 0, got " + std::to_string(aspect));
  }
  constexpr float k_fov_y_deg = 45.0f;
  constexpr float k_elevation_deg = 20.0f;
  constexpr float k_azimuth_deg = 25.0f;
  constexpr float k_margin = 1.1f;

  Camera cam;
  cam.fov_y_deg = k_fov_y_deg;
  cam.up = glm::vec3(0.0f, 1.0f, 0.0f);
  cam.target = 0.5f * (lo + hi);
  const float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
  // A sphere of radius r seen from distance d fills a cone of half angle asin(r / d); it must fit
  // in the narrower of the vertical and the horizontal half field of view.
  const float half_v = glm::radians(0.5f * k_fov_y_deg);
  const float half_h = std::atan(std::tan(half_v) * aspect);
  const float half = std::min(half_v, half_h);
  const float distance = k_margin * radius / std::sin(half);
  const float el = glm::radians(k_elevation_deg);
  const float az = glm::radians(k_azimuth_deg);
  const glm::vec3 dir(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
  cam.eye = cam.target + distance * dir;
  // Near stays well in front of the ground under the camera; far reaches the horizon of a large
  // ground plane. far / near = 500 keeps a 24-bit depth buffer precise.
  cam.near_m = 0.05f * distance;
  cam.far_m = 25.0f * distance;
  return cam;
}

}  // namespace cps::render
