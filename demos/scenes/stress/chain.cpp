// chain_20: 20 balls linked centre to centre by 20 distance constraints (paper Sec. 5.2), the
// first to a fixed point, released horizontally so the chain swings down like a whip. PGS passes
// a correction along the chain one link per sweep, so a long chain at 25 sweeps stretches.
#include "stress/stress.h"

#include <algorithm>
#include <cmath>

namespace cps::scenes {
namespace {

constexpr int kLinks = 20;
constexpr double kRadius = 0.1;     // m
constexpr double kMass = 0.5;       // kg
constexpr double kLinkLength = 0.3; // m, centre to centre (and fixed point to the first centre)
const Vec3 kFixedPoint(0.0, 8.0, 0.0);  // m

class ChainMetrics final : public Metrics {
 public:
  void observe(const World& world) override {
    energy_.observe(world);
    if (energy_.nonfinite()) return;
    for (const DistanceConstraint& d : world.distances()) {
      Vec3 p_a;
      Vec3 p_b;
      distance_endpoints(d, world.bodies(), p_a, p_b);
      const double error = std::abs((p_b - p_a).norm() - d.length);
      max_stretch_ = std::max(max_stretch_, error);
      max_stretch_rel_ = std::max(max_stretch_rel_, error / d.length);
    }
  }

  nlohmann::json report() const override {
    nlohmann::json j = nlohmann::json::object();
    energy_.add_to(j);
    j["max_stretch_rel"] = max_stretch_rel_;
    j["max_stretch_m"] = max_stretch_;
    return j;
  }

 private:
  EnergyTracker energy_;
  double max_stretch_ = 0.0;
  double max_stretch_rel_ = 0.0;
};

}  // namespace

WorldDef chain_world_def() {
  WorldDef def = stack_world_def();
  def.collision = false;  // the balls never collide (and there is no ground)
  def.friction = 0.0;
  return def;
}

void populate_chain_20(World& world) {
  for (int i = 0; i < kLinks; ++i) {
    BodyDef ball;
    ball.shape = Shape::sphere(kRadius);
    ball.mass = kMass;
    ball.position = kFixedPoint + Vec3(kLinkLength * (i + 1), 0.0, 0.0);  // horizontal, at rest
    const int index = world.add_body(ball);
    DistanceConstraint link;
    link.body_a = index;
    link.local_a = Vec3::Zero();
    link.body_b = i == 0 ? kWorldBody : index - 1;
    link.local_b = i == 0 ? kFixedPoint : Vec3::Zero();
    link.length = kLinkLength;
    world.add_distance(link);
  }
}

std::unique_ptr<Metrics> make_chain_metrics(const World& world) { return observed<ChainMetrics>(world); }

}  // namespace cps::scenes
