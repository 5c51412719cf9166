// Renderer: the frame plan, the passes that draw it, and the read-back.
//
// Frame outline (all passes use instancing; the only per-frame GL traffic is uniforms and
// instance-buffer updates):
//   0. plan (frame_plan.h): the camera and sun, the valid items as instances, sphere levels of
//      detail, planes in drawing order with their scissor rectangles, the shadow projection;
//   1. shadow pass (passes/shadow_pass.h): boxes and spheres into a 2048^2 depth texture from the
//      sun, orthographic projection fitted to the bodies and to the part of each plane their
//      shadows can reach;
//   2. main passes into a 4x multisampled framebuffer (passes/render_target.h): bodies
//      (passes/body_pass.h), opaque planes (passes/plane_pass.h), lines (passes/line_pass.h),
//      then planes with alpha < 1 back to front, blended, without depth writes, then the ghosts
//      (bodies with alpha < 1) back to front, blended, depth tested but without depth writes;
//   3. resolve (blit) into the context's framebuffer, glFinish, read back top row first.
// The backdrop: once a view (camera, sun, background, planes, size) has stayed for two frames in
// a row, the renderer draws the planes alone once (steps 0-3 without bodies or lines) and keeps
// that frame. While the view stays, each frame then runs steps 1-3 only inside its dynamic
// rectangle (FramePlan::dynamic_rect: the bodies, lines and shadows on screen), reads back only
// that rectangle and pastes it into a copy of the backdrop: the same pixels, to the bit, as the
// whole frame drawn (see Backdrop), for a fraction of the fragments, of the resolve and of the
// read-back.

#include "cps/render/renderer.h"

#include "frame_plan.h"
#include "gl_context.h"
#include "passes/body_meshes.h"
#include "passes/body_pass.h"
#include "passes/line_pass.h"
#include "passes/pass_common.h"
#include "passes/plane_pass.h"
#include "passes/render_target.h"
#include "passes/shadow_pass.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>
#include <stdexcept>
#include <string>

namespace cps::render {
namespace {

constexpr int k_min_size = 1;
constexpr int k_max_size = 8192;

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

// The draw list's planes, camera, sun and background, without bodies or lines.
DrawList planes_only(const DrawList& list) {
  DrawList d;
  d.planes = list.planes;
  d.camera = list.camera;
  d.light_direction = list.light_direction;
  d.background = list.background;
  return d;
}

// The backdrop: the frame of the planes alone (no body, no line, so no shadow map), kept while
// the view stays. Every pixel outside a frame's dynamic rectangle (FramePlan::dynamic_rect) is
// the same as the backdrop's, to the bit: the same fragments of the same planes, shaded alike
// (lit, as every shadow-map tap there reads the border), resolved alike.
struct Backdrop {
  std::vector<float> key;       // what the backdrop depends on, of the last frame drawn
  bool ready = false;           // image is the backdrop of `key`
  Image image;

  // Records the view of `list` at width x height; true when it is the same as the last
  // frame's (then a backdrop is worth drawing), false otherwise (the backdrop is dropped).
  bool see(const DrawList& list, int width, int height) {
    next.clear();
    const auto put = [this](const glm::vec3& v) { next.insert(next.end(), {v.x, v.y, v.z}); };
    next.push_back(static_cast<float>(width));
    next.push_back(static_cast<float>(height));
    const Camera& c = list.camera;
    put(c.eye);
    put(c.target);
    put(c.up);
    next.insert(next.end(), {c.fov_y_deg, c.near_m, c.far_m});
    put(list.light_direction);
    put(list.background);
    for (const PlaneItem& p : list.planes) {
      put(p.normal);
      put(p.center_hint);
      put(p.color_a);
      put(p.color_b);
      next.insert(next.end(), {p.offset, p.half_size, p.checker_m, p.alpha});
    }
    // Bitwise, so that a NaN compares equal to itself.
    const bool same = next.size() == key.size() &&
                      std::memcmp(next.data(), key.data(), next.size() * sizeof(float)) == 0;
    if (!same) ready = false;
    key.swap(next);
    return same;
  }

 private:
  std::vector<float> next;
};

}  // namespace

struct Renderer::Impl {
  GlContext context;  // first member: created first, destroyed last
  BodyMeshes meshes;
  ShadowPass shadow_pass;
  BodyPass body_pass;
  PlanePass plane_pass;
  LinePass line_pass;
  RenderTarget target;  // last GL member: its MSAA check reads glGetError
  FramePlan plan;       // CPU staging reused across frames
  Backdrop backdrop;
  FramePlan backdrop_plan;
  bool timing = false;  // set_stage_timing
  StageTimes times;

