#pragma once
// The AVBD authors' 3D demo scenes (avbd_demo.cpp): avbd_stack, avbd_stack_ratio, avbd_pyramid,
// avbd_rope, avbd_heavy_rope, avbd_dynamic_friction and avbd_static_friction, with the demo's
// geometry and its solver settings as their own defaults. Listed apart ("cps list"); found by
// name (find_scene).

#include "scene.h"

#include <span>

namespace cps::scenes {

/// The AVBD demo's scenes, in the order `cps list` prints them.
std::span<const Scene> avbd_demo_scenes();

}  // namespace cps::scenes
