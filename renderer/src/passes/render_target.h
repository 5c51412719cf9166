#pragma once
// Private: the image the main passes draw into: a 4x multisampled framebuffer when the
// implementation allows it (else the context's own), its resolve into the context's framebuffer
// and the read-back of the finished frame.

#include "frame_plan.h"
#include "gl_context.h"
#include "gl_objects.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace cps::render {

/// The main passes' render target for `context` (width x height pixels as the context's). Not
/// copyable: it keeps a reference to the context, which must outlive it.
class RenderTarget {
 public:
  /// Creates the multisampled colour (RGBA8) and depth (24-bit) buffers with
  /// min(4, GL_MAX_SAMPLES) samples, or none when that is below 2, the frame has more than
  /// 4096 x 4096 pixels (about 512 MB) or the framebuffer turns out incomplete: then the passes
  /// draw straight into the context's framebuffer. The context must be current; never throws
  /// for lack of MSAA.
  explicit RenderTarget(GlContext& context);
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;

  /// Binds the target for drawing over the whole frame, turns the scissor test on with `rect`
  /// (pixels, GL window coordinates) and clears that rectangle to `background` (RGB in [0, 1],
  /// alpha 1) and depth 1. The passes draw only inside `rect` until resolve().
  void begin(const glm::vec3& background, const PixelRect& rect) const;

  /// Resolves (blits) `rect` of the multisampled image into the context's framebuffer (nothing
  /// to do without MSAA) and turns the scissor test off.
  void resolve(const PixelRect& rect) const;

  /// glFinish, then the context's framebuffer as RGB8, rows top to bottom.
  Image read_back() const;

  /// Reads `rect` (GL window coordinates, inside the frame) of the context's framebuffer into
  /// the same pixels of `image` (RGB8, rows top to bottom, the context's size), leaving the
  /// others as they are.
  void read_rect(const PixelRect& rect, Image& image);

 private:
  GlContext& context_;
  int samples_ = 0;  // per pixel: 0 without MSAA, else in [2, 4]
  gl::Framebuffer fbo_;
  gl::Renderbuffer color_;
  gl::Renderbuffer depth_;
  std::vector<std::uint8_t> rgba_;  // read_rect's staging, 4 bytes per pixel
};

}  // namespace cps::render
