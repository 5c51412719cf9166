#pragma once
// Private: the EGL backend, headless and without any window system or pbuffer: a display of an
// enumerated hardware device (EGL_EXT_device_enumeration + EGL_EXT_platform_device: how NVIDIA's
// driver renders headless), else of Mesa's surfaceless platform (EGL_MESA_platform_surfaceless: a
// GPU render node when there is one, llvmpipe otherwise), else of a software device (Mesa's
// EGL_MESA_device_software, llvmpipe), an OpenGL 3.3 core context made
// current with no surface (EGL_KHR_surfaceless_context), drawing into its own framebuffer object.
// All EGL calls live in egl_context.cpp.

#include "gl_context.h"

#include <memory>

namespace cps::render {

/// Loads libEGL (dlopen of libEGL.so.1, once per process), makes a display as described above,
/// creates an OpenGL 3.3 core context (eglBindAPI(EGL_OPENGL_API)), makes it current without a
/// surface, loads the GL functions through eglGetProcAddress and creates a width x height RGBA8 +
/// 24-bit depth framebuffer object (each size in [1, 8192], checked by the caller). The context is
/// current on return. Throws std::runtime_error naming each step that failed (with the EGL error
/// name) and suggesting the OSMesa backend (`--backend osmesa`).
std::unique_ptr<OffscreenContext> make_egl_context(int width, int height);

}  // namespace cps::render
