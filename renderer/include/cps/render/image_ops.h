#pragma once
// CPU operations on finished frames: side-by-side composition, text labels and legends.

#include "cps/render/renderer.h"

#include <glm/glm.hpp>

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cps::render {

/// The images side by side, left to right, all of the same height. Returns an image of width
/// sum(widths) x height. Throws std::invalid_argument if the list is empty or the heights differ.
Image side_by_side(const std::vector<Image>& images);

/// The images in a grid of `columns` per row, left to right then top to bottom, all of the same
/// size; the cells after the last image (when columns does not divide their number) are filled
/// with `fill` (RGB in [0, 1]). Returns (columns x width) by (rows x height), rows = ceil(n /
/// columns); with columns >= n, the images side by side. Throws std::invalid_argument if the
/// list is empty, the sizes differ or columns < 1.
Image grid(const std::vector<Image>& images, int columns, const glm::vec3& fill = glm::vec3(0.92f));

/// Draws `text` (ASCII; '\n' starts a new line) into `image` with its top-left corner at pixel
/// (x, y), in stb_easy_font's segment font scaled by `scale` (pixels per font unit, >= 1; the
/// font is about 7 units high), in `color` (RGB in [0, 1]) on a translucent white box so it stays
/// legible on any background. Pixels outside the image are skipped. Throws
/// std::invalid_argument if scale < 1.
void draw_label(Image& image, int x, int y, std::string_view text, int scale,
                const glm::vec3& color = glm::vec3(0.05f));

/// `text` with its lines broken at spaces so that none is wider than max_width pixels in
/// draw_label's font at `scale` (>= 1); a word wider than that stays whole on its own line, and
/// the line breaks already in `text` stay.
std::string wrap_text(std::string_view text, int max_width, int scale);

/// One entry of a legend: a colour swatch (sRGB as shown, each in [0, 1]) and its text (ASCII,
/// one line).
struct LegendEntry {
  glm::vec3 color{0.0f};
  std::string text;
};

/// Width and height in pixels of the legend draw_legend draws for these arguments, padding
/// included: a heading line (none if empty), then one line per entry.
std::pair<int, int> legend_size(std::string_view heading, const std::vector<LegendEntry>& entries,
                                int scale);

/// Draws a legend into `image` with its top-left corner (padding included) at pixel (x, y): on
/// one translucent white box, the heading (if not empty), then per entry a square swatch of its
/// colour with a dark outline, about one text line high, and its text, in the font of draw_label
/// at `scale` (pixels per font unit, >= 1). Pixels outside the image are skipped. Throws
/// std::invalid_argument if scale < 1.
void draw_legend(Image& image, int x, int y, std::string_view heading,
                 const std::vector<LegendEntry>& entries, int scale);

}  // namespace cps::render
