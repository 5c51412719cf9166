#pragma once
// Private: what the renderer's passes share: instance buffers, vertex attribute setup, the
// frame's starting depth state, blending for translucent items, and the lighting uniforms of
// lighting.glsl. The GL context must be current for every function here.

#include "frame_plan.h"
#include "gl_objects.h"
#include "shader_program.h"

#include <cstddef>
#include <initializer_list>
#include <vector>

namespace cps::render {

/// A GL buffer of per-instance records (BodyInstance, LineInstance) refilled every frame; its
/// store grows (to max(needed, twice the old), bytes) only when too small. Created with the
/// context current.
class InstanceBuffer {
 public:
  InstanceBuffer() : buffer_(gl::Buffer::create()) {}

  /// Replaces the records with `records` (the buffer is left bound to GL_ARRAY_BUFFER).
  template <class Record>
  void upload(const std::vector<Record>& records) {
    upload_bytes(records.data(), records.size() * sizeof(Record));
    count_ = static_cast<GLsizei>(records.size());
  }

  const gl::Buffer& buffer() const { return buffer_; }
  /// Records uploaded last.
  GLsizei count() const { return count_; }

 private:
  void upload_bytes(const void* data, std::size_t bytes);

  gl::Buffer buffer_;
  std::size_t capacity_ = 0;  // bytes
  GLsizei count_ = 0;
};

/// Binds `buffer` to `target` (GL_ARRAY_BUFFER, or GL_ELEMENT_ARRAY_BUFFER of the bound vertex
/// array) and gives it `bytes` bytes from `data`, never to change (GL_STATIC_DRAW).
void fill_static(GLenum target, const gl::Buffer& buffer, const void* data, std::size_t bytes);

/// One float vertex attribute of a record: its number of floats and its byte offset.
struct FloatField {
  int components;
  std::size_t offset;
};

/// Enables the float vertex attributes first, first + 1, ... of the bound vertex array, one per
/// entry of `fields`, read from `stride`-byte records of `buffer` (left bound to
/// GL_ARRAY_BUFFER): one record per instance when `instanced`, else per vertex.
void float_attribs(const gl::Buffer& buffer, GLuint first, GLsizei stride,
                   std::initializer_list<FloatField> fields, bool instanced);

/// The state every frame starts from: depth test GL_LESS with depth writes, no blending, no
/// scissor test.
void reset_frame_state();

/// Translucent items: colour blended "over" by source alpha (the alpha channel adds up coverage),
/// depth tested but without depth writes. end_blending() restores depth writes and turns blending
/// off.
void begin_blending();
void end_blending();

/// Sets the uniforms of lighting.glsl on program `p` (in use): the sun, eye and fill light of
/// `view`, its background and fog, and the shadow map (texture unit 0) from `shadow`.
void set_lighting(const ShaderProgram& p, const FrameView& view, const ShadowSetup& shadow);

}  // namespace cps::render
