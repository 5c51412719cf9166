#pragma once
// Offscreen OpenGL renderer through OSMesa (Mesa's software rasterizer, llvmpipe) and PNG output.

#include "cps/render/draw_list.h"

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

namespace cps::render {

/// An RGB8 image, rows top to bottom: pixels.size() == 3 * width * height.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;
};

/// Owns one OSMesa context and its frame buffer of width x height pixels (both in [1, 8192]).
/// Draws lit, shaded boxes, spheres, checkered planes and lines with a shadow map from the sun.
/// Not copyable; one renderer per thread.
class Renderer {
 public:
  /// Creates the context (OpenGL 3.3 core or newer). Throws std::invalid_argument for a size out
  /// of range, std::runtime_error if OSMesa cannot create a context or a shader fails to build
  /// (the message holds the GL info log).
  Renderer(int width, int height);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  int width() const;
  int height() const;

  /// Draws one frame of `list` into the frame buffer and returns it as an RGB8 image, rows top to
  /// bottom. Throws std::runtime_error on a GL error.
  Image draw(const DrawList& list);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Writes `image` as a PNG at `path`. The file is first written under a temporary name in the
/// same folder and then renamed, so an interrupted run never leaves a half-written frame.
/// Throws std::runtime_error naming the path if it cannot be written.
void write_png(const std::filesystem::path& path, const Image& image);

/// Reads a PNG back (for tests and tools). Throws std::runtime_error naming the path on failure.
Image read_png(const std::filesystem::path& path);

}  // namespace cps::render
