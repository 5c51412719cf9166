#pragma once
// Private: the OSMesa backend (Mesa's software rasterizer, llvmpipe). All OSMesa calls live in
// osmesa_context.cpp, in the spirit of Mesa's osdemo.c: create a context, bind a client memory
// buffer as its window-system framebuffer, draw, glFinish, read the buffer.

#include "gl_context.h"

#include <memory>

namespace cps::render {

/// Loads libOSMesa (dlopen, once per process) and creates an OpenGL core-profile context (3.3
/// requested; Mesa may hand out a newer core version) whose default framebuffer is an RGBA8 client
/// buffer of width x height pixels (each in [1, 8192], checked by the caller) with a 24-bit depth
/// buffer. The context is current on return. Throws std::runtime_error naming the step that failed:
/// libOSMesa not found (install libosmesa6, or use the EGL backend: upstream Mesa dropped OSMesa in
/// 25.1), context creation, binding the buffer, or a GL version below 3.3; or, in a build without
/// GL/osmesa.h (CPS_HAVE_OSMESA_HEADERS 0), always, saying that the backend was left out.
std::unique_ptr<OffscreenContext> make_osmesa_context(int width, int height);

}  // namespace cps::render
