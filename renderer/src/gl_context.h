#pragma once
// Private: the offscreen OpenGL context the renderer draws with, whatever its backend (OSMesa or
// EGL), and the interface each backend implements (osmesa_context.cpp, egl_context.cpp). All
// backend code lives in those two files (their factories are declared in osmesa_context.h and
// egl_context.h); the renderer only sees GlContext.

#include "cps/render/renderer.h"

#include "gl_functions.h"

#include <cstdint>
#include <memory>
#include <string>

namespace cps::render {

/// What a backend provides: an OpenGL 3.3 (or newer) core context, a width x height RGBA8 + 24-bit
/// depth framebuffer that receives the final image, and the GL entry points valid for it.
class OffscreenContext {
 public:
  virtual ~OffscreenContext() = default;
  /// Makes this context current on the calling thread; no other cps context is current (the
  /// caller has unbound it). Throws std::runtime_error if the window system refuses.
  virtual void bind() = 0;
  /// Releases this context from the calling thread. Never throws.
  virtual void unbind() noexcept = 0;
  /// The framebuffer object that receives the final image: 0 when the backend has a default
  /// framebuffer (OSMesa), its own FBO otherwise (EGL, surfaceless).
  virtual GLuint framebuffer() const = 0;
  /// Reads framebuffer() into `out` as RGB8, rows top to bottom. The context must be current.
  virtual void read_rgb(Image& out) = 0;
  /// The GL entry points for this context.
  virtual const GlFunctions& functions() const = 0;
  /// e.g. "osmesa: OpenGL 4.5 (Core Profile) Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits)".
  virtual std::string description() const = 0;
  virtual int width() const = 0;
  virtual int height() const = 0;
};

/// Converts a width x height RGBA8 buffer stored bottom row first (as glReadPixels and OSMesa's
/// default Y-up buffer give it) into `out` as RGB8, rows top to bottom (width, height >= 1).
void rgba_bottom_up_to_rgb(const std::uint8_t* rgba, int width, int height, Image& out);

/// "OpenGL <GL_VERSION>, <GL_RENDERER>" of the context whose entry points are `fn` ("?" for a
/// string GL does not give). The context must be current.
std::string gl_version_and_renderer(const GlFunctions& fn);

/// Owner of one backend context. At most one cps context is current per thread: make_current
/// releases the previous one (whatever its backend) before binding this one and points
/// t_current_gl at this context's functions, so two renderers of different backends can be used
/// in turn on one thread. Not copyable, not movable.
class GlContext {
 public:
  /// width, height in [1, 8192] (checked by the caller). The new context is current on return.
  /// Throws std::runtime_error from the backend.
  GlContext(Backend backend, int width, int height);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  /// Binds this context to the calling thread (no-op if it already is). Throws
  /// std::runtime_error on failure.
  void make_current();
  /// The framebuffer object the final image must be drawn or resolved into (see OffscreenContext).
  GLuint framebuffer() const { return impl_->framebuffer(); }
  /// glFinish, then the final image as RGB8, rows top to bottom. The context must be current.
  void read_rgb(Image& out) { impl_->read_rgb(out); }
  int width() const { return impl_->width(); }
  int height() const { return impl_->height(); }
  Backend backend() const { return backend_; }
  /// e.g. "egl (Mesa surfaceless platform): OpenGL 4.5 (Core Profile) Mesa 22.3.6, llvmpipe ...".
  /// Makes the context current.
  std::string description() {
    make_current();
    return impl_->description();
  }

 private:
  Backend backend_;
  std::unique_ptr<OffscreenContext> impl_;
};

}  // namespace cps::render
