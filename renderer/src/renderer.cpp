// Renderer: GL resources kept across frames, the shadow pass, the main pass and the readback.
//
// Frame outline (all passes use instancing; the only per-frame GL traffic is uniforms and
// instance-buffer updates):
//   1. shadow pass: boxes and spheres into a 2048^2 depth texture from the sun, orthographic
//      projection fitted to the bodies and to the part of each plane their shadows can reach;
//   2. main pass into a 4x multisampled framebuffer: bodies, opaque planes, lines, then planes
//      with alpha < 1 back to front, blended, without depth writes, then the ghosts (bodies with
//      alpha < 1) back to front, blended, depth tested but without depth writes;
//   3. resolve (blit) into the context's framebuffer, glFinish, read back top row first.

#include "cps/render/renderer.h"

#include "gl_objects.h"
#include "meshes.h"
#include "gl_context.h"
#include "shader_program.h"

#include "cps_render_embedded_shaders.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace cps::render {
namespace {

constexpr int k_min_size = 1;
constexpr int k_max_size = 8192;
constexpr int k_shadow_size = 2048;
constexpr int k_msaa_samples = 4;
// Above this many pixels a 4x RGBA8 + depth multisampled buffer would exceed ~512 MB.
constexpr long long k_msaa_max_pixels = 4096LL * 4096LL;
// Sphere level of detail: icospheres subdivided 1..4 times (80, 320, 1280, 5120 triangles). Each
// sphere is drawn with the coarsest mesh whose silhouette stays within k_sphere_max_error_px of
// the true circle: an icosphere of level L deviates from the sphere by at most r * (1 - cos(a/2)),
// a = the longest edge's angle (63.4 deg for the icosahedron, about halved by each subdivision),
// so the allowed projected radius of level L is k_sphere_max_error_px / (1 - cos(a_L / 2)).
constexpr int k_sphere_min_subdivisions = 1;
constexpr int k_sphere_lods = 4;
constexpr float k_sphere_max_error_px = 0.5f;  // pixels; typical 0.5
constexpr int k_max_clip_planes = 16;     // size of u_clip in plane.frag.glsl

struct BodyInstance {
  float center[3];
  float orientation[4];  // x, y, z, w
  float half_extents[3];
  float color[4];  // linear RGB, alpha
};
static_assert(sizeof(BodyInstance) == 14 * sizeof(float));

struct LineInstance {
  float a[3];
  float b[3];
  float color[3];
  float width_px;
};
static_assert(sizeof(LineInstance) == 10 * sizeof(float));

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
  float eye_distance;
};

struct ShadowSetup {
  bool enabled = false;
  glm::mat4 view_proj{1.0f};
  float texel_world = 0.0f;  // m per shadow texel
};

bool finite(float v) { return std::isfinite(v); }
bool finite(const glm::vec3& v) { return finite(v.x) && finite(v.y) && finite(v.z); }

void check_size(const char* what, int value) {
  if (value < k_min_size || value > k_max_size) {
    throw std::invalid_argument("cps::render::Renderer: " + std::string(what) + " " +
                                std::to_string(value) + " out of range [" +
                                std::to_string(k_min_size) + ", " + std::to_string(k_max_size) +
                                "]");
  }
}

std::string gl_error_name(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: break;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%04X", static_cast<unsigned>(e));
  return buf;
}

void check_gl(const char* where) {
  const GLenum e = glGetError();
  if (e == GL_NO_ERROR) return;
  while (glGetError() != GL_NO_ERROR) {
  }
  throw std::runtime_error(std::string("cps::render: OpenGL error ") + gl_error_name(e) + " (" +
                           std::to_string(e) + ") " + where);
}

/// Uploads `bytes` to `buffer` (bound to GL_ARRAY_BUFFER), growing its store only when needed.
void upload(const gl::Buffer& buffer, std::size_t& capacity, const void* data, std::size_t bytes) {
  glBindBuffer(GL_ARRAY_BUFFER, buffer.id());
  if (bytes > capacity) {
    capacity = std::max(bytes, 2 * capacity);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(capacity), nullptr, GL_DYNAMIC_DRAW);
  }
  if (bytes > 0) glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data);
}

void float_attrib(GLuint index, int components, GLsizei stride, std::size_t offset, bool instanced) {
  glEnableVertexAttribArray(index);
  glVertexAttribPointer(index, components, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<const void*>(offset));
  glVertexAttribDivisor(index, instanced ? 1 : 0);
}

