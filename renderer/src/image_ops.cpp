#include "cps/render/image_ops.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace cps::render {
Image grid(const std::vector<Image>& images, int columns, const glm::vec3& fill) {
  if (images.empty()) throw std::invalid_argument("grid: no image given");
  if (columns < 1) throw std::invalid_argument("grid: " + std::to_string(columns) + " columns; give >= 1");
  const int w = images.front().width;
  const int h = images.front().height;
  for (const Image& im : images) {
    if (im.width != w || im.height != h) {
      throw std::invalid_argument("grid: sizes differ (" + std::to_string(im.width) + "x" +
                                  std::to_string(im.height) + " and " + std::to_string(w) + "x" +
                                  std::to_string(h) + " pixels)");
    }
  }
  const int n = static_cast<int>(images.size());
  const int cols = std::min(columns, n);
  const int rows = (n + cols - 1) / cols;
  Image out;
  out.width = cols * w;
  out.height = rows * h;
  out.pixels.resize(3 * static_cast<std::size_t>(out.width) * out.height);
  const std::uint8_t c[3] = {static_cast<std::uint8_t>(std::lround(std::clamp(fill.r, 0.0f, 1.0f) * 255.0f)),
                             static_cast<std::uint8_t>(std::lround(std::clamp(fill.g, 0.0f, 1.0f) * 255.0f)),
                             static_cast<std::uint8_t>(std::lround(std::clamp(fill.b, 0.0f, 1.0f) * 255.0f))};
  for (std::size_t i = 0; i < out.pixels.size(); i += 3) std::copy_n(c, 3, &out.pixels[i]);
  const auto row_bytes = 3 * static_cast<std::size_t>(w);
  for (int k = 0; k < n; ++k) {
    const int x0 = (k % cols) * w;
    const int y0 = (k / cols) * h;
    for (int y = 0; y < h; ++y) {
      std::copy_n(&images[static_cast<std::size_t>(k)].pixels[row_bytes * y], row_bytes,
                  &out.pixels[3 * (static_cast<std::size_t>(y0 + y) * out.width + x0)]);
    }
  }
  return out;
}

}  // namespace cps::render
