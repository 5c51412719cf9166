// OSMesa context creation and frame buffer readback. The only file that includes GL/osmesa.h.
//
// libOSMesa is opened with dlopen (RTLD_LOCAL) rather than linked: its exported glXxx symbols
// then never enter the program's global namespace (see gl_functions.h), and a cps binary still
// starts, and can render through EGL, on a system without OSMesa (upstream Mesa removed it in
// 25.1). GL functions come from OSMesaGetProcAddress, which returns Mesa's dispatch stubs.

#include "osmesa_context.h"

#if CPS_HAVE_OSMESA_HEADERS
#include <GL/osmesa.h>
#include <dlfcn.h>
#endif

#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
// Gallium's OSMesa keeps every buffer ever bound by OSMesaMakeCurrent in a global list that
// OSMesaDestroyContext does not free (a few hundred bytes per context); it is not reachable through
// the API, so LeakSanitizer is told to ignore allocations made inside libOSMesa. Likewise
// fontconfig, which cairo loads to find DejaVu Sans for the figures' labels (demos/cps/
// compose.cpp): its pattern cache (about 1 kB, allocated in FcValueSave and kin) is never freed
// before exit. (One suppression list per process: this binary's renderer holds it.)
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libOSMesa.so\n"
         "leak:libfontconfig.so\n";
}
#endif

#if CPS_HAVE_OSMESA_HEADERS
namespace cps::render {
namespace {

/// The OSMesa entry points, from the library opened once per process (never closed: Mesa keeps
/// per-thread and at-exit state that must outlive every context).
struct OsMesaApi {
  decltype(&::OSMesaCreateContextAttribs) CreateContextAttribs = nullptr;
  decltype(&::OSMesaDestroyContext) DestroyContext = nullptr;
  decltype(&::OSMesaMakeCurrent) MakeCurrent = nullptr;
  decltype(&::OSMesaGetProcAddress) GetProcAddress = nullptr;
};

const OsMesaApi& osmesa_api() {
  static OsMesaApi api;
  static std::string error;
  static std::once_flag once;
  std::call_once(once, [] {
    // Debian 12 ships libOSMesa.so.8 (libosmesa6); the unversioned name needs the -dev package.
    void* lib = nullptr;
    std::string tried;
    for (const char* name : {"libOSMesa.so.8", "libOSMesa.so"}) {
      lib = dlopen(name, RTLD_NOW | RTLD_LOCAL);
      if (lib != nullptr) break;
      const char* why = dlerror();
      tried += std::string(tried.empty() ? "" : "; ") + (why != nullptr ? why : name);
    }
    if (lib == nullptr) {
      error = "cannot load libOSMesa (" + tried +
              "); install the Debian package libosmesa6, or render with --backend egl";
      return;
    }
    const auto sym = [&](const char* name) {
      void* f = dlsym(lib, name);
      if (f == nullptr && error.empty()) error = std::string("libOSMesa has no ") + name;
      return f;
    };
    api.CreateContextAttribs =
        reinterpret_cast<decltype(api.CreateContextAttribs)>(sym("OSMesaCreateContextAttribs"));
    api.DestroyContext = reinterpret_cast<decltype(api.DestroyContext)>(sym("OSMesaDestroyContext"));
    api.MakeCurrent = reinterpret_cast<decltype(api.MakeCurrent)>(sym("OSMesaMakeCurrent"));
    api.GetProcAddress = reinterpret_cast<decltype(api.GetProcAddress)>(sym("OSMesaGetProcAddress"));
  });
  if (!error.empty()) throw std::runtime_error("cps::render: osmesa backend: " + error);
  return api;
}

void* osmesa_lookup(const char* name, void* user) {
  const auto get = reinterpret_cast<decltype(&::OSMesaGetProcAddress)>(user);
  return reinterpret_cast<void*>(get(name));
}

class OsMesaContext final : public OffscreenContext {
 public:
  OsMesaContext(int width, int height)
      : api_(osmesa_api()),
        width_(width),
        height_(height),
        rgba_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4u, 0) {
    const int attribs[] = {
        OSMESA_FORMAT,                OSMESA_RGBA,
        OSMESA_DEPTH_BITS,            24,
        OSMESA_STENCIL_BITS,          0,
        OSMESA_ACCUM_BITS,            0,
        OSMESA_PROFILE,               OSMESA_CORE_PROFILE,
        OSMESA_CONTEXT_MAJOR_VERSION, 3,
        OSMESA_CONTEXT_MINOR_VERSION, 3,
        0,
    };
    ctx_ = api_.CreateContextAttribs(attribs, nullptr);
    if (ctx_ == nullptr) {
      throw std::runtime_error(
          "cps::render: osmesa backend: OSMesaCreateContextAttribs failed (OpenGL 3.3 core, RGBA, "
          "depth 24)");
    }
    try {
      bind();
      load_gl_functions(fn_, osmesa_lookup, reinterpret_cast<void*>(api_.GetProcAddress),
                        "osmesa backend");
      GLint major = 0;
      GLint minor = 0;
      fn_.GetIntegerv(GL_MAJOR_VERSION, &major);
      fn_.GetIntegerv(GL_MINOR_VERSION, &minor);
      if (major < 3 || (major == 3 && minor < 3)) {
        throw std::runtime_error("cps::render: osmesa backend: OSMesa gave OpenGL " +
                                 std::to_string(major) + "." + std::to_string(minor) +
                                 ", need 3.3 core");
      }
    } catch (...) {
      unbind();
      api_.DestroyContext(ctx_);
      throw;
    }
  }

  ~OsMesaContext() override {
    unbind();  // owns no GL object: nothing to delete while current
    api_.DestroyContext(ctx_);
  }

  void bind() override {
    if (!api_.MakeCurrent(ctx_, rgba_.data(), GL_UNSIGNED_BYTE, width_, height_)) {
      throw std::runtime_error("cps::render: osmesa backend: OSMesaMakeCurrent failed for a " +
                               std::to_string(width_) + "x" + std::to_string(height_) + " buffer");
    }
  }

  void unbind() noexcept override { api_.MakeCurrent(nullptr, nullptr, 0, 0, 0); }

  GLuint framebuffer() const override { return 0; }

  void read_rgb(Image& out) override {
    fn_.Finish();  // OSMesa copies the rendering into rgba_ when the context flushes
    // OSMesa's default (OSMESA_Y_UP = true) stores the bottom row first.
    rgba_bottom_up_to_rgb(rgba_.data(), width_, height_, out);
  }

  const GlFunctions& functions() const override { return fn_; }

  std::string description() const override {
    return "osmesa: " + gl_version_and_renderer(fn_);
  }

  int width() const override { return width_; }
  int height() const override { return height_; }

 private:
  const OsMesaApi& api_;
  int width_;
  int height_;
  std::vector<std::uint8_t> rgba_;  // the OSMesa colour buffer, 4 * width * height bytes
  OSMesaContext ctx_ = nullptr;
  GlFunctions fn_;
};

}  // namespace

std::unique_ptr<OffscreenContext> make_osmesa_context(int width, int height) {
  return std::make_unique<OsMesaContext>(width, height);
}

}  // namespace cps::render

#else  // built without GL/osmesa.h

namespace cps::render {

std::unique_ptr<OffscreenContext> make_osmesa_context(int, int) {
  throw std::runtime_error(
      "cps::render: osmesa backend: this cps was built without OSMesa's header GL/osmesa.h "
      "(Debian: libosmesa6-dev), so the osmesa backend is left out; --backend auto and egl render "
      "through EGL");
}

}  // namespace cps::render

#endif
