#pragma once
// Private: the OpenGL entry points the renderer calls, loaded per context, and the macros that
// route every glXxx(...) call in the renderer to the table of the context current on the thread.
//
// Why a table and not linked symbols: libOSMesa exports the whole GL API (dispatching through
// Mesa's libglapi), and libOpenGL (GLVND, what EGL uses) exports the same names (dispatching
// through libGLdispatch). A binary that links both gets, for each glXxx, whichever library the
// dynamic linker finds first: with libOpenGL first every call made under an OSMesa context goes
// to GLVND, which knows nothing of OSMesa, and silently does nothing (glGetString returns NULL);
// with libOSMesa first, EGL only works while the EGL vendor happens to be Mesa (both share
// libglapi), never with another vendor's driver. So no GL library is linked at all: each backend
// fills a GlFunctions from its own OSMesaGetProcAddress / eglGetProcAddress, and
// GlContext::make_current (gl_context.h) points t_current_gl at the table of the context it makes
// current. This is what GL loaders (glad, libepoxy) do, with the table chosen per context.
//
// A GL function missing from CPS_GL_FUNCTIONS still compiles (gl.h/glext.h declare it) but fails
// to link (no library defines it): add one line to the list below.

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1  // prototypes are only used for decltype, never linked
#endif
#include <GL/gl.h>
#include <GL/glext.h>

#include <stdexcept>
#include <string>

// X(name): one GL entry point, named without its "gl" prefix. Sorted alphabetically. The list
// holds the functions the renderer calls plus a few common GL 3.3 core ones (readback, uniforms,
// state) so that small changes to the drawing code rarely need to touch it.
#define CPS_GL_FUNCTIONS(X)                                                                         \
  X(ActiveTexture) X(AttachShader) X(BindAttribLocation) X(BindBuffer) X(BindBufferBase)            \
  X(BindFragDataLocation) X(BindFramebuffer) X(BindRenderbuffer) X(BindTexture)                     \
  X(BindVertexArray) X(BlendEquation) X(BlendFunc) X(BlendFuncSeparate) X(BlitFramebuffer)          \
  X(BufferData) X(BufferSubData) X(CheckFramebufferStatus) X(Clear) X(ClearColor) X(ClearDepth)     \
  X(ColorMask) X(CompileShader) X(CreateProgram) X(CreateShader) X(CullFace) X(DeleteBuffers)       \
  X(DeleteFramebuffers) X(DeleteProgram) X(DeleteRenderbuffers) X(DeleteShader) X(DeleteTextures)   \
  X(DeleteVertexArrays) X(DepthFunc) X(DepthMask) X(DetachShader) X(Disable)                        \
  X(DisableVertexAttribArray) X(DrawArrays) X(DrawArraysInstanced) X(DrawBuffer) X(DrawBuffers)     \
  X(DrawElements) X(DrawElementsInstanced) X(Enable) X(EnableVertexAttribArray) X(Finish) X(Flush)  \
  X(FramebufferRenderbuffer) X(FramebufferTexture2D) X(FrontFace) X(GenBuffers)                     \
  X(GenFramebuffers) X(GenRenderbuffers) X(GenTextures) X(GenVertexArrays) X(GenerateMipmap)        \
  X(GetError) X(GetFloatv) X(GetIntegerv) X(GetProgramInfoLog) X(GetProgramiv)                      \
  X(GetShaderInfoLog) X(GetShaderiv) X(GetString) X(GetUniformBlockIndex) X(GetUniformLocation)     \
  X(LineWidth) X(LinkProgram) X(PixelStorei) X(PolygonMode) X(PolygonOffset) X(ReadBuffer)          \
  X(ReadPixels) X(RenderbufferStorage) X(RenderbufferStorageMultisample) X(Scissor)                 \
  X(ShaderSource) X(TexImage2D) X(TexParameterf) X(TexParameterfv) X(TexParameteri)                 \
  X(TexSubImage2D) X(Uniform1f) X(Uniform1fv) X(Uniform1i) X(Uniform1iv) X(Uniform2f)               \
  X(Uniform2fv) X(Uniform3f) X(Uniform3fv) X(Uniform4f) X(Uniform4fv) X(UniformBlockBinding)        \
  X(UniformMatrix3fv) X(UniformMatrix4fv) X(UseProgram) X(VertexAttribDivisor)                      \
  X(VertexAttribIPointer) X(VertexAttribPointer) X(Viewport)

