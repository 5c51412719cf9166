// The stack test, paper Sec. 10.1: five cubes of edge 2.4 m and mass 1.2 kg, centres 3 m apart
// (0.6 m gaps), the bottom centre 2 m above the ground; g = -10 m/s^2, 60 Hz, 25 iterations,
// beta = 0.2, no contact caching. The paper reports that the stack topples after about 85 s.
#include "scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cps::scenes {
namespace {

constexpr int kCubes = 5;
constexpr double kHalfEdge = 1.2;   // m
constexpr double kMass = 1.2;       // kg
// A cube counts as toppled once its centre leaves this radius around the column's axis (m) ...
constexpr double kToppleDrift = 0.5;
// ... or it tilts further than this (degrees).
constexpr double kToppleTilt = 10.0;

// Angle (degrees) between world up and the cube axis closest to it.
double tilt_deg(const Body& b) {
  const Mat3 R = b.rotation();
  const double up = std::max({std::abs(R(1, 0)), std::abs(R(1, 1)), std::abs(R(1, 2))});
  return std::acos(std::min(1.0, up)) * 180.0 / std::numbers::pi;
}

class StackMetrics final : public Metrics {
 public:
  void observe(const World& world) override {
    for (const Body& b : world.bodies()) {
      if (b.is_static()) continue;
      const double drift = std::hypot(b.x.x(), b.x.z());
      const double tilt = tilt_deg(b);
      max_drift_ = std::max(max_drift_, drift);
      max_tilt_ = std::max(max_tilt_, tilt);
      if (!topple_time_ && (drift > kToppleDrift || tilt > kToppleTilt)) topple_time_ = world.time();
    }
    max_penetration_ = std::max(max_penetration_, deepest_contact(world));
  }

  nlohmann::json report() const override {
    return {{"topple_time_s", topple_time_ ? nlohmann::json(*topple_time_) : nlohmann::json()},
            {"max_drift_m", max_drift_},
            {"max_tilt_deg", max_tilt_},
            {"max_penetration_m", max_penetration_}};
  }

 private:
  std::optional<double> topple_time_;
  double max_drift_ = 0.0;
  double max_tilt_ = 0.0;
  double max_penetration_ = 0.0;
};

}  // namespace

WorldDef stack_world_def() {
  WorldDef def;
  def.gravity = Vec3(0.0, -10.0, 0.0);
  def.dt = 1.0 / 60.0;
  def.iterations = 25;
  def.beta = 0.2;
  def.friction = 0.5;  // the paper gives none
  return def;
}

void add_ground_and_cube_column(World& world, double bottom, double spacing, int count) {
  add_ground(world);
  for (int i = 0; i < count; ++i) {
    BodyDef cube;
    cube.shape = Shape::box(Vec3::Constant(kHalfEdge));
    cube.mass = kMass;
    cube.position = Vec3(0.0, bottom + spacing * i, 0.0);
    world.add_body(cube);
  }
}

// Centres 3 m apart (0.6 m gaps), the bottom one 2 m up: the cubes fall and settle.
void populate_stack(World& world) { add_ground_and_cube_column(world, 2.0, 3.0, kCubes); }

std::unique_ptr<Metrics> make_stack_metrics(const World& world) { return observed<StackMetrics>(world); }

}  // namespace cps::scenes
