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

namespace {

// Width and height of `text` in font units.
std::pair<int, int> text_size(std::string_view text) {
  std::string buffer(text);
  return {stb_easy_font_width(buffer.data()), stb_easy_font_height(buffer.data())};
}

// The glyphs of `text` only, top-left corner at (x, y).
void draw_text(Image& image, int x, int y, std::string_view text, int scale, const glm::vec3& color) {
  std::string buffer(text);
  // stb_easy_font emits 4 vertices per quad, 16 bytes each: x, y, z as float and 4 colour bytes.
  std::vector<char> vertices(64 * (buffer.size() + 1) * 16);
  const int quads = stb_easy_font_print(0.0f, 0.0f, buffer.data(), nullptr, vertices.data(),
                                        static_cast<int>(vertices.size()));
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

// Font units a legend line takes (stb_easy_font's line pitch), and the swatch's side.
constexpr int kLine = 12;
constexpr int kSwatch = 8;
constexpr int kSwatchGap = 4;

}  // namespace

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

void draw_label(Image& image, int x, int y, std::string_view text, int scale,
                const glm::vec3& color) {
  if (scale < 1) throw std::invalid_argument("draw_label: scale " + std::to_string(scale) + " must be >= 1");
  const auto [width, height] = text_size(text);
  const std::uint8_t white[3] = {255, 255, 255};
  const int pad = 2 * scale;
  fill_rect(image, x - pad, y - pad, x + width * scale + pad, y + height * scale + pad, white, 0.75f);
  draw_text(image, x, y, text, scale, color);
}

std::string wrap_text(std::string_view text, int max_width, int scale) {
  std::string out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    std::string line;
    std::size_t word = start;
    while (word < end) {
      std::size_t space = text.find(' ', word);
      if (space == std::string_view::npos || space > end) space = end;
      const std::string_view w = text.substr(word, space - word);
      const std::string longer = line.empty() ? std::string(w) : line + " " + std::string(w);
      if (!line.empty() && text_size(longer).first * scale > max_width) {
        out += line + "\n";
        line = std::string(w);
      } else {
        line = longer;
      }
      word = space + 1;
    }
    out += line;
    if (end == text.size()) break;
    out += "\n";
    start = end + 1;
  }
  return out;
}

std::pair<int, int> legend_size(std::string_view heading, const std::vector<LegendEntry>& entries,
                                int scale) {
  int width = heading.empty() ? 0 : text_size(heading).first;
  for (const LegendEntry& e : entries) {
    width = std::max(width, kSwatch + kSwatchGap + text_size(e.text).first);
  }
  const int lines = static_cast<int>(entries.size()) + (heading.empty() ? 0 : 1);
  return {(width + 4) * scale, (lines * kLine + 2) * scale};
}

void draw_legend(Image& image, int x, int y, std::string_view heading,
                 const std::vector<LegendEntry>& entries, int scale) {
  if (scale < 1) throw std::invalid_argument("draw_legend: scale " + std::to_string(scale) + " must be >= 1");
  const auto [width, height] = legend_size(heading, entries, scale);
  const std::uint8_t white[3] = {255, 255, 255};
  fill_rect(image, x, y, x + width, y + height, white, 0.75f);
  const glm::vec3 ink(0.05f);
  const std::uint8_t dark[3] = {40, 40, 40};
  int row = y + 2 * scale;
  const int left = x + 2 * scale;
  if (!heading.empty()) {
    draw_text(image, left, row, heading, scale, ink);
    row += kLine * scale;
  }
  for (const LegendEntry& e : entries) {
    const std::uint8_t c[3] = {
        static_cast<std::uint8_t>(std::lround(std::clamp(e.color.r, 0.0f, 1.0f) * 255.0f)),
        static_cast<std::uint8_t>(std::lround(std::clamp(e.color.g, 0.0f, 1.0f) * 255.0f)),
        static_cast<std::uint8_t>(std::lround(std::clamp(e.color.b, 0.0f, 1.0f) * 255.0f))};
    // The swatch spans the glyphs' height (rows -1 .. 8 of the font), outlined in dark grey.
    const int s0 = row - scale;
    fill_rect(image, left, s0, left + kSwatch * scale, s0 + kSwatch * scale, dark, 1.0f);
    fill_rect(image, left + scale, s0 + scale, left + (kSwatch - 1) * scale,
              s0 + (kSwatch - 1) * scale, c, 1.0f);
    draw_text(image, left + (kSwatch + kSwatchGap) * scale, row, e.text, scale, ink);
    row += kLine * scale;
  }
}

}  // namespace cps::render