namespace cps::render {

/// One pointer per entry of CPS_GL_FUNCTIONS, with the exact type of the GL prototype; member
/// `Clear` holds glClear, and so on. Filled by load_gl_functions for one context.
struct GlFunctions {
#define CPS_GL_MEMBER(name) decltype(&::gl##name) name = nullptr;
  CPS_GL_FUNCTIONS(CPS_GL_MEMBER)
#undef CPS_GL_MEMBER
};

/// Looks up one GL function by its full name ("glClear"); returns nullptr if unknown.
/// `user` is passed through (e.g. a loaded library's eglGetProcAddress).
using GlProcLookup = void* (*)(const char* name, void* user);

/// Fills `out` with lookup("gl" + name, user) for every entry. Throws std::runtime_error naming
/// `backend` and the first function the lookup returns nullptr for.
void load_gl_functions(GlFunctions& out, GlProcLookup lookup, void* user, const char* backend);

/// The table of the context current on this thread (set by GlContext::make_current), or nullptr.
extern thread_local constinit const GlFunctions* t_current_gl;

/// The current thread's table. Throws std::logic_error if no cps context is current (a GL call
/// outside any context is a programming error, which would otherwise crash).
inline const GlFunctions& current_gl() {
  if (t_current_gl == nullptr) {
    throw std::logic_error("cps::render: OpenGL call with no renderer context current");
  }
  return *t_current_gl;
}

}  // namespace cps::render