/// A unit mesh with its per-instance body buffer (layout of body.vert.glsl).
struct InstancedMesh {
  gl::VertexArray vao;
  gl::Buffer vertices;
  gl::Buffer indices;
  gl::Buffer instances;
  GLsizei index_count = 0;
  std::size_t capacity = 0;

  explicit InstancedMesh(const MeshData& mesh)
      : vao(gl::VertexArray::create()),
        vertices(gl::Buffer::create()),
        indices(gl::Buffer::create()),
        instances(gl::Buffer::create()),
        index_count(static_cast<GLsizei>(mesh.indices.size())) {
    glBindVertexArray(vao.id());
    glBindBuffer(GL_ARRAY_BUFFER, vertices.id());
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.vertices.size() * sizeof(MeshVertex)),
                 mesh.vertices.data(), GL_STATIC_DRAW);
    float_attrib(0, 3, sizeof(MeshVertex), offsetof(MeshVertex, position), false);
    float_attrib(1, 3, sizeof(MeshVertex), offsetof(MeshVertex, normal), false);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, indices.id());
    glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(mesh.indices.size() * sizeof(std::uint32_t)),
                 mesh.indices.data(), GL_STATIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, instances.id());
    constexpr GLsizei stride = sizeof(BodyInstance);
    float_attrib(2, 3, stride, offsetof(BodyInstance, center), true);
    float_attrib(3, 4, stride, offsetof(BodyInstance, orientation), true);
    float_attrib(4, 3, stride, offsetof(BodyInstance, half_extents), true);
    float_attrib(5, 4, stride, offsetof(BodyInstance, color), true);
    glBindVertexArray(0);
  }

  void draw(GLsizei count) const {
    if (count == 0) return;
    glBindVertexArray(vao.id());
    glDrawElementsInstanced(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr, count);
  }
};

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

}  // namespace

struct Renderer::Impl {
  GlContext context;  // first member: created first, destroyed last
  ShaderProgram body_program;
  ShaderProgram shadow_program;
  ShaderProgram plane_program;
  ShaderProgram line_program;
  InstancedMesh cube;
  std::array<InstancedMesh, k_sphere_lods> spheres;  // coarse to fine
  std::array<float, k_sphere_lods> sphere_limits_px;
  gl::VertexArray line_vao;
  gl::Buffer line_corners;
  gl::Buffer line_instances;
  std::size_t line_capacity = 0;
  gl::VertexArray empty_vao;  // core profile needs a bound VAO even without attributes
  gl::Texture shadow_map;
  gl::Framebuffer shadow_fbo;
  int samples = 0;
  gl::Framebuffer msaa_fbo;
  gl::Renderbuffer msaa_color;
  gl::Renderbuffer msaa_depth;

  // CPU staging reused across frames.
  std::vector<BodyInstance> box_data;
  std::array<std::vector<BodyInstance>, k_sphere_lods> sphere_data;  // per level of detail
  // Ghosts (alpha < 1), each list sorted far to near from the eye.
  std::vector<BodyInstance> ghost_box_data;
  std::array<std::vector<BodyInstance>, k_sphere_lods> ghost_sphere_data;
  std::vector<LineInstance> line_data;
  std::vector<PlaneDraw> planes;

  Impl(int width, int height, Backend backend)
      : context(backend, width, height),
        body_program("body", {shaders::quat, shaders::body_vert},
                     {shaders::lighting, shaders::body_frag}),
        shadow_program("shadow", {shaders::quat, shaders::shadow_vert}, {shaders::shadow_frag}),
        plane_program("plane", {shaders::plane_vert}, {shaders::lighting, shaders::plane_frag}),
        line_program("line", {shaders::line_vert}, {shaders::line_frag}),
        cube(make_unit_cube()),
        spheres{InstancedMesh(make_unit_icosphere(k_sphere_min_subdivisions)),
                InstancedMesh(make_unit_icosphere(k_sphere_min_subdivisions + 1)),
                InstancedMesh(make_unit_icosphere(k_sphere_min_subdivisions + 2)),
                InstancedMesh(make_unit_icosphere(k_sphere_min_subdivisions + 3))},
        sphere_limits_px(sphere_lod_limits_px()),
        line_vao(gl::VertexArray::create()),
        line_corners(gl::Buffer::create()),
        line_instances(gl::Buffer::create()),
        empty_vao(gl::VertexArray::create()),
        shadow_map(gl::Texture::create()),
        shadow_fbo(gl::Framebuffer::create()) {
    init_lines();
    init_shadow_map();
    init_msaa(width, height);
    check_gl("while creating the renderer");
  }

