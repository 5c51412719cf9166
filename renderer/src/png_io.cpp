// write_png / read_png through stb_image_write and stb_image (compiled into Debian's libstb).

#include "cps/render/renderer.h"

#include <stb_image.h>
#include <stb_image_write.h>

#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>

namespace cps::render {
namespace {

// Speed over size. Measured on 1280x720 renders (llvmpipe host, stb from Debian 12): stb's
// default (adaptive filter, level 8) takes 65-80 ms per frame; filter 0 ("none") with level 1
// takes 24-34 ms and the files are even slightly smaller, since the renders are mostly flat
// colour which deflate handles well without prediction.
constexpr int k_png_compression_level = 1;
constexpr int k_png_filter = 0;

// stb keeps these settings in global variables; they are set once, before the first write.
void configure_stb_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    stbi_write_png_compression_level = k_png_compression_level;
    stbi_write_force_png_filter = k_png_filter;
  });
}

}  // namespace

// write_png: image of width x height > 0 with 3 * width * height bytes (RGB8, rows top to bottom),
// else std::runtime_error naming the path. Encodes with stb_image_write into "<path>.tmp" in the
// same folder and renames it over `path` (atomic on POSIX within one file system); on any failure
// the temporary file is removed and std::runtime_error names the path.
void write_png(const std::filesystem::path& path, const Image& image) {
  const auto expected = static_cast<std::size_t>(image.width > 0 ? image.width : 0) *
                        static_cast<std::size_t>(image.height > 0 ? image.height : 0) * 3u;
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != expected) {
    throw std::runtime_error("write_png: invalid image (" + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + ", " +
                             std::to_string(image.pixels.size()) + " bytes) for " + path.string());
  }
  configure_stb_once();
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  const int ok = stbi_write_png(tmp.c_str(), image.width, image.height, 3, image.pixels.data(),
                                image.width * 3);
  if (ok == 0) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error("write_png: cannot write " + path.string());
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error("write_png: cannot rename " + tmp.string() + " to " + path.string() +
                             ": " + ec.message());
  }
}

// read_png: decodes any PNG stb_image reads, converted to 3 channels (RGB8, rows top to bottom).
// std::runtime_error naming the path and stb's failure reason if it cannot.
Image read_png(const std::filesystem::path& path) {
  int w = 0;
  int h = 0;
  int channels_in_file = 0;
  stbi_uc* data = stbi_load(path.c_str(), &w, &h, &channels_in_file, 3);
  if (data == nullptr) {
    const char* reason = stbi_failure_reason();
    throw std::runtime_error("read_png: cannot read " + path.string() + ": " +
                             (reason != nullptr ? reason : "unknown error"));
  }
  Image image;
  image.width = w;
  image.height = h;
  image.pixels.assign(data, data + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3u);
  stbi_image_free(data);
  return image;
}

}  // namespace cps::render
