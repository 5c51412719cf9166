#pragma once
// CPU operations on finished frames: grid composition. No text is drawn here: the cps command
// writes its labels in caption strips outside the scene, with cairo.

#include "cps/render/renderer.h"

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace cps::render {

/// The images in a grid of `columns` per row, left to right then top to bottom, all of the same
/// size; the cells after the last image (when columns does not divide their number) are filled
/// with `fill` (RGB in [0, 1]). Returns (columns x width) by (rows x height), rows = ceil(n /
/// columns); with columns >= n, the images side by side. Throws std::invalid_argument if the
/// list is empty, the sizes differ or columns < 1.
Image grid(const std::vector<Image>& images, int columns, const glm::vec3& fill = glm::vec3(0.92f));

}  // namespace cps::render
