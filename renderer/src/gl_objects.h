#pragma once
// Private: OpenGL declarations and move-only RAII owners for GL object names.
//
// GL entry points come from the current context's function table (gl_functions.h: glXxx calls
// are routed there by macros), never from a linked GL library. Every owner deletes its name in
// its destructor; the OpenGL context that created it must be current at that moment (Renderer
// makes its context current before its members are destroyed).

#include "gl_functions.h"

#include <utility>

namespace cps::render::gl {

/// Owner of one GL object name. Create: a function that returns a new name; Destroy: a function
/// that deletes one name. Name 0 means "empty" and is never deleted.
template <GLuint (*Create)(), void (*Destroy)(GLuint)>
class Object {
 public:
  Object() = default;
  explicit Object(GLuint adopted) : id_(adopted) {}
  static Object create() { return Object(Create()); }
  ~Object() { reset(); }
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;
  Object(Object&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
  Object& operator=(Object&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, 0);
    }
    return *this;
  }
  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_ != 0) Destroy(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

namespace detail {
inline GLuint gen_buffer() { GLuint id = 0; glGenBuffers(1, &id); return id; }
inline void del_buffer(GLuint id) { glDeleteBuffers(1, &id); }
inline GLuint gen_vertex_array() { GLuint id = 0; glGenVertexArrays(1, &id); return id; }
inline void del_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
inline GLuint gen_texture() { GLuint id = 0; glGenTextures(1, &id); return id; }
inline void del_texture(GLuint id) { glDeleteTextures(1, &id); }
inline GLuint gen_framebuffer() { GLuint id = 0; glGenFramebuffers(1, &id); return id; }
inline void del_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
inline GLuint gen_renderbuffer() { GLuint id = 0; glGenRenderbuffers(1, &id); return id; }
inline void del_renderbuffer(GLuint id) { glDeleteRenderbuffers(1, &id); }
inline GLuint gen_none() { return 0; }
inline void del_shader(GLuint id) { glDeleteShader(id); }
inline void del_program(GLuint id) { glDeleteProgram(id); }
}  // namespace detail

using Buffer = Object<detail::gen_buffer, detail::del_buffer>;
using VertexArray = Object<detail::gen_vertex_array, detail::del_vertex_array>;
using Texture = Object<detail::gen_texture, detail::del_texture>;
using Framebuffer = Object<detail::gen_framebuffer, detail::del_framebuffer>;
using Renderbuffer = Object<detail::gen_renderbuffer, detail::del_renderbuffer>;
/// Shaders and programs are created with glCreateShader/glCreateProgram and adopted.
using Shader = Object<detail::gen_none, detail::del_shader>;
using ProgramName = Object<detail::gen_none, detail::del_program>;

}  // namespace cps::render::gl
