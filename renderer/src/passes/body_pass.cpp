// The body pass (see body_pass.h). Lighting: Lambert + Blinn-Phong (Blinn 1977), see
// lighting.glsl.

#include "passes/body_pass.h"

#include "passes/pass_common.h"

#include "cps_render_embedded_shaders.h"

namespace cps::render {

BodyPass::BodyPass()
    : program_("body", {shaders::quat, shaders::body_vert}, {shaders::lighting, shaders::body_frag}) {}

// u_kind tells body.frag.glsl a box (0) from a sphere (1).
void BodyPass::draw_instances(const BodyMeshes& meshes) const {
  program_.set("u_kind", 0);
  meshes.cube.draw();
  program_.set("u_kind", 1);
  meshes.draw_spheres();
}

void BodyPass::draw_opaque(const FramePlan& plan, const BodyMeshes& meshes) const {
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  program_.use();
  set_lighting(program_, plan.view, plan.shadow);
  program_.set("u_view_proj", plan.view.view_proj);
  draw_instances(meshes);
}

// Ghosts are depth tested against everything opaque (the ground hides what is below it), but
// without depth writes, so every ghost shows through every other, whichever variant it belongs
// to, even where two coincide exactly; back faces culled, so each convex body adds one layer.
// They cast no shadow: a translucent body would cast a full one, and the shadows of several
// variants would merge into one dark patch.
void BodyPass::draw_ghosts(const FramePlan& plan, BodyMeshes& meshes) const {
  if (!plan.has_ghosts()) return;
  begin_blending();
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  program_.use();
  meshes.upload(plan.ghost_boxes, plan.ghost_spheres);
  draw_instances(meshes);
  glDisable(GL_CULL_FACE);
  end_blending();
}

}  // namespace cps::render
