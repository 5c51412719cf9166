// EGL context creation (surfaceless, no pbuffer) and readback from its framebuffer object. The
// only file that includes EGL headers.
//
// libEGL (GLVND's libEGL.so.1, which loads the vendor's driver, e.g. Mesa's libEGL_mesa) is opened
// with dlopen rather than linked, so that a machine without EGL gets a clear error naming the
// missing library instead of a binary that does not start, and the OSMesa backend still works.
// GL functions come from eglGetProcAddress (EGL 1.5 / EGL_KHR_client_get_all_proc_addresses give
// core functions too), never from linked symbols: see gl_functions.h.

#include "egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <dlfcn.h>

#include <cstdint>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace cps::render {
namespace {

const char* const k_hint = "render with --backend osmesa instead";

/// The EGL entry points, from libEGL opened once per process (never closed).
struct EglApi {
  decltype(&::eglGetProcAddress) GetProcAddress = nullptr;
  decltype(&::eglGetError) GetError = nullptr;
  decltype(&::eglQueryString) QueryString = nullptr;
  decltype(&::eglInitialize) Initialize = nullptr;
  decltype(&::eglBindAPI) BindAPI = nullptr;
  decltype(&::eglChooseConfig) ChooseConfig = nullptr;
  decltype(&::eglCreateContext) CreateContext = nullptr;
  decltype(&::eglDestroyContext) DestroyContext = nullptr;
  decltype(&::eglMakeCurrent) MakeCurrent = nullptr;
  // Extensions, nullptr when absent.
  PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT = nullptr;
  PFNEGLQUERYDEVICESEXTPROC QueryDevicesEXT = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC QueryDeviceStringEXT = nullptr;
  std::string client_extensions;
};

/// True if the space-separated list `list` contains `name` as a whole word.
bool has_extension(const std::string& list, const std::string& name) {
  std::size_t pos = 0;
  while ((pos = list.find(name, pos)) != std::string::npos) {
    const bool starts = pos == 0 || list[pos - 1] == ' ';
    const std::size_t end = pos + name.size();
    if (starts && (end == list.size() || list[end] == ' ')) return true;
    pos = end;
  }
  return false;
}

std::string egl_error_name(EGLint e) {
  switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: break;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "EGL error 0x%04X", static_cast<unsigned>(e));
  return buf;
}

const EglApi& egl_api() {
  static EglApi api;
  static std::string error;
  static std::once_flag once;
  std::call_once(once, [] {
    void* lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
    if (lib == nullptr) {
      const char* why = dlerror();
      error = std::string("cannot load libEGL.so.1 (") + (why != nullptr ? why : "not found") +
              "); install the Debian packages libegl1 and libegl-mesa0";
      return;
    }
    const auto sym = [&](const char* name) {
      void* f = dlsym(lib, name);
      if (f == nullptr && error.empty()) error = std::string("libEGL.so.1 has no ") + name;
      return f;
    };
#define CPS_EGL_SYM(name) api.name = reinterpret_cast<decltype(api.name)>(sym("egl" #name))
    CPS_EGL_SYM(GetProcAddress);
    CPS_EGL_SYM(GetError);
    CPS_EGL_SYM(QueryString);
    CPS_EGL_SYM(Initialize);
    CPS_EGL_SYM(BindAPI);
    CPS_EGL_SYM(ChooseConfig);
    CPS_EGL_SYM(CreateContext);
    CPS_EGL_SYM(DestroyContext);
    CPS_EGL_SYM(MakeCurrent);
#undef CPS_EGL_SYM
    if (!error.empty()) return;
    // Client extensions (EGL_EXT_client_extensions): a null string means none are supported.
    const char* ext = api.QueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    api.client_extensions = ext != nullptr ? ext : "";
    if (has_extension(api.client_extensions, "EGL_EXT_platform_base")) {
      api.GetPlatformDisplayEXT = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
          api.GetProcAddress("eglGetPlatformDisplayEXT"));
    }
    if (has_extension(api.client_extensions, "EGL_EXT_device_enumeration") ||
        has_extension(api.client_extensions, "EGL_EXT_device_base")) {
      api.QueryDevicesEXT =
          reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(api.GetProcAddress("eglQueryDevicesEXT"));
      api.QueryDeviceStringEXT = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
          api.GetProcAddress("eglQueryDeviceStringEXT"));
    }
  });
  if (!error.empty()) throw std::runtime_error(std::string("cps::render: egl backend: ") + error +
                                               "; " + k_hint);
  return api;
}

