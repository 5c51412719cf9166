#pragma once
// Private: the line pass: segments of constant on-screen width, instanced, unlit
// (line.vert.glsl, line.frag.glsl), drawn after the opaque planes.

#include "frame_plan.h"
#include "gl_objects.h"
#include "passes/pass_common.h"
#include "shader_program.h"

#include <vector>

namespace cps::render {

/// The line program, its vertex array (attribute 0: the 4 corners of a unit quad, per vertex;
/// 1-4: each LineInstance's ends, colour and width) and the instance buffer. Created with the
/// context current; throws std::runtime_error if the program does not build.
class LinePass {
 public:
  LinePass();

  /// Replaces the instances with `lines`.
  void upload(const std::vector<LineInstance>& lines) { instances_.upload(lines); }

  /// Draws the instances uploaded from plan.lines into the bound target, with the camera of
  /// plan.view; nothing when there are none.
  void draw(const FramePlan& plan) const;

 private:
  ShaderProgram program_;
  gl::VertexArray vao_;
  gl::Buffer corners_;
  InstanceBuffer instances_;
};

}  // namespace cps::render
