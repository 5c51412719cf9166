#pragma once
// Private: compiling and linking GLSL programs from embedded sources, and uniform setters.

#include "gl_objects.h"

#include <glm/glm.hpp>

#include <initializer_list>
#include <string>
#include <string_view>

namespace cps::render {

/// A linked GLSL program. Each stage is the concatenation of "#version 330 core\n" and the given
/// source parts (so shared snippets need no #include). Throws std::runtime_error holding the
/// program name, the stage and the GL info log if a stage does not compile or the program does
/// not link.
class ShaderProgram {
 public:
  ShaderProgram(std::string_view name, std::initializer_list<std::string_view> vertex_parts,
                std::initializer_list<std::string_view> fragment_parts);

  void use() const { glUseProgram(program_.id()); }
  GLuint id() const { return program_.id(); }

  /// Uniform setters; the program must be in use. Unknown names (e.g. optimised away) are ignored.
  void set(const char* name, int v) const;
  void set(const char* name, float v) const;
  void set(const char* name, const glm::vec2& v) const;
  void set(const char* name, const glm::vec3& v) const;
  void set(const char* name, const glm::mat4& v) const;
  void set(const char* name, const glm::vec4* v, int count) const;  // vec4 array

 private:
  GLint location(const char* name) const { return glGetUniformLocation(program_.id(), name); }
  gl::ProgramName program_;
};

}  // namespace cps::render
