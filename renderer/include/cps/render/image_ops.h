#pragma once
// CPU operations on finished frames: side-by-side composition and text labels.

#include "cps/render/renderer.h"

#include <glm/glm.hpp>

#include <string_view>
#include <vector>

namespace cps::render {

/// The images side by side, left to right, all of the same height. Returns an image of width
/// sum(widths) x height. Throws std::invalid_argument if the list is empty or the heights differ.
Image side_by_side(const std::vector<Image>& images);

/// Draws `text` (ASCII; '\n' starts a new line) into `image` with its top-left corner at pixel
/// (x, y), in stb_easy_font's segment font scaled by `scale` (pixels per font unit, >= 1; the
/// font is about 7 units high), in `color` (RGB in [0, 1]) on a translucent white box so it stays
/// legible on any background. Pixels outside the image are skipped. Throws
/// std::invalid_argument if scale < 1.
void draw_label(Image& image, int x, int y, std::string_view text, int scale,
                const glm::vec3& color = glm::vec3(0.05f));

}  // namespace cps::render
