// Helpers shared by the renderer's passes (see pass_common.h).

#include "passes/pass_common.h"

#include <algorithm>

namespace cps::render {

void InstanceBuffer::upload_bytes(const void* data, std::size_t bytes) {
  glBindBuffer(GL_ARRAY_BUFFER, buffer_.id());
  if (bytes > capacity_) {
    capacity_ = std::max(bytes, 2 * capacity_);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(capacity_), nullptr, GL_DYNAMIC_DRAW);
  }
  if (bytes > 0) glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data);
}

void fill_static(GLenum target, const gl::Buffer& buffer, const void* data, std::size_t bytes) {
  glBindBuffer(target, buffer.id());
  glBufferData(target, static_cast<GLsizeiptr>(bytes), data, GL_STATIC_DRAW);
}

void float_attribs(const gl::Buffer& buffer, GLuint first, GLsizei stride,
                   std::initializer_list<FloatField> fields, bool instanced) {
  glBindBuffer(GL_ARRAY_BUFFER, buffer.id());
  GLuint index = first;
  for (const FloatField& f : fields) {
    glEnableVertexAttribArray(index);
    glVertexAttribPointer(index, f.components, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(f.offset));
    glVertexAttribDivisor(index, instanced ? 1 : 0);
    ++index;
  }
}

void reset_frame_state() {
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
}

void begin_blending() {
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
}

void end_blending() {
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

void set_lighting(const ShaderProgram& p, const FrameView& view, const ShadowSetup& shadow) {
  p.set("u_light_dir", view.light_dir);
  p.set("u_eye", view.eye);
  p.set("u_fill_dir", view.fill_dir);
  p.set("u_background", view.background_linear);
  p.set("u_fog", view.fog);
  p.set("u_shadow_enabled", shadow.enabled ? 1 : 0);
  p.set("u_shadow_map", 0);
  p.set("u_light_view_proj", shadow.view_proj);
  p.set("u_shadow_offset", 1.5f * shadow.texel_world);
  p.set("u_shadow_texel", 1.0f / static_cast<float>(k_shadow_size));
}

}  // namespace cps::render
