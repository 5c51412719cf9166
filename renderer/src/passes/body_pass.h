#pragma once
// Private: the body pass: boxes and spheres, instanced, lit and shadowed (body.vert.glsl,
// body.frag.glsl): the opaque ones first, the ghosts (alpha < 1) last.

#include "frame_plan.h"
#include "passes/body_meshes.h"
#include "shader_program.h"

namespace cps::render {

/// The body program. Created with the context current; throws std::runtime_error if the program
/// does not build.
class BodyPass {
 public:
  BodyPass();

  /// Draws the opaque instances of `meshes` (uploaded from plan.boxes and plan.spheres) into the
  /// bound target with back faces culled; sets the program's camera and lighting uniforms for
  /// the frame. Leaves culling on.
  void draw_opaque(const FramePlan& plan, const BodyMeshes& meshes) const;

  /// Uploads plan.ghost_boxes and plan.ghost_spheres into `meshes` (the opaque instances were
  /// drawn already) and blends them over the frame, back faces culled. Call after draw_opaque
  /// of the same frame and after every other pass. Leaves culling off.
  void draw_ghosts(const FramePlan& plan, BodyMeshes& meshes) const;

 private:
  /// Draws the instances uploaded to `meshes`, boxes then spheres; the program is in use.
  void draw_instances(const BodyMeshes& meshes) const;

  ShaderProgram program_;
};

}  // namespace cps::render
