// The funnel, paper Sec. 10.3: 20 balls in an upside-down square pyramid made of 4 static
// infinite planes through the origin (the free side is y > |x| and y > |z|). The paper reports it
// becomes reasonably stable without contact caching. No ground: it would only touch the apex.
#include "scene.h"

#include <algorithm>
#include <cmath>

namespace cps::scenes {
namespace {

constexpr double kRadius = 0.5;  // m
constexpr double kMass = 1.0;    // kg

// kinetic_energy_J and final_penetration_m at the end; max_penetration_m, the deepest contact of
// any step (m), as in every scene.
class FunnelMetrics final : public Metrics {
 public:
  void observe(const World& world) override {
    world_ = &world;
    max_penetration_ = std::max(max_penetration_, deepest_contact(world));
  }
  nlohmann::json report() const override {
    return {{"kinetic_energy_J", world_ ? kinetic_energy(*world_) : 0.0},
            {"max_penetration_m", max_penetration_},
            {"final_penetration_m", world_ ? max_penetration_now(*world_) : 0.0}};
  }

 private:
  const World* world_ = nullptr;
  double max_penetration_ = 0.0;  // m
};

}  // namespace

WorldDef funnel_world_def() {
  WorldDef def = stack_world_def();  // g, dt, 25 iterations, beta 0.2, mu 0.5
  // Speculative contacts 1 mm out. With contacts made only on overlap (margin 0, the paper's
  // rule) a ball in the pile that the push factor has just lifted clear loses its contact, falls
  // g dt^2 = 2.8 mm back in and is pushed out again: 44 to 52 of the ~50 contacts come and go
  // from step to step, and the pile keeps 1e-3 to 7e-3 J of kinetic energy. A 1 mm margin keeps
  // every resting contact in the system and the pile comes to rest (about 5e-6 J at 10 s).
  def.contact_margin = 0.001;
  return def;
}

void add_funnel_walls(World& world) {
  const double s = 1.0 / std::sqrt(2.0);
  for (const Vec3& n : {Vec3(s, s, 0.0), Vec3(-s, s, 0.0), Vec3(0.0, s, s), Vec3(0.0, s, -s)}) {
    BodyDef wall;
    wall.shape = Shape::plane(n, 0.0);
    wall.is_static = true;
    world.add_body(wall);
  }
}

void populate_funnel(World& world) {
  add_funnel_walls(world);
  for (int i = 0; i < 5; ++i) {
    for (int k = 0; k < 4; ++k) {
      BodyDef ball;
      ball.shape = Shape::sphere(kRadius);
      ball.mass = kMass;
      ball.position = Vec3(-2.4 + 1.2 * i, 8.0, -1.8 + 1.2 * k);
      world.add_body(ball);
    }
  }
}

std::unique_ptr<Metrics> make_funnel_metrics(const World& world) {
  return observed<FunnelMetrics>(world);
}

}  // namespace cps::scenes