// Displays are initialised and never terminated. One display handle exists per platform and
// device for the whole process, so eglTerminate would end the contexts of every other renderer on
// it; and on Mesa 22.3 terminating unloads the driver, leaving two 56-byte allocations that
// LeakSanitizer reports as leaked (from an unloaded module). A display's driver state thus stays
// until the process exits; eglInitialize on an initialised display is a no-op.

void* egl_lookup(const char* name, void* user) {
  const auto* api = static_cast<const EglApi*>(user);
  return reinterpret_cast<void*>(api->GetProcAddress(name));
}

/// One way to get a display: a platform and its native display (a device handle or default).
struct Candidate {
  std::string name;  // for messages: "Mesa surfaceless platform", "EGL device 0 (...)"
  EGLenum platform;
  void* native;
};

class EglContext final : public OffscreenContext {
 public:
  EglContext(int width, int height) : api_(egl_api()), width_(width), height_(height) {
    const std::vector<Candidate> candidates = find_candidates();
    std::string failures;
    for (const Candidate& c : candidates) {
      std::string why;
      if (try_candidate(c, why)) {
        source_ = c.name;
        break;
      }
      failures += (failures.empty() ? "" : "; ") + c.name + ": " + why;
    }
    if (context_ == EGL_NO_CONTEXT) {
      if (candidates.empty() && api_.client_extensions.empty()) {
        failures = "libEGL reports no client extensions, so no EGL driver is installed or found "
                   "(Mesa's is the Debian package libegl-mesa0)";
      } else if (candidates.empty()) {
        failures = "libEGL offers neither EGL_MESA_platform_surfaceless nor "
                   "EGL_EXT_platform_device + EGL_EXT_device_enumeration (client extensions: " +
                   api_.client_extensions + ")";
      }
      throw std::runtime_error("cps::render: egl backend: no OpenGL 3.3 core context could be "
                               "made: " + failures + "; " + k_hint);
    }
    try {
      load_gl_functions(fn_, egl_lookup, const_cast<EglApi*>(&api_), "egl backend");
      check_version();
      create_framebuffer();
    } catch (...) {
      destroy();
      throw;
    }
  }

  ~EglContext() override { destroy(); }

  void bind() override {
    api_.BindAPI(EGL_OPENGL_API);
    if (!api_.MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      throw std::runtime_error("cps::render: egl backend: eglMakeCurrent failed (" +
                               egl_error_name(api_.GetError()) + ")");
    }
  }

  void unbind() noexcept override {
    api_.BindAPI(EGL_OPENGL_API);  // releasing applies to the thread's bound API
    api_.MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }

  GLuint framebuffer() const override { return fbo_; }

