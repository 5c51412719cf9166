// The main passes' render target (see render_target.h).

#include "passes/render_target.h"

#include <algorithm>

namespace cps::render {
namespace {

constexpr int k_msaa_samples = 4;
// Above this many pixels a 4x RGBA8 + depth multisampled buffer would exceed ~512 MB.
constexpr long long k_msaa_max_pixels = 4096LL * 4096LL;

}  // namespace

RenderTarget::RenderTarget(GlContext& context) : context_(context) {
  const int width = context.width();
  const int height = context.height();
  GLint max_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  samples_ = std::min(k_msaa_samples, static_cast<int>(max_samples));
  if (static_cast<long long>(width) * height > k_msaa_max_pixels) samples_ = 0;
  if (samples_ < 2) {
    samples_ = 0;
    return;
  }
  fbo_ = gl::Framebuffer::create();
  color_ = gl::Renderbuffer::create();
  depth_ = gl::Renderbuffer::create();
  glBindRenderbuffer(GL_RENDERBUFFER, color_.id());
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_RGBA8, width, height);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_.id());
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_DEPTH_COMPONENT24, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_.id());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.id());
  const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (!complete || glGetError() != GL_NO_ERROR) {
    fbo_.reset();
    color_.reset();
    depth_.reset();
    samples_ = 0;
  }
}

void RenderTarget::begin(const glm::vec3& background, const PixelRect& rect) const {
  glBindFramebuffer(GL_FRAMEBUFFER, samples_ > 0 ? fbo_.id() : context_.framebuffer());
  glViewport(0, 0, context_.width(), context_.height());
  glEnable(GL_SCISSOR_TEST);
  glScissor(rect[0], rect[1], rect[2], rect[3]);
  glClearColor(background.r, background.g, background.b, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

void RenderTarget::resolve(const PixelRect& rect) const {
  if (samples_ > 0) {
    const int x1 = rect[0] + rect[2];
    const int y1 = rect[1] + rect[3];
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_.id());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, context_.framebuffer());
    glBlitFramebuffer(rect[0], rect[1], x1, y1, rect[0], rect[1], x1, y1, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  glDisable(GL_SCISSOR_TEST);
}

void RenderTarget::read_rect(const PixelRect& rect, Image& image) {
  const auto w = static_cast<std::size_t>(rect[2]);
  const auto h = static_cast<std::size_t>(rect[3]);
  if (w == 0 || h == 0) return;
  rgba_.resize(w * h * 4u);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, context_.framebuffer());
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(rect[0], rect[1], rect[2], rect[3], GL_RGBA, GL_UNSIGNED_BYTE, rgba_.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  // GL rows run bottom to top; the image's top to bottom.
  const auto width = static_cast<std::size_t>(image.width);
  for (std::size_t j = 0; j < h; ++j) {
    const std::size_t row = static_cast<std::size_t>(image.height) - 1u -
                            (static_cast<std::size_t>(rect[1]) + j);
    const std::uint8_t* src = rgba_.data() + j * w * 4u;
    std::uint8_t* dst = image.pixels.data() + (row * width + static_cast<std::size_t>(rect[0])) * 3u;
    for (std::size_t i = 0; i < w; ++i) {
      dst[3 * i] = src[4 * i];
      dst[3 * i + 1] = src[4 * i + 1];
      dst[3 * i + 2] = src[4 * i + 2];
    }
  }
}

Image RenderTarget::read_back() const {
  Image image;
  context_.read_rgb(image);
  return image;
}

}  // namespace cps::render
