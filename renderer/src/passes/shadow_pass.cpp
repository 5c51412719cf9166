// The shadow pass (see shadow_pass.h). Shadow mapping after Williams 1978, filtered (PCF) in
// lighting.glsl after Reeves et al. 1987.

#include "passes/shadow_pass.h"

#include "cps_render_embedded_shaders.h"

#include <array>
#include <stdexcept>

namespace cps::render {

ShadowPass::ShadowPass()
    : program_("shadow", {shaders::quat, shaders::shadow_vert}, {shaders::shadow_frag}),
      map_(gl::Texture::create()),
      fbo_(gl::Framebuffer::create()) {
  glBindTexture(GL_TEXTURE_2D, map_.id());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, k_shadow_size, k_shadow_size, 0,
               GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const std::array<float, 4> border = {1.0f, 1.0f, 1.0f, 1.0f};  // outside: never shadowed
  glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, map_.id(), 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("cps::render: shadow map framebuffer incomplete");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

// Front faces culled (the map stores the far side of each closed body) and a slope-scaled
// polygon offset: together with the normal offset of lighting.glsl this avoids acne without
// visible peter-panning at contacts.
void ShadowPass::draw(const ShadowSetup& shadow, const BodyMeshes& meshes) const {
  if (!shadow.enabled) return;
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
  glViewport(0, 0, k_shadow_size, k_shadow_size);
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_FRONT);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.5f, 2.0f);
  program_.use();
  program_.set("u_light_view_proj", shadow.view_proj);
  meshes.cube.draw();
  meshes.draw_spheres();
  glDisable(GL_POLYGON_OFFSET_FILL);
  glCullFace(GL_BACK);
}

void ShadowPass::bind_map() const {
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, map_.id());
}

}  // namespace cps::render
