#pragma once
// Private: the shadow pass: the opaque boxes and spheres into a k_shadow_size^2 depth texture
// seen from the sun, which the body and plane passes then sample (lighting.glsl).

#include "frame_plan.h"
#include "gl_objects.h"
#include "passes/body_meshes.h"
#include "shader_program.h"

namespace cps::render {

/// The shadow map (24-bit depth, linear filtering with depth comparison GL_LEQUAL, border depth 1:
/// never shadowed outside), its framebuffer and the shadow program (shadow.vert.glsl,
/// shadow.frag.glsl). Created with the context current; throws std::runtime_error if the program
/// does not build or the framebuffer is incomplete.
class ShadowPass {
 public:
  ShadowPass();

  /// When `shadow` is enabled, clears the map and draws the instances of `meshes` into it with
  /// shadow.view_proj; leaves the shadow framebuffer bound, back faces culled and culling on.
  void draw(const ShadowSetup& shadow, const BodyMeshes& meshes) const;

  /// Binds the map to texture unit 0 for the main pass (sampler u_shadow_map).
  void bind_map() const;

 private:
  ShaderProgram program_;
  gl::Texture map_;
  gl::Framebuffer fbo_;
};

}  // namespace cps::render