// Route glXxx to the current table. A macro never re-expands its own name, and the members drop
// the "gl" prefix, so `fn.Clear(...)` and these definitions do not collide.
#define glActiveTexture (::cps::render::current_gl().ActiveTexture)
#define glAttachShader (::cps::render::current_gl().AttachShader)
#define glBindAttribLocation (::cps::render::current_gl().BindAttribLocation)
#define glBindBuffer (::cps::render::current_gl().BindBuffer)
#define glBindBufferBase (::cps::render::current_gl().BindBufferBase)
#define glBindFragDataLocation (::cps::render::current_gl().BindFragDataLocation)
#define glBindFramebuffer (::cps::render::current_gl().BindFramebuffer)
#define glBindRenderbuffer (::cps::render::current_gl().BindRenderbuffer)
#define glBindTexture (::cps::render::current_gl().BindTexture)
#define glBindVertexArray (::cps::render::current_gl().BindVertexArray)
#define glBlendEquation (::cps::render::current_gl().BlendEquation)
#define glBlendFunc (::cps::render::current_gl().BlendFunc)
#define glBlendFuncSeparate (::cps::render::current_gl().BlendFuncSeparate)
#define glBlitFramebuffer (::cps::render::current_gl().BlitFramebuffer)
#define glBufferData (::cps::render::current_gl().BufferData)
#define glBufferSubData (::cps::render::current_gl().BufferSubData)
#define glCheckFramebufferStatus (::cps::render::current_gl().CheckFramebufferStatus)
#define glClear (::cps::render::current_gl().Clear)
#define glClearColor (::cps::render::current_gl().ClearColor)
#define glClearDepth (::cps::render::current_gl().ClearDepth)
#define glColorMask (::cps::render::current_gl().ColorMask)
#define glCompileShader (::cps::render::current_gl().CompileShader)
#define glCreateProgram (::cps::render::current_gl().CreateProgram)
#define glCreateShader (::cps::render::current_gl().CreateShader)
#define glCullFace (::cps::render::current_gl().CullFace)
#define glDeleteBuffers (::cps::render::current_gl().DeleteBuffers)
#define glDeleteFramebuffers (::cps::render::current_gl().DeleteFramebuffers)
#define glDeleteProgram (::cps::render::current_gl().DeleteProgram)
#define glDeleteRenderbuffers (::cps::render::current_gl().DeleteRenderbuffers)
#define glDeleteShader (::cps::render::current_gl().DeleteShader)
#define glDeleteTextures (::cps::render::current_gl().DeleteTextures)
#define glDeleteVertexArrays (::cps::render::current_gl().DeleteVertexArrays)
#define glDepthFunc (::cps::render::current_gl().DepthFunc)
#define glDepthMask (::cps::render::current_gl().DepthMask)
#define glDetachShader (::cps::render::current_gl().DetachShader)
#define glDisable (::cps::render::current_gl().Disable)
#define glDisableVertexAttribArray (::cps::render::current_gl().DisableVertexAttribArray)
#define glDrawArrays (::cps::render::current_gl().DrawArrays)
#define glDrawArraysInstanced (::cps::render::current_gl().DrawArraysInstanced)
#define glDrawBuffer (::cps::render::current_gl().DrawBuffer)
#define glDrawBuffers (::cps::render::current_gl().DrawBuffers)
#define glDrawElements (::cps::render::current_gl().DrawElements)
#define glDrawElementsInstanced (::cps::render::current_gl().DrawElementsInstanced)
#define glEnable (::cps::render::current_gl().Enable)
#define glEnableVertexAttribArray (::cps::render::current_gl().EnableVertexAttribArray)
#define glFinish (::cps::render::current_gl().Finish)
#define glFlush (::cps::render::current_gl().Flush)
#define glFramebufferRenderbuffer (::cps::render::current_gl().FramebufferRenderbuffer)
#define glFramebufferTexture2D (::cps::render::current_gl().FramebufferTexture2D)
#define glFrontFace (::cps::render::current_gl().FrontFace)
#define glGenBuffers (::cps::render::current_gl().GenBuffers)
#define glGenFramebuffers (::cps::render::current_gl().GenFramebuffers)
#define glGenRenderbuffers (::cps::render::current_gl().GenRenderbuffers)
#define glGenTextures (::cps::render::current_gl().GenTextures)
#define glGenVertexArrays (::cps::render::current_gl().GenVertexArrays)
#define glGenerateMipmap (::cps::render::current_gl().GenerateMipmap)
#define glGetError (::cps::render::current_gl().GetError)
#define glGetFloatv (::cps::render::current_gl().GetFloatv)
#define glGetIntegerv (::cps::render::current_gl().GetIntegerv)
#define glGetProgramInfoLog (::cps::render::current_gl().GetProgramInfoLog)
#define glGetProgramiv (::cps::render::current_gl().GetProgramiv)
#define glGetShaderInfoLog (::cps::render::current_gl().GetShaderInfoLog)
#define glGetShaderiv (::cps::render::current_gl().GetShaderiv)
#define glGetString (::cps::render::current_gl().GetString)
#define glGetUniformBlockIndex (::cps::render::current_gl().GetUniformBlockIndex)
#define glGetUniformLocation (::cps::render::current_gl().GetUniformLocation)
#define glLineWidth (::cps::render::current_gl().LineWidth)
#define glLinkProgram (::cps::render::current_gl().LinkProgram)
#define glPixelStorei (::cps::render::current_gl().PixelStorei)
#define glPolygonMode (::cps::render::current_gl().PolygonMode)
#define glPolygonOffset (::cps::render::current_gl().PolygonOffset)
#define glReadBuffer (::cps::render::current_gl().ReadBuffer)
#define glReadPixels (::cps::render::current_gl().ReadPixels)
#define glRenderbufferStorage (::cps::render::current_gl().RenderbufferStorage)
#define glRenderbufferStorageMultisample (::cps::render::current_gl().RenderbufferStorageMultisample)
#define glScissor (::cps::render::current_gl().Scissor)
#define glShaderSource (::cps::render::current_gl().ShaderSource)
#define glTexImage2D (::cps::render::current_gl().TexImage2D)
#define glTexParameterf (::cps::render::current_gl().TexParameterf)
#define glTexParameterfv (::cps::render::current_gl().TexParameterfv)
#define glTexParameteri (::cps::render::current_gl().TexParameteri)
#define glTexSubImage2D (::cps::render::current_gl().TexSubImage2D)
#define glUniform1f (::cps::render::current_gl().Uniform1f)
#define glUniform1fv (::cps::render::current_gl().Uniform1fv)
#define glUniform1i (::cps::render::current_gl().Uniform1i)
#define glUniform1iv (::cps::render::current_gl().Uniform1iv)
#define glUniform2f (::cps::render::current_gl().Uniform2f)
#define glUniform2fv (::cps::render::current_gl().Uniform2fv)
#define glUniform3f (::cps::render::current_gl().Uniform3f)
#define glUniform3fv (::cps::render::current_gl().Uniform3fv)
#define glUniform4f (::cps::render::current_gl().Uniform4f)
#define glUniform4fv (::cps::render::current_gl().Uniform4fv)
#define glUniformBlockBinding (::cps::render::current_gl().UniformBlockBinding)
#define glUniformMatrix3fv (::cps::render::current_gl().UniformMatrix3fv)
#define glUniformMatrix4fv (::cps::render::current_gl().UniformMatrix4fv)
#define glUseProgram (::cps::render::current_gl().UseProgram)
#define glVertexAttribDivisor (::cps::render::current_gl().VertexAttribDivisor)
#define glVertexAttribIPointer (::cps::render::current_gl().VertexAttribIPointer)
#define glVertexAttribPointer (::cps::render::current_gl().VertexAttribPointer)
#define glViewport (::cps::render::current_gl().Viewport)
