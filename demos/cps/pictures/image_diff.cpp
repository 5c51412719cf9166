#include "pictures/image_diff.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

namespace cps::cli {
namespace {

void check_pixels(const render::Image& image, const char* which) {
  if (image.width < 0 || image.height < 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 3) {
    throw std::invalid_argument(std::string("image ") + which + ": its pixels are not width x height x 3 bytes");
  }
}

}  // namespace

ImageDiff compare_images(const render::Image& a, const render::Image& b, double threshold_levels) {
  check_pixels(a, "a");
  check_pixels(b, "b");
  ImageDiff d;
  d.pixels = static_cast<long long>(a.width) * a.height;
  d.same_size = a.width == b.width && a.height == b.height;
  if (!d.same_size) return d;
  long long sum = 0;
  for (std::size_t p = 0; p < a.pixels.size(); p += 3) {
    int largest = 0;
    for (std::size_t c = p; c < p + 3; ++c) {
      const int diff = std::abs(static_cast<int>(a.pixels[c]) - static_cast<int>(b.pixels[c]));
      largest = std::max(largest, diff);
      sum += diff;
    }
    d.max_abs = std::max(d.max_abs, largest);
    if (largest > threshold_levels) ++d.past;
  }
  if (!a.pixels.empty()) d.mean_abs = static_cast<double>(sum) / static_cast<double>(a.pixels.size());
  return d;
}

render::Image diff_picture(const render::Image& a, const render::Image& b, double threshold_levels) {
  check_pixels(a, "a");
  check_pixels(b, "b");
  if (a.width != b.width || a.height != b.height) {
    throw std::invalid_argument("diff_picture: the images' sizes differ");
  }
  render::Image out{a.width, a.height, std::vector<std::uint8_t>(a.pixels.size())};
  for (std::size_t p = 0; p < a.pixels.size(); p += 3) {
    int largest = 0;
    for (std::size_t c = p; c < p + 3; ++c) {
      largest = std::max(largest, std::abs(static_cast<int>(a.pixels[c]) - static_cast<int>(b.pixels[c])));
    }
    if (largest > threshold_levels) {
      out.pixels[p] = 255;
      out.pixels[p + 1] = 0;
      out.pixels[p + 2] = 0;
    } else {
      const int grey = (a.pixels[p] + a.pixels[p + 1] + a.pixels[p + 2]) / 9;
      out.pixels[p] = out.pixels[p + 1] = out.pixels[p + 2] = static_cast<std::uint8_t>(grey);
    }
  }
  return out;
}

}  // namespace cps::cli
