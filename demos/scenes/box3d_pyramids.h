#pragma once
// Box3D's pyramid benchmark scenes (box3d_pyramids.cpp): large_pyramid and many_pyramids, as
// Box3D's benchmark builds them, with Box3D's world as their own defaults. Listed apart from the
// paper's and the stress scenes ("cps list"); found by name (find_scene).

#include "scene.h"

#include <span>

namespace cps::scenes {

/// Box3D's benchmark scenes, in the order `cps list` prints them.
std::span<const Scene> benchmark_scenes();

/// The highest point (m, world y) of any movable body now: a box's highest corner, a sphere's
/// top; -infinity in a world without movable bodies. No errors.
double highest_point(const World& world);

}  // namespace cps::scenes
