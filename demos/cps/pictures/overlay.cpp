#include "pictures/overlay.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cps::cli {
namespace {

// The shader's colours are linear and its output is gamma encoded (1/2.2, lighting.glsl): a
// ghost lit at full strength shows about its overlay colour.
glm::vec3 linear_colour(std::size_t k) {
  const std::array<float, 3> c = overlay_colour(k);
  return {std::pow(c[0], 2.2f), std::pow(c[1], 2.2f), std::pow(c[2], 2.2f)};
}

}  // namespace

render::DrawList overlay_draw_list(const std::vector<const World*>& worlds, const DrawStyle& style) {
  if (worlds.empty() || worlds.size() > kMaxVariants) {
    throw std::invalid_argument("overlay_draw_list: " + std::to_string(worlds.size()) +
                                " worlds; 1 to " + std::to_string(kMaxVariants) + " are drawn");
  }
  render::DrawList list;
  for (std::size_t k = 0; k < worlds.size(); ++k) {
    DrawStyle ghost = style;
    ghost.body_colour = linear_colour(k);
    ghost.body_alpha = kGhostAlpha;
    render::DrawList one = draw_list(*worlds[k], ghost);
    if (k == 0) {
      list = std::move(one);
      continue;
    }
    list.boxes.insert(list.boxes.end(), one.boxes.begin(), one.boxes.end());
    list.spheres.insert(list.spheres.end(), one.spheres.begin(), one.spheres.end());
    list.lines.insert(list.lines.end(), one.lines.begin(), one.lines.end());
  }
  return list;
}

std::vector<PageLegendEntry> overlay_legend(const std::vector<Variant>& variants) {
  std::vector<PageLegendEntry> entries;
  for (std::size_t k = 0; k < variants.size(); ++k) entries.push_back({overlay_colour(k), variants[k].legend});
  return entries;
}

}  // namespace cps::cli
