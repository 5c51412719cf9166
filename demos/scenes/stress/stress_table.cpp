// The stress scenes: stiff and extreme cases, listed apart from the paper's scenes.
#include "scene.h"

namespace cps::scenes {

std::span<const Scene> stress_scenes() { return {}; }

}  // namespace cps::scenes
