// Renderer: GL resources kept across frames, the shadow pass, the main pass and the readback.
//
// Frame outline (all passes use instancing; the only per-frame GL traffic is uniforms and
// instance-buffer updates):
//   0. plan (frame_plan.h): the camera and sun, the valid items as instances, sphere levels of
//      detail, planes in drawing order with their scissor rectangles, the shadow projection;
//   1. shadow pass: boxes and spheres into a 2048^2 depth texture from the sun, orthographic
//      projection fitted to the bodies and to the part of each plane their shadows can reach;
//   2. main pass into a 4x multisampled framebuffer: bodies, opaque planes, lines, then planes
//      with alpha < 1 back to front, blended, without depth writes, then the ghosts (bodies with
//      alpha < 1) back to front, blended, depth tested but without depth writes;
//   3. resolve (blit) into the context's framebuffer, glFinish, read back top row first.

#include "cps/render/renderer.h"

#include "frame_plan.h"
#include "gl_objects.h"
#include "meshes.h"
#include "gl_context.h"
#include "shader_program.h"

#include "cps_render_embedded_shaders.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace cps::render {
namespace {

constexpr int k_min_size = 1;
constexpr int k_max_size = 8192;
constexpr int k_msaa_samples = 4;
// Above this many pixels a 4x RGBA8 + depth multisampled buffer would exceed ~512 MB.
constexpr long long k_msaa_max_pixels = 4096LL * 4096LL;
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

}  // namespace

struct Renderer::Impl {
  GlContext context;  // first member: created first, destroyed last
  ShaderProgram body_program;
  ShaderProgram shadow_program;
  ShaderProgram plane_program;
  ShaderProgram line_program;
  InstancedMesh cube;
  std::array<InstancedMesh, k_sphere_lods> spheres;  // coarse to fine
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

  FramePlan plan;  // CPU staging reused across frames

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

  void set_lighting(const ShaderProgram& p) const {
    const FrameView& v = plan.view;
    const ShadowSetup& shadow = plan.shadow;
    p.set("u_light_dir", v.light_dir);
    p.set("u_eye", v.eye);
    p.set("u_fill_dir", v.fill_dir);
    p.set("u_background", v.background_linear);
    p.set("u_fog", v.fog);
    p.set("u_shadow_enabled", shadow.enabled ? 1 : 0);
    p.set("u_shadow_map", 0);
    p.set("u_light_view_proj", shadow.view_proj);
    p.set("u_shadow_offset", 1.5f * shadow.texel_world);
    p.set("u_shadow_texel", 1.0f / static_cast<float>(k_shadow_size));
  }

  void draw_plane(const PlaneDraw& d) const {
    glScissor(d.scissor[0], d.scissor[1], d.scissor[2], d.scissor[3]);
    // Every other plane clips this one (see plane.frag.glsl).
    std::array<glm::vec4, k_max_clip_planes> clip{};
    int n_clip = 0;
    for (const PlaneDraw& other : plan.planes) {
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
    plan.build(list, width, height);
    const FrameView& v = plan.view;
    const ShadowSetup& shadow = plan.shadow;

    upload(cube.instances, cube.capacity, plan.boxes.data(),
           plan.boxes.size() * sizeof(BodyInstance));
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      upload(spheres[i].instances, spheres[i].capacity, plan.spheres[i].data(),
             plan.spheres[i].size() * sizeof(BodyInstance));
    }
    upload(line_instances, line_capacity, plan.lines.data(),
           plan.lines.size() * sizeof(LineInstance));
    const auto n_boxes = static_cast<GLsizei>(plan.boxes.size());
    const auto draw_spheres = [&] {
      for (std::size_t i = 0; i < spheres.size(); ++i) {
        spheres[i].draw(static_cast<GLsizei>(plan.spheres[i].size()));
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
    glClearColor(v.background.r, v.background.g, v.background.b, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, shadow_map.id());

    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    body_program.use();
    set_lighting(body_program);
    body_program.set("u_view_proj", v.view_proj);
    body_program.set("u_kind", 0);
    cube.draw(n_boxes);
    body_program.set("u_kind", 1);
    draw_spheres();

    glDisable(GL_CULL_FACE);
    plane_program.use();
    set_lighting(plane_program);
    plane_program.set("u_view_proj", v.view_proj);
    glBindVertexArray(empty_vao.id());
    const auto first_translucent =
        plan.planes.begin() + static_cast<std::ptrdiff_t>(plan.first_translucent);
    // Each plane drawn only inside the screen rectangle of its visible part.
    glEnable(GL_SCISSOR_TEST);
    for (auto it = plan.planes.begin(); it != first_translucent; ++it) {
      if (it->visible) draw_plane(*it);
    }
    glDisable(GL_SCISSOR_TEST);

    if (!plan.lines.empty()) {
      line_program.use();
      line_program.set("u_view", v.view);
      line_program.set("u_proj", v.proj);
      line_program.set("u_viewport", glm::vec2(static_cast<float>(width), static_cast<float>(height)));
      line_program.set("u_near", v.near_m);
      glBindVertexArray(line_vao.id());
      glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(plan.lines.size()));
    }

    if (first_translucent != plan.planes.end()) {
      glEnable(GL_BLEND);
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      glDepthMask(GL_FALSE);
      plane_program.use();
      glBindVertexArray(empty_vao.id());
      glEnable(GL_SCISSOR_TEST);
      for (auto it = first_translucent; it != plan.planes.end(); ++it) {
        if (it->visible) draw_plane(*it);
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
    if (plan.has_ghosts()) {
      glEnable(GL_BLEND);
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      glDepthMask(GL_FALSE);
      glEnable(GL_CULL_FACE);
      glCullFace(GL_BACK);
      body_program.use();
      // The opaque bodies' instances were drawn: their buffers now take the ghosts'.
      upload(cube.instances, cube.capacity, plan.ghost_boxes.data(),
             plan.ghost_boxes.size() * sizeof(BodyInstance));
      body_program.set("u_kind", 0);
      cube.draw(static_cast<GLsizei>(plan.ghost_boxes.size()));
      body_program.set("u_kind", 1);
      for (std::size_t i = 0; i < spheres.size(); ++i) {
        upload(spheres[i].instances, spheres[i].capacity, plan.ghost_spheres[i].data(),
               plan.ghost_spheres[i].size() * sizeof(BodyInstance));
        spheres[i].draw(static_cast<GLsizei>(plan.ghost_spheres[i].size()));
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