  void read_rgb(Image& out) override {
    const auto w = static_cast<std::size_t>(width_);
    const auto h = static_cast<std::size_t>(height_);
    rgba_.resize(w * h * 4u);
    fn_.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    fn_.ReadBuffer(GL_COLOR_ATTACHMENT0);
    fn_.PixelStorei(GL_PACK_ALIGNMENT, 4);
    fn_.ReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rgba_.data());
    const GLenum e = fn_.GetError();
    if (e != GL_NO_ERROR) {
      throw std::runtime_error("cps::render: egl backend: glReadPixels failed (GL error " +
                               std::to_string(e) + ")");
    }
    rgba_bottom_up_to_rgb(rgba_.data(), width_, height_, out);
  }

  const GlFunctions& functions() const override { return fn_; }

  std::string description() const override {
    return "egl (" + source_ + "): " + gl_version_and_renderer(fn_);
  }

  int width() const override { return width_; }
  int height() const override { return height_; }

 private:
  /// The displays to try, in order: enumerated hardware devices (a GPU: NVIDIA's driver offers
  /// only these), then Mesa's surfaceless platform (a render node, else llvmpipe), then the
  /// software devices (EGL_MESA_device_software). A GPU thus wins over llvmpipe when GLVND has
  /// both vendors; without a GPU the order is surfaceless first, as before.
  std::vector<Candidate> find_candidates() const {
    std::vector<Candidate> hardware;
    std::vector<Candidate> software;
    if (api_.GetPlatformDisplayEXT == nullptr) return hardware;
    if (api_.QueryDevicesEXT != nullptr &&
        has_extension(api_.client_extensions, "EGL_EXT_platform_device")) {
      EGLint count = 0;
      if (api_.QueryDevicesEXT(0, nullptr, &count) && count > 0) {
        std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
        if (api_.QueryDevicesEXT(count, devices.data(), &count)) {
          devices.resize(static_cast<std::size_t>(count));
          for (std::size_t i = 0; i < devices.size(); ++i) {
            std::string name = "EGL device " + std::to_string(i);
            std::string ext;
            if (api_.QueryDeviceStringEXT != nullptr) {
              const char* e = api_.QueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
              if (e != nullptr) ext = e;
            }
            if (!ext.empty()) name += " (" + ext + ")";
            const bool is_software = has_extension(ext, "EGL_MESA_device_software");
            (is_software ? software : hardware)
                .push_back({name, EGL_PLATFORM_DEVICE_EXT, devices[i]});
          }
        }
      }
    }
    std::vector<Candidate> out = std::move(hardware);
    if (has_extension(api_.client_extensions, "EGL_MESA_platform_surfaceless")) {
      out.push_back({"Mesa surfaceless platform", EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY});
    }
    out.insert(out.end(), software.begin(), software.end());
    return out;
  }

  /// Display, initialise, context, make current. On failure: `why` names the step and the EGL
  /// error, everything made so far is released, and false is returned.
  bool try_candidate(const Candidate& c, std::string& why) {
    const auto fail = [&](const std::string& step) {
      why = step + " failed (" + egl_error_name(api_.GetError()) + ")";
      return false;
    };
    EGLDisplay display = api_.GetPlatformDisplayEXT(c.platform, c.native, nullptr);
    if (display == EGL_NO_DISPLAY) return fail("eglGetPlatformDisplayEXT");
    EGLint major = 0;
    EGLint minor = 0;
    if (!api_.Initialize(display, &major, &minor)) return fail("eglInitialize");
    const char* ext_c = api_.QueryString(display, EGL_EXTENSIONS);
    const std::string ext = ext_c != nullptr ? ext_c : "";
    const auto give_up = [&](const std::string& reason) {
      why = reason;
      return false;
    };
    if (!has_extension(ext, "EGL_KHR_surfaceless_context")) {
      return give_up("the display lacks EGL_KHR_surfaceless_context");
    }
    if (!(major > 1 || (major == 1 && minor >= 5)) && !has_extension(ext, "EGL_KHR_create_context")) {
      return give_up("EGL " + std::to_string(major) + "." + std::to_string(minor) +
                     " without EGL_KHR_create_context cannot ask for OpenGL 3.3 core");
    }
    if (!api_.BindAPI(EGL_OPENGL_API)) {
      fail("eglBindAPI(EGL_OPENGL_API)");
      return give_up(why + ": this EGL driver offers no desktop OpenGL");
    }
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!has_extension(ext, "EGL_KHR_no_config_context") &&
        !has_extension(ext, "EGL_MESA_configless_context")) {
      const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
      EGLint n = 0;
      if (!api_.ChooseConfig(display, want, &config, 1, &n) || n < 1) {
        fail("eglChooseConfig(EGL_OPENGL_BIT)");
        return give_up(why);
      }
    }
    const EGLint attribs[] = {
        EGL_CONTEXT_MAJOR_VERSION, 3,
        EGL_CONTEXT_MINOR_VERSION, 3,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL_NONE,
    };
    EGLContext context = api_.CreateContext(display, config, EGL_NO_CONTEXT, attribs);
    if (context == EGL_NO_CONTEXT) {
      fail("eglCreateContext(OpenGL 3.3 core)");
      return give_up(why);
    }
    if (!api_.MakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
      fail("eglMakeCurrent(no surface)");
      api_.DestroyContext(display, context);
      return give_up(why);
    }
    display_ = display;
    context_ = context;
    return true;
  }

  void check_version() {
    GLint major = 0;
    GLint minor = 0;
    fn_.GetIntegerv(GL_MAJOR_VERSION, &major);
    fn_.GetIntegerv(GL_MINOR_VERSION, &minor);
    if (major < 3 || (major == 3 && minor < 3)) {
      throw std::runtime_error("cps::render: egl backend: the context has OpenGL " +
                               std::to_string(major) + "." + std::to_string(minor) +
                               ", need 3.3 core; " + k_hint);
    }
  }

  void create_framebuffer() {
    fn_.GenFramebuffers(1, &fbo_);
    fn_.GenRenderbuffers(1, &color_);
    fn_.GenRenderbuffers(1, &depth_);
    fn_.BindRenderbuffer(GL_RENDERBUFFER, color_);
    fn_.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width_, height_);
    fn_.BindRenderbuffer(GL_RENDERBUFFER, depth_);
    fn_.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width_, height_);
    fn_.BindRenderbuffer(GL_RENDERBUFFER, 0);
    fn_.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
    fn_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
    fn_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
    const GLenum status = fn_.CheckFramebufferStatus(GL_FRAMEBUFFER);
    fn_.BindFramebuffer(GL_FRAMEBUFFER, 0);
    const GLenum e = fn_.GetError();
    if (status != GL_FRAMEBUFFER_COMPLETE || e != GL_NO_ERROR) {
      throw std::runtime_error("cps::render: egl backend: the " + std::to_string(width_) + "x" +
                               std::to_string(height_) +
                               " RGBA8 + depth 24 framebuffer object is incomplete (status " +
                               std::to_string(status) + ", GL error " + std::to_string(e) + ")");
    }
  }

  void destroy() noexcept {
    if (context_ != EGL_NO_CONTEXT) {
      // Delete the framebuffer while the context is current, then release and destroy it.
      api_.BindAPI(EGL_OPENGL_API);
      if (api_.MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) &&
          fn_.DeleteFramebuffers != nullptr) {
        if (fbo_ != 0) fn_.DeleteFramebuffers(1, &fbo_);
        if (color_ != 0) fn_.DeleteRenderbuffers(1, &color_);
        if (depth_ != 0) fn_.DeleteRenderbuffers(1, &depth_);
      }
      unbind();
      api_.DestroyContext(display_, context_);
      context_ = EGL_NO_CONTEXT;
    }
  }

  const EglApi& api_;
  int width_;
  int height_;
  std::string source_;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  GlFunctions fn_;
  GLuint fbo_ = 0;
  GLuint color_ = 0;
  GLuint depth_ = 0;
  std::vector<std::uint8_t> rgba_;  // readback staging, 4 * width * height bytes
};

}  // namespace

std::unique_ptr<OffscreenContext> make_egl_context(int width, int height) {
  return std::make_unique<EglContext>(width, height);
}

}  // namespace cps::render
