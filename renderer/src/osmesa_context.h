#pragma once
// Private: the one place where an OSMesa context is created (all OSMesa calls live in
// osmesa_context.cpp), in the spirit of Mesa's osdemo.c: create a context, bind a client memory
// buffer as its window-system framebuffer, draw, glFinish, read the buffer.

#include "cps/render/renderer.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace cps::render {

/// An OpenGL core-profile context (3.3 requested; Mesa may hand out a newer core version) whose
/// default framebuffer is an RGBA8 client buffer of width x height pixels with a 24-bit depth
/// buffer. Not copyable, not movable (OSMesa keeps a pointer to the buffer).
class OsMesaContext {
 public:
  /// width, height in [1, 8192] (checked by the caller). Throws std::runtime_error if OSMesa
  /// cannot create the context, cannot bind the buffer or gives a version below 3.3.
  OsMesaContext(int width, int height);
  ~OsMesaContext();
  OsMesaContext(const OsMesaContext&) = delete;
  OsMesaContext& operator=(const OsMesaContext&) = delete;

  /// Binds the context and its buffer to the calling thread. Throws std::runtime_error on failure.
  void make_current();

  /// glFinish, then copies the default framebuffer (stored bottom row first) into `out` as RGB8,
  /// rows top to bottom (alpha dropped). The context must be current.
  void read_rgb(Image& out);

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  struct Handle;
  int width_;
  int height_;
  std::vector<std::uint8_t> rgba_;  // the OSMesa colour buffer, 4 * width * height bytes
  std::unique_ptr<Handle> handle_;
};

}  // namespace cps::render