  Impl(int width, int height, Backend backend) : context(backend, width, height), target(context) {
    check_gl("while creating the renderer");
  }

  ~Impl() {
    // The GL objects below are deleted after this body: their context must be current.
    try {
      context.make_current();
    } catch (...) {
    }
  }

  // The frame outline at the top of this file, step by step. With stage timing on, mark(x)
  // waits for the GL work so far and adds the time since the previous mark to x.
  Image draw(const DrawList& list) {
    using Clock = std::chrono::steady_clock;
    Clock::time_point last = Clock::now();
    const auto mark = [&](double& into, bool gl) {
      if (!timing) return;
      if (gl) glFinish();
      const Clock::time_point now = Clock::now();
      into += std::chrono::duration<double, std::milli>(now - last).count();
      last = now;
    };
    times = StageTimes{};
    context.make_current();
    const bool same_view = backdrop.see(list, context.width(), context.height());
    if (same_view && !backdrop.ready) {
      // The backdrop (once the view has stayed for a frame): the planes alone, whole frame.
      backdrop_plan.build(planes_only(list), context.width(), context.height());
      backdrop.image = render(backdrop_plan, mark);
      backdrop.ready = true;
    }
    plan.build(list, context.width(), context.height());  // 0.
    mark(times.plan, false);
    const PixelRect& dyn = plan.dynamic_rect;
    const bool whole = dyn[0] == 0 && dyn[1] == 0 && dyn[2] == context.width() &&
                       dyn[3] == context.height();
    if (!same_view || !backdrop.ready || whole) return render(plan, mark);
    plan.restrict_to(dyn);
    Image image = backdrop.image;
    if (dyn[2] > 0 && dyn[3] > 0) {
      draw_passes(plan, mark);
      target.read_rect(dyn, image);
      mark(times.read_back, false);
    }
    return image;
  }

  // Steps 1 to 3 of the frame outline for `p` (uploaded here), inside p.draw_rect.
  template <class Mark>
  void draw_passes(const FramePlan& p, Mark& mark) {
    meshes.upload(p.boxes, p.spheres);
    line_pass.upload(p.lines);
    mark(times.upload, true);
    reset_frame_state();
    shadow_pass.draw(p.shadow, meshes);  // 1.
    mark(times.shadow, true);
    target.begin(p.view.background, p.draw_rect);  // 2.
    shadow_pass.bind_map();
    body_pass.draw_opaque(p, meshes);
    mark(times.bodies, true);
    plane_pass.draw_opaque(p);
    mark(times.planes, true);
    line_pass.draw(p);
    plane_pass.draw_translucent(p);
    body_pass.draw_ghosts(p, meshes);  // last: blended over everything else
    glBindVertexArray(0);
    mark(times.overlay, true);
    target.resolve(p.draw_rect);  // 3.
    mark(times.resolve, true);
    check_gl("while drawing a frame");
  }

  // The whole frame of `p`, read back.
  template <class Mark>
  Image render(const FramePlan& p, Mark& mark) {
    draw_passes(p, mark);
    Image image = target.read_back();
    mark(times.read_back, false);
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
  switch (backend) {
    case Backend::osmesa: return "osmesa";
    case Backend::egl: return "egl";
    case Backend::automatic: return "auto";
  }
  return "?";
}

std::optional<Backend> parse_backend(std::string_view name) {
  for (const Backend b : {Backend::osmesa, Backend::egl, Backend::automatic}) {
    if (name == backend_name(b)) return b;
  }
  return std::nullopt;
}

// draw(list): renders one frame (lengths in metres, camera field of view in degrees) and returns
// it as width x height RGB8, rows top to bottom. Items with non-finite values or non-positive sizes
// (or alpha <= 0) are skipped; bodies with alpha < 1 are ghosts (see the frame outline above). Throws std::runtime_error naming the GL error code if glGetError reports one, or if
// the context cannot be made current. Lighting: Lambert + Blinn-Phong (Blinn 1977) under a sun
// with PCF-filtered shadow mapping (Williams 1978; Reeves et al. 1987; LearnOpenGL "Shadow
// Mapping"), hemisphere ambient and a weak camera-relative fill light.
Image Renderer::draw(const DrawList& list) { return impl_->draw(list); }

void Renderer::set_stage_timing(bool on) { impl_->timing = on; }
StageTimes Renderer::last_stage_times() const { return impl_->times; }

}  // namespace cps::render