  ~Impl() {
    // The GL objects below are deleted after this body: their context must be current.
    try {
      context.make_current();
    } catch (...) {
    }
  }

  void init_lines() {
    glBindVertexArray(line_vao.id());
    const std::array<float, 8> corners = {0, -1, 0, 1, 1, -1, 1, 1};
    glBindBuffer(GL_ARRAY_BUFFER, line_corners.id());
    glBufferData(GL_ARRAY_BUFFER, sizeof(corners), corners.data(), GL_STATIC_DRAW);
    float_attrib(0, 2, 2 * sizeof(float), 0, false);
    glBindBuffer(GL_ARRAY_BUFFER, line_instances.id());
    constexpr GLsizei stride = sizeof(LineInstance);
    float_attrib(1, 3, stride, offsetof(LineInstance, a), true);
    float_attrib(2, 3, stride, offsetof(LineInstance, b), true);
    float_attrib(3, 3, stride, offsetof(LineInstance, color), true);
    float_attrib(4, 1, stride, offsetof(LineInstance, width_px), true);
    glBindVertexArray(0);
  }

  void init_shadow_map() {
    glBindTexture(GL_TEXTURE_2D, shadow_map.id());
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, k_shadow_size, k_shadow_size, 0,
                 GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const std::array<float, 4> border = {1.0f, 1.0f, 1.0f, 1.0f};  // outside: never shadowed
    glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo.id());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_map.id(), 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("cps::render: shadow map framebuffer incomplete");
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  /// 4x MSAA when the implementation allows it; otherwise render straight into the context's
  /// framebuffer.
  void init_msaa(int width, int height) {
    GLint max_samples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    samples = std::min(k_msaa_samples, static_cast<int>(max_samples));
    if (static_cast<long long>(width) * height > k_msaa_max_pixels) samples = 0;
    if (samples < 2) {
      samples = 0;
      return;
    }
    msaa_fbo = gl::Framebuffer::create();
    msaa_color = gl::Renderbuffer::create();
    msaa_depth = gl::Renderbuffer::create();
    glBindRenderbuffer(GL_RENDERBUFFER, msaa_color.id());
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, msaa_depth.id());
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, msaa_fbo.id());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msaa_color.id());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, msaa_depth.id());
    const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (!complete || glGetError() != GL_NO_ERROR) {
      msaa_fbo.reset();
      msaa_color.reset();
      msaa_depth.reset();
      samples = 0;
    }
  }

  /// Copies the valid items into the staging buffers. Spheres are sorted by level of detail from
  /// their projected radius r * focal_px / depth (pixels; depth along the unit view direction
  /// `forward`, m; spheres reaching behind the eye count as large).
  void gather(const DrawList& list, const glm::vec3& eye, const glm::vec3& forward,
              float focal_px) {
    box_data.clear();
    ghost_box_data.clear();
    for (const BoxItem& b : list.boxes) {
      const glm::vec3 h = glm::abs(b.half_extents);
      if (!finite(b.center) || !finite(h) || !finite(b.color) || !(std::min({h.x, h.y, h.z}) > 0.0f)) continue;
      if (!finite(b.alpha) || !(b.alpha > 0.0f)) continue;
      (b.alpha < 1.0f ? ghost_box_data : box_data)
          .push_back(make_instance(b.center, safe_normalize(b.orientation), h, b.color, b.alpha));
    }
    for (std::vector<BodyInstance>& v : sphere_data) v.clear();
    for (std::vector<BodyInstance>& v : ghost_sphere_data) v.clear();
    for (const SphereItem& s : list.spheres) {
      const float r = std::abs(s.radius);
      if (!finite(s.center) || !finite(r) || !finite(s.color) || !(r > 0.0f)) continue;
      if (!finite(s.alpha) || !(s.alpha > 0.0f)) continue;
      const float depth = glm::dot(s.center - eye, forward);
      const float radius_px = depth > r ? r * focal_px / depth : std::numeric_limits<float>::max();
      std::size_t lod = 0;
      while (lod + 1 < sphere_limits_px.size() && radius_px > sphere_limits_px[lod]) ++lod;
      (s.alpha < 1.0f ? ghost_sphere_data : sphere_data)[lod].push_back(
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
    std::stable_sort(ghost_box_data.begin(), ghost_box_data.end(), far_first);
    for (std::vector<BodyInstance>& v : ghost_sphere_data) {
      std::stable_sort(v.begin(), v.end(), far_first);
    }
    line_data.clear();
    for (const LineItem& l : list.lines) {
      if (!finite(l.a) || !finite(l.b) || !finite(l.color) || !finite(l.width_px)) continue;
      LineInstance li{};
      put(li.a, l.a);
      put(li.b, l.b);
      put(li.color, glm::clamp(l.color, 0.0f, 1.0f));
      li.width_px = std::clamp(l.width_px, 0.5f, 256.0f);
      line_data.push_back(li);
    }
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
      d.eye_distance = glm::distance(eye, d.origin);
      planes.push_back(d);  // invisible (alpha 0) planes still clip the others
    }
    // Opaque planes first, then translucent ones from far to near.
    std::stable_sort(planes.begin(), planes.end(), [](const PlaneDraw& x, const PlaneDraw& y) {
      const bool xo = x.alpha >= 1.0f;
      const bool yo = y.alpha >= 1.0f;
      if (xo != yo) return xo;
      if (xo) return false;
      return x.eye_distance > y.eye_distance;
    });
  }

  /// Orthographic sun projection fitted to the bodies' bounds; its depth range is extended to the
  /// planes under them (along the light) so that every shadow receiver lies inside it.
  ShadowSetup fit_shadow(const DrawList& list, const glm::vec3& light_dir) const {
    ShadowSetup s;
    glm::vec3 lo;
    glm::vec3 hi;
    if (!bounds(list, lo, hi)) return s;
    const glm::vec3 center = 0.5f * (lo + hi);
    const float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
    const glm::vec3 light_eye = center - light_dir * (2.0f * radius + 1.0f);
    const glm::mat4 view = glm::lookAt(light_eye, center, least_aligned_axis(light_dir));
    glm::vec3 llo(std::numeric_limits<float>::max());
    glm::vec3 lhi(std::numeric_limits<float>::lowest());
    for (int i = 0; i < 8; ++i) {
      const glm::vec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
      const glm::vec3 q = glm::vec3(view * glm::vec4(corner, 1.0f));
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
    const glm::mat4 inv_view = glm::inverse(view);
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
    s.enabled = true;
    s.view_proj = proj * view;
    s.texel_world = std::max(lhi.x - llo.x, lhi.y - llo.y) / static_cast<float>(k_shadow_size);
    return s;
  }

  void set_lighting(const ShaderProgram& p, const glm::vec3& light_dir, const glm::vec3& eye,
                    const glm::vec3& fill_dir, const glm::vec3& background_linear,
                    const glm::vec2& fog, const ShadowSetup& shadow) const {
    p.set("u_light_dir", light_dir);
    p.set("u_eye", eye);
    p.set("u_fill_dir", fill_dir);
    p.set("u_background", background_linear);
    p.set("u_fog", fog);
    p.set("u_shadow_enabled", shadow.enabled ? 1 : 0);
    p.set("u_shadow_map", 0);
    p.set("u_light_view_proj", shadow.view_proj);
    p.set("u_shadow_offset", 1.5f * shadow.texel_world);
    p.set("u_shadow_texel", 1.0f / static_cast<float>(k_shadow_size));
  }

  /// The pixel rectangle {x, y, w, h} (GL window coordinates) holding every fragment of plane d
  /// that plane.frag.glsl keeps: its square clipped (Sutherland-Hodgman) by the solid sides of
  /// the other planes it is clipped by and by the near plane, projected, widened by 1 pixel. The
  /// shader's discard stays exact; the scissor only spares llvmpipe the fragments it would
  /// discard (and the sky beyond a ground plane's far edge). Returns false if nothing is left.
  bool plane_scissor(const PlaneDraw& d, const glm::mat4& view_proj, const glm::vec3& eye,
                     const glm::vec3& forward, float near_m, int width, int height,
                     std::array<GLint, 4>& rect) const {
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
    clip(forward, glm::dot(forward, eye) + near_m);
    if (poly.empty()) return false;
    glm::vec2 lo(std::numeric_limits<float>::max());
    glm::vec2 hi(std::numeric_limits<float>::lowest());
    for (const glm::vec3& p : poly) {
      const glm::vec4 c = view_proj * glm::vec4(p, 1.0f);
      if (!(c.w > 0.0f)) return true;  // numerically on the eye plane: keep the whole viewport
      const glm::vec2 px((0.5f * c.x / c.w + 0.5f) * static_cast<float>(width),
                         (0.5f * c.y / c.w + 0.5f) * static_cast<float>(height));
      lo = glm::min(lo, px);
      hi = glm::max(hi, px);
    }
    const float x0 = std::clamp(std::floor(lo.x) - 1.0f, 0.0f, static_cast<float>(width));
    const float y0 = std::clamp(std::floor(lo.y) - 1.0f, 0.0f, static_cast<float>(height));
    const float x1 = std::clamp(std::ceil(hi.x) + 1.0f, 0.0f, static_cast<float>(width));
    const float y1 = std::clamp(std::ceil(hi.y) + 1.0f, 0.0f, static_cast<float>(height));
    if (!(x1 > x0) || !(y1 > y0)) return false;
    rect = {static_cast<GLint>(x0), static_cast<GLint>(y0), static_cast<GLint>(x1 - x0),
            static_cast<GLint>(y1 - y0)};
    return true;
  }

  void draw_plane(const PlaneDraw& d, const std::array<GLint, 4>& scissor) const {
    glScissor(scissor[0], scissor[1], scissor[2], scissor[3]);
    // Every other plane clips this one (see plane.frag.glsl).
    std::array<glm::vec4, k_max_clip_planes> clip{};
    int n_clip = 0;
    for (const PlaneDraw& other : planes) {
      if (other.index == d.index || n_clip == k_max_clip_planes) continue;
      clip[static_cast<std::size_t>(n_clip++)] = glm::vec4(other.normal, other.offset);
    }
    plane_program.set("u_clip_count", n_clip);
    plane_program.set("u_clip", clip.data(), n_clip);
    plane_program.set("u_origin", d.origin);
    plane_program.set("u_t1", d.t1);
    plane_program.set("u_t2", d.t2);
    plane_program.set("u_normal", d.normal);
    plane_program.set("u_half_size", d.half_size);
    plane_program.set("u_checker", d.checker);
    plane_program.set("u_color_a", d.color_a);
    plane_program.set("u_color_b", d.color_b);
    plane_program.set("u_alpha", d.alpha);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  }

  Image draw(const DrawList& list) {
    context.make_current();
    const int width = context.width();
    const int height = context.height();
    const Camera& cam = list.camera;

    glm::vec3 light_dir = list.light_direction;
    if (!finite(light_dir) || glm::length(light_dir) < 1e-6f) light_dir = DrawList{}.light_direction;
    light_dir = glm::normalize(light_dir);

    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    const float fov = std::clamp(cam.fov_y_deg, 1.0f, 179.0f);
    const float near_m = cam.near_m > 0.0f ? cam.near_m : 0.1f;
    const float far_m = cam.far_m > near_m ? cam.far_m : near_m * 1000.0f;
    const glm::mat4 proj = glm::perspective(glm::radians(fov), aspect, near_m, far_m);
    // Guard lookAt against a degenerate camera (eye on the target, or up along the view, e.g.
    // a top-down view with up = +y): fall back to a valid direction / up vector.
    glm::vec3 target = cam.target;
    if (!(glm::length(target - cam.eye) > 1e-6f)) target = cam.eye - glm::vec3(0.0f, 0.0f, 1.0f);
    glm::vec3 forward = glm::normalize(target - cam.eye);
    glm::vec3 up = finite(cam.up) && glm::length(cam.up) > 1e-6f ? glm::normalize(cam.up)
                                                                  : glm::vec3(0.0f, 1.0f, 0.0f);
    if (glm::length(glm::cross(forward, up)) < 1e-4f) up = least_aligned_axis(forward);
    const glm::mat4 view = glm::lookAt(cam.eye, target, up);
    const glm::mat4 view_proj = proj * view;

    const float focal_px =
        0.5f * static_cast<float>(height) / std::tan(0.5f * glm::radians(fov));
    gather(list, cam.eye, forward, focal_px);
    const ShadowSetup shadow = fit_shadow(list, light_dir);

    upload(cube.instances, cube.capacity, box_data.data(), box_data.size() * sizeof(BodyInstance));
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      upload(spheres[i].instances, spheres[i].capacity, sphere_data[i].data(),
             sphere_data[i].size() * sizeof(BodyInstance));
    }
    upload(line_instances, line_capacity, line_data.data(), line_data.size() * sizeof(LineInstance));
    const auto n_boxes = static_cast<GLsizei>(box_data.size());
    const auto draw_spheres = [&] {
      for (std::size_t i = 0; i < spheres.size(); ++i) {
        spheres[i].draw(static_cast<GLsizei>(sphere_data[i].size()));
      }
    };

    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);

    // 1. Shadow pass. Front faces culled (the map stores the far side of each closed body) and a
    // slope-scaled polygon offset: together with the normal offset this avoids acne without
    // visible peter-panning at contacts.
    if (shadow.enabled) {
      glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo.id());
      glViewport(0, 0, k_shadow_size, k_shadow_size);
      glClear(GL_DEPTH_BUFFER_BIT);
      glEnable(GL_CULL_FACE);
      glCullFace(GL_FRONT);
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.5f, 2.0f);
      shadow_program.use();
      shadow_program.set("u_light_view_proj", shadow.view_proj);
      cube.draw(n_boxes);
      draw_spheres();
      glDisable(GL_POLYGON_OFFSET_FILL);
      glCullFace(GL_BACK);
    }

    // 2. Main pass.
    glBindFramebuffer(GL_FRAMEBUFFER, samples > 0 ? msaa_fbo.id() : context.framebuffer());
    glViewport(0, 0, width, height);
    const glm::vec3 bg = glm::clamp(finite(list.background) ? list.background : glm::vec3(0.0f),
                                    0.0f, 1.0f);
    glClearColor(bg.r, bg.g, bg.b, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    const glm::vec3 bg_linear = glm::pow(bg, glm::vec3(2.2f));

    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, shadow_map.id());

    // Fill light from the camera's right, a little above and in front.
    const glm::vec3 right = glm::normalize(glm::cross(forward, up));
    const glm::vec3 cam_up = glm::cross(right, forward);
    const glm::vec3 fill_dir = glm::normalize(0.8f * right + 0.35f * cam_up - 0.5f * forward);
    // Fog only far away: starts at 4x the eye-target distance, complete at 12x.
    const float focus = std::max(glm::distance(cam.eye, target), near_m);
    const glm::vec2 fog(4.0f * focus, 12.0f * focus);

    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    body_program.use();
    set_lighting(body_program, light_dir, cam.eye, fill_dir, bg_linear, fog, shadow);
    body_program.set("u_view_proj", view_proj);
    body_program.set("u_kind", 0);
    cube.draw(n_boxes);
    body_program.set("u_kind", 1);
    draw_spheres();

    glDisable(GL_CULL_FACE);
    plane_program.use();
    set_lighting(plane_program, light_dir, cam.eye, fill_dir, bg_linear, fog, shadow);
    plane_program.set("u_view_proj", view_proj);
    glBindVertexArray(empty_vao.id());
    auto first_translucent = std::find_if(planes.begin(), planes.end(),
                                          [](const PlaneDraw& d) { return d.alpha < 1.0f; });
    // Each plane drawn only inside the screen rectangle of its visible part.
    const auto draw_clipped = [&](const PlaneDraw& d) {
      std::array<GLint, 4> rect = {0, 0, width, height};
      if (plane_scissor(d, view_proj, cam.eye, forward, near_m, width, height, rect)) {
        draw_plane(d, rect);
      }
    };
    glEnable(GL_SCISSOR_TEST);
    for (auto it = planes.begin(); it != first_translucent; ++it) draw_clipped(*it);
    glDisable(GL_SCISSOR_TEST);

    if (!line_data.empty()) {
      line_program.use();
      line_program.set("u_view", view);
      line_program.set("u_proj", proj);
      line_program.set("u_viewport", glm::vec2(static_cast<float>(width), static_cast<float>(height)));
      line_program.set("u_near", near_m);
      glBindVertexArray(line_vao.id());
      glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(line_data.size()));
    }

    if (first_translucent != planes.end()) {
      glEnable(GL_BLEND);
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      glDepthMask(GL_FALSE);
      plane_program.use();
      glBindVertexArray(empty_vao.id());
      glEnable(GL_SCISSOR_TEST);
      for (auto it = first_translucent; it != planes.end(); ++it) {
        if (it->alpha > 0.0f) draw_clipped(*it);
      }
      glDisable(GL_SCISSOR_TEST);
      glDepthMask(GL_TRUE);
      glDisable(GL_BLEND);
    }

    // Ghosts last: depth tested against everything opaque (the ground hides what is below it),
    // but without depth writes, so every ghost shows through every other, whichever variant it
    // belongs to, even where two coincide exactly; back faces culled, so each convex body adds
    // one layer. They cast no shadow: a translucent body would cast a full one, and the shadows
    // of several variants would merge into one dark patch.
    const bool ghosts = !ghost_box_data.empty() ||
                        std::any_of(ghost_sphere_data.begin(), ghost_sphere_data.end(),
                                    [](const std::vector<BodyInstance>& v) { return !v.empty(); });
    if (ghosts) {
      glEnable(GL_BLEND);
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      glDepthMask(GL_FALSE);
      glEnable(GL_CULL_FACE);
      glCullFace(GL_BACK);
      body_program.use();
      // The opaque bodies' instances were drawn: their buffers now take the ghosts'.
      upload(cube.instances, cube.capacity, ghost_box_data.data(),
             ghost_box_data.size() * sizeof(BodyInstance));
      body_program.set("u_kind", 0);
      cube.draw(static_cast<GLsizei>(ghost_box_data.size()));
      body_program.set("u_kind", 1);
      for (std::size_t i = 0; i < spheres.size(); ++i) {
        upload(spheres[i].instances, spheres[i].capacity, ghost_sphere_data[i].data(),
               ghost_sphere_data[i].size() * sizeof(BodyInstance));
        spheres[i].draw(static_cast<GLsizei>(ghost_sphere_data[i].size()));
      }
      glDisable(GL_CULL_FACE);
      glDepthMask(GL_TRUE);
      glDisable(GL_BLEND);
    }
    glBindVertexArray(0);

    // 3. Resolve the multisampled image into the context's framebuffer.
    if (samples > 0) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo.id());
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, context.framebuffer());
      glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
    }
    check_gl("while drawing a frame");

    Image image;
    context.read_rgb(image);
    return image;
  }
};

