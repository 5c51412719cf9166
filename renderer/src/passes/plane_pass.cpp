// The plane pass (see plane_pass.h).

#include "passes/plane_pass.h"

#include "passes/pass_common.h"

#include "cps_render_embedded_shaders.h"

#include <array>

namespace cps::render {

PlanePass::PlanePass()
    : program_("plane", {shaders::plane_vert}, {shaders::lighting, shaders::plane_frag}),
      empty_vao_(gl::VertexArray::create()) {}

void PlanePass::draw_opaque(const FramePlan& plan) const {
  glDisable(GL_CULL_FACE);
  program_.use();
  set_lighting(program_, plan.view, plan.shadow);
  program_.set("u_view_proj", plan.view.view_proj);
  draw_range(plan, 0, plan.first_translucent);
}

void PlanePass::draw_translucent(const FramePlan& plan) const {
  if (plan.first_translucent == plan.planes.size()) return;
  begin_blending();
  program_.use();
  draw_range(plan, plan.first_translucent, plan.planes.size());
  end_blending();
}

void PlanePass::draw_range(const FramePlan& plan, std::size_t first, std::size_t last) const {
  glBindVertexArray(empty_vao_.id());
  for (std::size_t i = first; i < last; ++i) {
    if (plan.planes[i].visible) draw_plane(plan.planes[i], plan);
  }
  const PixelRect& r = plan.draw_rect;
  glScissor(r[0], r[1], r[2], r[3]);
}

void PlanePass::draw_plane(const PlaneDraw& d, const FramePlan& plan) const {
  glScissor(d.scissor[0], d.scissor[1], d.scissor[2], d.scissor[3]);
  // Every other plane clips this one (see plane.frag.glsl).
  std::array<glm::vec4, k_max_clip_planes> clip{};
  int n_clip = 0;
  for (const PlaneDraw& other : plan.planes) {
    if (other.index == d.index || n_clip == k_max_clip_planes) continue;
    clip[static_cast<std::size_t>(n_clip++)] = glm::vec4(other.normal, other.offset);
  }
  program_.set("u_clip_count", n_clip);
  program_.set("u_clip", clip.data(), n_clip);
  program_.set("u_origin", d.origin);
  program_.set("u_t1", d.t1);
  program_.set("u_t2", d.t2);
  program_.set("u_normal", d.normal);
  program_.set("u_half_size", d.half_size);
  program_.set("u_checker", d.checker);
  program_.set("u_color_a", d.color_a);
  program_.set("u_color_b", d.color_b);
  program_.set("u_alpha", d.alpha);
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

}  // namespace cps::render
