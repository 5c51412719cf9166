#pragma once
// Private: the plane pass: checkered planes (plane.vert.glsl, plane.frag.glsl), each clipped by
// the others and drawn inside its scissor rectangle; the opaque ones, then the translucent ones.

#include "frame_plan.h"
#include "gl_objects.h"
#include "shader_program.h"

#include <cstddef>

namespace cps::render {

/// The plane program and the empty vertex array it draws with (the square's corners come from
/// gl_VertexID; a core profile needs a bound VAO even without attributes). Created with the
/// context current; throws std::runtime_error if the program does not build.
class PlanePass {
 public:
  PlanePass();

  /// Draws the visible opaque planes of plan.planes into the bound target, both sides, culling
  /// off; sets the program's camera and lighting uniforms for the frame.
  void draw_opaque(const FramePlan& plan) const;

  /// Blends the visible translucent planes (far to near) over the frame, without depth writes.
  /// Call after draw_opaque of the same frame.
  void draw_translucent(const FramePlan& plan) const;

 private:
  /// Draws planes [first, last) of plan.planes that are visible, each in its scissor rectangle
  /// (the scissor test on, as RenderTarget::begin leaves it), then sets the scissor back to
  /// plan.draw_rect.
  void draw_range(const FramePlan& plan, std::size_t first, std::size_t last) const;
  /// Draws plane d, clipped by every other plane of `plan` (at most k_max_clip_planes).
  void draw_plane(const PlaneDraw& d, const FramePlan& plan) const;

  ShaderProgram program_;
  gl::VertexArray empty_vao_;
};

}  // namespace cps::render
