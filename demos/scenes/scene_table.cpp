#include "scene.h"

#include <algorithm>
#include <array>

namespace cps::scenes {
namespace {

const std::array kScenes = {
    Scene{"stack", "5 cubes of 2.4 m and 1.2 kg dropped in a column onto the ground (Sec. 10.1)",
          10.0, &stack_world_def, &populate_stack, &make_stack_metrics},
};

}  // namespace

std::span<const Scene> all_scenes() { return kScenes; }

const Scene* find_scene(std::string_view name) {
  const auto it = std::find_if(kScenes.begin(), kScenes.end(),
                               [name](const Scene& s) { return s.name == name; });
  return it == kScenes.end() ? nullptr : &*it;
}

WorldDef world_def_with(const Scene& scene, const Overrides& o) {
  WorldDef def = scene.world_def();
  if (o.dt) def.dt = *o.dt;
  if (o.iterations) def.iterations = *o.iterations;
  if (o.beta) def.beta = *o.beta;
  if (o.friction) def.friction = *o.friction;
  return def;
}

Run make_run(const Scene& scene, const Overrides& overrides) {
  Run run{World(world_def_with(scene, overrides)), nullptr};
  scene.populate(run.world);
  run.metrics = scene.make_metrics(run.world);
  return run;
}

double deepest_contact(const World& world) {
  double deepest = 0.0;
  for (const Manifold& m : world.manifolds()) {
    for (int i = 0; i < m.count; ++i) {
      deepest = std::max(deepest, m.contacts[static_cast<std::size_t>(i)].depth);
    }
  }
  return deepest;
}

}  // namespace cps::scenes
