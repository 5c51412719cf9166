// The intersecting stack test, paper Sec. 10.2: the stack's cubes with centres 2 m apart
// (0.4 m overlaps), the bottom one 1.2 m into the ground. With the push factor kept in the
// velocity (baumgarte) the cubes fly apart; with the single frame push factor (split) they come
// to rest (the paper's Fig. 7 b and c, at 0.5 s).
#include "scene.h"

#include <algorithm>

namespace cps::scenes {
namespace {

constexpr int kCubes = 5;
constexpr double kHalfEdge = 1.2;  // m
constexpr double kMass = 1.2;      // kg

class IntersectingStackMetrics final : public Metrics {
 public:
  void observe(const World& world) override { world_ = &world; }

  nlohmann::json report() const override {
    nlohmann::json heights = nlohmann::json::array();
    nlohmann::json speeds = nlohmann::json::array();
    double max_speed = 0.0;
    if (world_) {
      for (const Body& b : world_->bodies()) {
        if (b.is_static()) continue;
        heights.push_back(b.x.y());
        speeds.push_back(b.velocity().norm());
        max_speed = std::max(max_speed, b.velocity().norm());
      }
    }
    return {{"heights_m", heights}, {"speeds_mps", speeds}, {"max_speed_mps", max_speed}};
  }

 private:
  const World* world_ = nullptr;
};

}  // namespace

WorldDef intersecting_stack_world_def() {
  WorldDef def = stack_world_def();  // same cubes and settings as Sec. 10.1
  return def;
}

void populate_intersecting_stack(World& world) {
  BodyDef ground;
  ground.shape = Shape::plane(Vec3::UnitY(), 0.0);
  ground.is_static = true;
  world.add_body(ground);
  for (int i = 0; i < kCubes; ++i) {
    BodyDef cube;
    cube.shape = Shape::box(Vec3::Constant(kHalfEdge));
    cube.mass = kMass;
    cube.position = Vec3(0.0, 2.0 * i, 0.0);
    world.add_body(cube);
  }
}

std::unique_ptr<Metrics> make_intersecting_stack_metrics(const World& world) {
  auto m = std::make_unique<IntersectingStackMetrics>();
  m->observe(world);
  return m;
}

}  // namespace cps::scenes
