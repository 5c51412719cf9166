#include "shader_program.h"

#include <glm/gtc/type_ptr.hpp>

#include <stdexcept>
#include <vector>

namespace cps::render {
namespace {

constexpr std::string_view k_version = "#version 330 core\n";

gl::Shader compile(std::string_view program_name, GLenum stage,
                   std::initializer_list<std::string_view> parts) {
  gl::Shader shader(glCreateShader(stage));
  if (!shader) throw std::runtime_error("cps::render: glCreateShader failed");
  std::vector<const GLchar*> strings;
  std::vector<GLint> lengths;
  strings.push_back(k_version.data());
  lengths.push_back(static_cast<GLint>(k_version.size()));
  for (std::string_view part : parts) {
    strings.push_back(part.data());
    lengths.push_back(static_cast<GLint>(part.size()));
  }
  glShaderSource(shader.id(), static_cast<GLsizei>(strings.size()), strings.data(), lengths.data());
  glCompileShader(shader.id());
  GLint ok = GL_FALSE;
  glGetShaderiv(shader.id(), GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint log_size = 0;
    glGetShaderiv(shader.id(), GL_INFO_LOG_LENGTH, &log_size);
    std::string log(static_cast<std::size_t>(log_size > 0 ? log_size : 1), '\0');
    glGetShaderInfoLog(shader.id(), static_cast<GLsizei>(log.size()), nullptr, log.data());
    throw std::runtime_error("cps::render: " + std::string(stage == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                             " shader of program '" + std::string(program_name) +
                             "' does not compile:\n" + log.c_str());
  }
  return shader;
}

}  // namespace

ShaderProgram::ShaderProgram(std::string_view name,
                             std::initializer_list<std::string_view> vertex_parts,
                             std::initializer_list<std::string_view> fragment_parts) {
  gl::Shader vs = compile(name, GL_VERTEX_SHADER, vertex_parts);
  gl::Shader fs = compile(name, GL_FRAGMENT_SHADER, fragment_parts);
  program_ = gl::ProgramName(glCreateProgram());
  if (!program_) throw std::runtime_error("cps::render: glCreateProgram failed");
  glAttachShader(program_.id(), vs.id());
  glAttachShader(program_.id(), fs.id());
  glLinkProgram(program_.id());
  GLint ok = GL_FALSE;
  glGetProgramiv(program_.id(), GL_LINK_STATUS, &ok);
  glDetachShader(program_.id(), vs.id());
  glDetachShader(program_.id(), fs.id());
  if (ok != GL_TRUE) {
    GLint log_size = 0;
    glGetProgramiv(program_.id(), GL_INFO_LOG_LENGTH, &log_size);
    std::string log(static_cast<std::size_t>(log_size > 0 ? log_size : 1), '\0');
    glGetProgramInfoLog(program_.id(), static_cast<GLsizei>(log.size()), nullptr, log.data());
    throw std::runtime_error("cps::render: program '" + std::string(name) +
                             "' does not link:\n" + log.c_str());
  }
}

void ShaderProgram::set(const char* name, int v) const { glUniform1i(location(name), v); }
void ShaderProgram::set(const char* name, float v) const { glUniform1f(location(name), v); }
void ShaderProgram::set(const char* name, const glm::vec2& v) const {
  glUniform2fv(location(name), 1, glm::value_ptr(v));
}
void ShaderProgram::set(const char* name, const glm::vec3& v) const {
  glUniform3fv(location(name), 1, glm::value_ptr(v));
}
void ShaderProgram::set(const char* name, const glm::vec4* v, int count) const {
  if (count > 0) glUniform4fv(location(name), count, glm::value_ptr(v[0]));
}
void ShaderProgram::set(const char* name, const glm::mat4& v) const {
  glUniformMatrix4fv(location(name), 1, GL_FALSE, glm::value_ptr(v));
}

}  // namespace cps::render