// Renderer(width, height, backend): width and height in pixels, each in [1, 8192], else
// std::invalid_argument naming the value. Creates the backend's context (OpenGL 3.3 core or
// newer, RGBA8, 24-bit depth; see gl_context.h), compiles the embedded shaders
// (std::runtime_error with the info log on failure), builds the unit cube and the icospheres (levels of detail), the 2048x2048 shadow map and, when llvmpipe allows
// it and the frame has at most 4096x4096 pixels, a 4x multisampled framebuffer (GL_MAX_SAMPLES is
// queried; otherwise the frame is rendered without MSAA).
Renderer::Renderer(int width, int height, Backend backend) {
  check_size("width", width);
  check_size("height", height);
  impl_ = std::make_unique<Impl>(width, height, backend);
}

Renderer::~Renderer() = default;

int Renderer::width() const { return impl_->context.width(); }
int Renderer::height() const { return impl_->context.height(); }
Backend Renderer::backend() const { return impl_->context.backend(); }
std::string Renderer::context_description() { return impl_->context.description(); }

std::string_view backend_name(Backend backend) {
  return backend == Backend::egl ? "egl" : "osmesa";
}

std::optional<Backend> parse_backend(std::string_view name) {
  if (name == "osmesa") return Backend::osmesa;
  if (name == "egl") return Backend::egl;
  return std::nullopt;
}

// draw(list): renders one frame (lengths in metres, camera field of view in degrees) and returns
// it as width x height RGB8, rows top to bottom. Items with non-finite values or non-positive sizes
// (or alpha <= 0) are skipped; bodies with alpha < 1 are ghosts (see the frame outline above). Throws std::runtime_error naming the GL error code if glGetError reports one, or if
// the context cannot be made current. Lighting: Lambert + Blinn-Phong (Blinn 1977) under a sun
// with PCF-filtered shadow mapping (Williams 1978; Reeves et al. 1987; LearnOpenGL "Shadow
// Mapping"), hemisphere ambient and a weak camera-relative fill light.
Image Renderer::draw(const DrawList& list) { return impl_->draw(list); }

}  // namespace cps::render
