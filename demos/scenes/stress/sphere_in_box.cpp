// sphere_in_box: a ball started with its centre inside a box resting on the ground, 0.3 m below
// the box's top face (0.7 m of overlap). The box-sphere test pushes it out through the top face.
// With the single frame push factor (Sec. 8.1, this scene's default) the overlap is resolved by
// moving positions only, so nothing should leave fast; with --push baumgarte the push velocity
// beta d / dt stays in the momenta and the ball is thrown up.
#include "stress/stress.h"

#include <algorithm>

namespace cps::scenes {
namespace {

constexpr double kBoxHalf = 1.0;       // m (edge 2 m)
constexpr double kBoxMass = 10.0;      // kg
constexpr double kSphereRadius = 0.4;  // m
constexpr double kSphereMass = 1.0;    // kg
constexpr double kDepthBelowTop = 0.3; // m: sphere centre below the box's top face

// m: the ball's radius, half the smaller body's size: the hard cases' leave distance (stress.h,
// HardCaseWatch).
constexpr double kLeaveM = kSphereRadius;

// The fastest speed, the overlap and the ball's height, and the hard cases' measures with the
// ball resting on the box's top face as its resting place (it starts 0.7 m below it, so
// arrival_s is when the push has brought it out).
class SphereInBoxMetrics final : public Metrics {
 public:
  explicit SphereInBoxMetrics(const World& world) : watch_(resting_places_stacked(world), kLeaveM) {}

  void observe(const World& world) override {
    world_ = &world;
    watch_.observe(world);
    if (!all_finite(world)) {
      nonfinite_ = true;
      return;
    }
    if (world.counters().steps == 0) return;  // the state as built is not a result
    for (const Body& b : world.bodies()) {
      if (!b.is_static()) max_speed_ = std::max(max_speed_, b.velocity().norm());
    }
  }
  void diverged_since(double since_s) override { watch_.diverged_since(since_s); }

  nlohmann::json report() const override {
    const bool ok = world_ && !nonfinite_;
    nlohmann::json j = {
        {"max_speed_mps", max_speed_},
        {"final_penetration_m", ok ? nlohmann::json(max_penetration_now(*world_)) : nlohmann::json()},
        {"sphere_height_m", ok ? world_->body(2).x.y() : 0.0}};
    watch_.add_to(j);  // max_penetration_m (the deepest contact of any step) and nan among them
    return j;
  }

 private:
  const World* world_ = nullptr;
  HardCaseWatch watch_;
  double max_speed_ = 0.0;
  bool nonfinite_ = false;
};

}  // namespace

WorldDef sphere_in_box_world_def() {
  WorldDef def = stack_world_def();
  def.push = PushMode::split;
  return def;
}

void populate_sphere_in_box(World& world) {
  add_ground(world);
  BodyDef box;
  box.shape = Shape::box(Vec3::Constant(kBoxHalf));
  box.mass = kBoxMass;
  box.position = Vec3(0.0, kBoxHalf, 0.0);  // resting on the ground
  world.add_body(box);
  BodyDef ball;
  ball.shape = Shape::sphere(kSphereRadius);
  ball.mass = kSphereMass;
  ball.position = Vec3(0.0, 2.0 * kBoxHalf - kDepthBelowTop, 0.0);
  world.add_body(ball);
}

std::unique_ptr<Metrics> make_sphere_in_box_metrics(const World& world) {
  return observed<SphereInBoxMetrics>(world, world);
}

}  // namespace cps::scenes
