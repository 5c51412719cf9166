// OSMesa context creation and frame buffer readback. The only file that includes GL/osmesa.h.

#include "osmesa_context.h"

#include "gl_objects.h"

#include <GL/osmesa.h>

#include <cstring>
#include <stdexcept>
#include <string>

#if defined(__SANITIZE_ADDRESS__)
// Gallium's OSMesa keeps every buffer ever bound by OSMesaMakeCurrent in a global list that
// OSMesaDestroyContext does not free (a few hundred bytes per context); it is not reachable through
// the API, so LeakSanitizer is told to ignore allocations made inside libOSMesa.
extern "C" const char* __lsan_default_suppressions() { return "leak:libOSMesa.so\n"; }
#endif

namespace cps::render {

struct OsMesaContext::Handle {
  OSMesaContext ctx = nullptr;
};

OsMesaContext::OsMesaContext(int width, int height)
    : width_(width),
      height_(height),
      rgba_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4u, 0),
      handle_(std::make_unique<Handle>()) {
  const int attribs[] = {
      OSMESA_FORMAT,                OSMESA_RGBA,
      OSMESA_DEPTH_BITS,            24,
      OSMESA_STENCIL_BITS,          0,
      OSMESA_ACCUM_BITS,            0,
      OSMESA_PROFILE,               OSMESA_CORE_PROFILE,
      OSMESA_CONTEXT_MAJOR_VERSION, 3,
      OSMESA_CONTEXT_MINOR_VERSION, 3,
      0,
  };
  handle_->ctx = OSMesaCreateContextAttribs(attribs, nullptr);
  if (handle_->ctx == nullptr) {
    throw std::runtime_error(
        "cps::render: OSMesaCreateContextAttribs failed (OpenGL 3.3 core, RGBA, depth 24)");
  }
  try {
    make_current();
    GLint major = 0;
    GLint minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major < 3 || (major == 3 && minor < 3)) {
      throw std::runtime_error("cps::render: OSMesa gave OpenGL " + std::to_string(major) + "." +
                               std::to_string(minor) + ", need 3.3 core");
    }
  } catch (...) {
    OSMesaDestroyContext(handle_->ctx);
    throw;
  }
}

OsMesaContext::~OsMesaContext() {
  if (handle_ && handle_->ctx != nullptr) {
    if (OSMesaGetCurrentContext() == handle_->ctx) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(handle_->ctx);
  }
}

void OsMesaContext::make_current() {
  if (OSMesaGetCurrentContext() == handle_->ctx) return;
  if (!OSMesaMakeCurrent(handle_->ctx, rgba_.data(), GL_UNSIGNED_BYTE, width_, height_)) {
    throw std::runtime_error("cps::render: OSMesaMakeCurrent failed for a " +
                             std::to_string(width_) + "x" + std::to_string(height_) + " buffer");
  }
}

void OsMesaContext::read_rgb(Image& out) {
  glFinish();  // OSMesa copies the rendering into rgba_ when the context flushes
  const auto w = static_cast<std::size_t>(width_);
  const auto h = static_cast<std::size_t>(height_);
  out.width = width_;
  out.height = height_;
  out.pixels.resize(w * h * 3u);
  for (std::size_t row = 0; row < h; ++row) {
    // OSMesa's default (OSMESA_Y_UP = true) stores the bottom row first.
    const std::uint8_t* src = rgba_.data() + (h - 1u - row) * w * 4u;
    std::uint8_t* dst = out.pixels.data() + row * w * 3u;
    for (std::size_t x = 0; x < w; ++x) {
      dst[3 * x + 0] = src[4 * x + 0];
      dst[3 * x + 1] = src[4 * x + 1];
      dst[3 * x + 2] = src[4 * x + 2];
    }
  }
}

}  // namespace cps::render
