#pragma once
// Offscreen OpenGL renderer (OSMesa or EGL, both headless) and PNG encoding.

#include "cps/render/draw_list.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cps::render {

/// An RGB8 image, rows top to bottom: pixels.size() == 3 * width * height.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;
};

/// Milliseconds (wall clock) one Renderer::draw spent in each stage, when stage timing is on
/// (Renderer::set_stage_timing): glFinish ends each GL stage, so each figure is the work of that
/// stage alone (llvmpipe draws on its own threads; without the glFinish calls their work would
/// land in read_back).
struct StageTimes {
  double plan = 0.0;       // CPU: the frame plan (frame_plan.h)
  double upload = 0.0;     // instance buffers
  double shadow = 0.0;     // the shadow map (0 when it was kept from the previous frame)
  double bodies = 0.0;     // clear and opaque bodies
  double planes = 0.0;     // opaque planes
  double overlay = 0.0;    // lines, translucent planes, ghosts
  double resolve = 0.0;    // the multisample resolve
  double read_back = 0.0;  // glReadPixels or OSMesa's copy, to top-down RGB8
  double total() const {
    return plan + upload + shadow + bodies + planes + overlay + resolve + read_back;
  }
};

/// How the renderer gets its OpenGL context. Both render headless, without any window system.
enum class Backend {
  /// OSMesa (libOSMesa, Mesa's llvmpipe on the CPU). Upstream Mesa removed OSMesa in 25.1;
  /// Debian 12 ships it (libosmesa6).
  osmesa,
  /// EGL without a surface: Mesa's surfaceless platform (GPU render node, else llvmpipe), or an
  /// EGL device (e.g. NVIDIA's driver). Needs libEGL.so.1 and a vendor driver (libegl-mesa0).
  egl,
  /// The default: OSMesa where its context can be made (the library loads), else EGL; chosen
  /// when the context is created, so one binary renders on machines with either library.
  automatic,
};

/// "osmesa", "egl" or "auto".
std::string_view backend_name(Backend backend);

/// The backend named `name` ("osmesa", "egl", "auto"), or nullopt for any other text.
std::optional<Backend> parse_backend(std::string_view name);

/// Owns one OpenGL context and its frame buffer of width x height pixels (both in [1, 8192]).
/// Draws lit, shaded boxes, spheres, checkered planes and lines with a shadow map from the sun.
/// Not copyable; one renderer per thread (renderers of either backend may be used in turn).
class Renderer {
 public:
  /// Creates the context (OpenGL 3.3 core or newer) through `backend` (automatic: OSMesa, else
  /// EGL). Throws std::invalid_argument for a size out of range, std::runtime_error if the
  /// backend cannot create a context (the message names the step that failed; for automatic,
  /// each backend's reason) or a shader fails to build (the message holds the GL info log).
  Renderer(int width, int height, Backend backend = Backend::automatic);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  int width() const;
  int height() const;
  /// The backend that made the context: osmesa or egl, never automatic.
  Backend backend() const;
  /// The backend, GL version and renderer, e.g. "osmesa: OpenGL 4.5 (Core Profile) Mesa 22.3.6,
  /// llvmpipe (LLVM 15.0.6, 256 bits)".
  std::string context_description();

  /// Draws one frame of `list` into the frame buffer and returns it as an RGB8 image, rows top to
  /// bottom. Throws std::runtime_error on a GL error. While the view (camera, sun, background,
  /// planes, size) stays the same from frame to frame, only the rectangle holding the bodies,
  /// lines and shadows is drawn again, over a kept frame of the planes: the same pixels.
  Image draw(const DrawList& list);

  /// Stage timing (for measurement only; off by default): when on, draw() waits for each stage
  /// to finish (glFinish) and records its time, which makes the frame slower (the stages no
  /// longer overlap).
  void set_stage_timing(bool on);
  /// The stage times of the last draw() with stage timing on (all zero before).
  StageTimes last_stage_times() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Encodes `image` as an 8-bit RGB PNG file with stb_image_write (no row filter, deflate by
/// Intel's ISA-L at level 2, or by zlib at level 1 in a build without ISA-L: the fastest of the
/// encoders measured for these renders, see png_io.cpp). Returns the file's bytes, held in this
/// thread's encoder: valid until this thread's next encode_png call. Thread-safe: each thread has
/// its own encoder, whose buffers (about 6 bytes per pixel of the largest image, plus twice its
/// file) stay for its next call. Throws
/// std::invalid_argument for an invalid image (width or height <= 0, or pixels.size() !=
/// 3 * width * height; the message gives the sizes; or more than 2^30 bytes of rows, (3 width + 1)
/// height, the most stb_image_write's int sizes are kept within), std::runtime_error if the
/// compressor fails. Writes no file: the caller decides how (the cps command writes atomically,
/// see FileSink).
std::span<const std::uint8_t> encode_png(const Image& image);

/// Writes one file: `bytes` as the whole content of `path`. The renderer writes no file itself;
/// PngWriter hands every encoded frame to its sink. Called on PngWriter's threads (one call per
/// file, distinct paths at the same time), so it must be thread-safe; it must throw an exception
/// (std::runtime_error naming the path and the reason) if the file cannot be written.
using FileSink =
    std::function<void(const std::filesystem::path& path, std::span<const std::uint8_t> bytes)>;

/// Encodes PNG files on background threads while the caller draws the next frames (the GL context
/// stays on the caller's thread: only finished images are handed over) and writes each through
/// the sink. At most `max_in_flight` images are queued or being encoded at any time, so memory
/// stays bounded (one 1280x720 frame is 2.7 MB).
///
/// Errors: the first failure (an invalid image: std::runtime_error naming the path; or whatever
/// the sink threw) is kept; from then on queued images are dropped (the sink is not called for
/// them), and the next write() or finish() rethrows it.
/// Not copyable; use from one thread.
class PngWriter {
 public:
  /// sink: writes each file (must not be empty); threads: encoder threads in [1, 16] (typical
  /// 1-2); max_in_flight: images queued or being encoded, >= threads (typical 3). Throws
  /// std::invalid_argument otherwise.
  explicit PngWriter(FileSink sink, int threads = 1, int max_in_flight = 3);
  /// Waits for the queued writes to end, then joins the threads. Errors are not reported here:
  /// call finish() to see them.
  ~PngWriter();
  PngWriter(const PngWriter&) = delete;
  PngWriter& operator=(const PngWriter&) = delete;

  /// Queues `image` for `path`; blocks while max_in_flight images are pending. Throws the error
  /// of an earlier failed write, and then queues nothing.
  void write(std::filesystem::path path, Image image);

  /// Blocks until every queued image is written; throws the first write error if there was one.
  void finish();

  /// Files written so far (sink calls that returned).
  long long written() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads a PNG back as RGB8 (for tests and tools) through libpng, which checks every chunk's CRC
/// and the zlib checksum; alpha, if any, is composited onto black; 16-bit samples without gAMA
/// or sRGB are taken as sRGB, as 8-bit ones are. Throws std::runtime_error naming the path and
/// the reason on failure: not a regular file (a FIFO, a folder, a link loop), a declared size past
/// what encode_png writes ((3 width + 1) height > 2^30 bytes, checked before any pixel is
/// allocated), or a file libpng refuses.
Image read_png(const std::filesystem::path& path);

}  // namespace cps::render
