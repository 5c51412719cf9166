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

void RenderTarget::begin(const glm::vec3& background) const {
  glBindFramebuffer(GL_FRAMEBUFFER, samples_ > 0 ? fbo_.id() : context_.framebuffer());
  glViewport(0, 0, context_.width(), context_.height());
  glClearColor(background.r, background.g, background.b, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

void RenderTarget::resolve() const {
  if (samples_ == 0) return;
  const int width = context_.width();
  const int height = context_.height();
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_.id());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, context_.framebuffer());
  glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

Image RenderTarget::read_back() const {
  Image image;
  context_.read_rgb(image);
  return image;
}

}  // namespace cps::render
