#include "cps/render/image_ops.h"

#include <stb_easy_font.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace cps::render {
namespace {

// Blends colour c (bytes) over pixel (px, py) with weight a in [0, 1].
void blend(Image& image, int px, int py, const std::uint8_t c[3], float a) {
  if (px < 0 || py < 0 || px >= image.width || py >= image.height) return;
  std::uint8_t* p = &image.pixels[3 * (static_cast<std::size_t>(py) * image.width + px)];
  for (int k = 0; k < 3; ++k) {
    p[k] = static_cast<std::uint8_t>(std::lround((1.0f - a) * p[k] + a * c[k]));
  }
}

void fill_rect(Image& image, int x0, int y0, int x1, int y1, const std::uint8_t c[3], float a) {
  for (int py = y0; py < y1; ++py) {
    for (int px = x0; px < x1; ++px) blend(image, px, py, c, a);
  }
}

}  // namespace

Image side_by_side(const std::vector<Image>& images) {
  if (images.empty()) throw std::invalid_argument("side_by_side: no image given");
  Image out;
  out.height = images.front().height;
  for (const Image& im : images) {
    if (im.height != out.height) {
      throw std::invalid_argument("side_by_side: heights differ (" + std::to_string(im.height) +
                                  " and " + std::to_string(out.height) + " pixels)");
    }
    out.width += im.width;
  }
  out.pixels.resize(3 * static_cast<std::size_t>(out.width) * out.height);
  for (int y = 0; y < out.height; ++y) {
    std::size_t offset = 3 * static_cast<std::size_t>(y) * out.width;
    for (const Image& im : images) {
      const auto row = 3 * static_cast<std::size_t>(im.width);
      std::copy_n(&im.pixels[row * y], row, &out.pixels[offset]);
      offset += row;
    }
  }
  return out;
}

void draw_label(Image& image, int x, int y, std::string_view text, int scale,
                const glm::vec3& color) {
  if (scale < 1) throw std::invalid_argument("draw_label: scale " + std::to_string(scale) + " must be >= 1");
  std::string buffer(text);
  // stb_easy_font emits 4 vertices per quad, 16 bytes each: x, y, z as float and 4 colour bytes.
  std::vector<char> vertices(64 * (buffer.size() + 1) * 16);
  const int quads = stb_easy_font_print(0.0f, 0.0f, buffer.data(), nullptr, vertices.data(),
                                        static_cast<int>(vertices.size()));
  const int width = stb_easy_font_width(buffer.data());
  const int height = stb_easy_font_height(buffer.data());
  const std::uint8_t white[3] = {255, 255, 255};
  const int pad = 2 * scale;
  fill_rect(image, x - pad, y - pad, x + width * scale + pad, y + height * scale + pad, white, 0.75f);
  const std::uint8_t ink[3] = {static_cast<std::uint8_t>(std::clamp(color.r, 0.0f, 1.0f) * 255.0f),
                               static_cast<std::uint8_t>(std::clamp(color.g, 0.0f, 1.0f) * 255.0f),
                               static_cast<std::uint8_t>(std::clamp(color.b, 0.0f, 1.0f) * 255.0f)};
  for (int q = 0; q < quads; ++q) {
    const float* v0 = reinterpret_cast<const float*>(&vertices[static_cast<std::size_t>(q) * 64]);
    const float* v2 = reinterpret_cast<const float*>(&vertices[static_cast<std::size_t>(q) * 64 + 32]);
    const int x0 = x + static_cast<int>(std::lround(v0[0] * scale));
    const int y0 = y + static_cast<int>(std::lround(v0[1] * scale));
    const int x1 = x + static_cast<int>(std::lround(v2[0] * scale));
    const int y1 = y + static_cast<int>(std::lround(v2[1] * scale));
    fill_rect(image, std::min(x0, x1), std::min(y0, y1), std::max(x0, x1), std::max(y0, y1), ink, 1.0f);
  }
}

}  // namespace cps::render
