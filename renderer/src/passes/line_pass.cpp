// The line pass (see line_pass.h).

#include "passes/line_pass.h"

#include "passes/pass_common.h"

#include "cps_render_embedded_shaders.h"

#include <array>

namespace cps::render {

LinePass::LinePass()
    : program_("line", {shaders::line_vert}, {shaders::line_frag}),
      vao_(gl::VertexArray::create()),
      corners_(gl::Buffer::create()) {
  glBindVertexArray(vao_.id());
  const std::array<float, 8> corners = {0, -1, 0, 1, 1, -1, 1, 1};
  fill_static(GL_ARRAY_BUFFER, corners_, corners.data(), sizeof(corners));
  float_attribs(corners_, 0, 2 * sizeof(float), {{2, 0}}, false);
  float_attribs(instances_.buffer(), 1, sizeof(LineInstance),
                {{3, offsetof(LineInstance, a)}, {3, offsetof(LineInstance, b)},
                 {3, offsetof(LineInstance, color)}, {1, offsetof(LineInstance, width_px)}},
                true);
  glBindVertexArray(0);
}

void LinePass::draw(const FramePlan& plan) const {
  if (instances_.count() == 0) return;
  const FrameView& v = plan.view;
  program_.use();
  program_.set("u_view", v.view);
  program_.set("u_proj", v.proj);
  program_.set("u_viewport", glm::vec2(static_cast<float>(v.width), static_cast<float>(v.height)));
  program_.set("u_near", v.near_m);
  glBindVertexArray(vao_.id());
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, instances_.count());
}

}  // namespace cps::render
