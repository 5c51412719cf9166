// scale_0.01 and scale_100: the stack (paper Sec. 10.1) with every length times s and every mass
// times s^3 (same density), g unchanged. With g fixed, time scales as sqrt(s) (a fall of height
// s h takes sqrt(s) times as long), so the step is dt = (1/60 s) sqrt(s). Under
// x -> s x, t -> sqrt(s) t, m -> s^3 m: v -> sqrt(s) v, forces (m g, lambda) -> s^3, the push
// target beta d / dt -> sqrt(s) (a velocity), the friction limit mu m g -> s^3 (a force), the
// inertia m L^2 -> s^5: every equation of Secs. 3 to 7 maps onto itself, step for step. The engine
// has no absolute length or speed that matters here: the box-box test's tolerances are relative
// to the half extents (collision_box_box.cpp), the contact margin is 0, and the only absolute
// thresholds (1e-12 m for coincident centres, restitution below 1 m/s) do not act in the stack.
// So x(t) / s must follow the unscaled stack up to rounding: exactly for s = 4^k (every scaled
// input, and so every operation, is the unscaled one times a power of 2), and for other s until a
// contact decision (made only on overlap, depth > 0) falls the other way in one run. The metrics
// run that unscaled stack alongside, step for step (position error in units of its 2.4 m edge),
// and report the first step whose contact count differs.
#include "stress/stress.h"

#include <algorithm>
#include <cmath>

namespace cps::scenes {
namespace {

constexpr double kReferenceEdge = 2.4;  // m: the unscaled cube edge, the unit of the error

WorldDef unscaled(WorldDef def, double s) {
  def.dt /= std::sqrt(s);
  return def;
}

class ScaleMetrics final : public Metrics {
 public:
  // The reference runs with the scaled world's own parameters (so overrides such as
  // --iterations apply to both), its step divided by sqrt(s).
  ScaleMetrics(const WorldDef& scaled, double s) : s_(s), reference_(unscaled(scaled, s)) {
    populate_stack(reference_);
  }

  void observe(const World& world) override {
    while (reference_.counters().steps < world.counters().steps) reference_.step();
    if (!all_finite(world)) {
      nonfinite_ = true;
      return;
    }
    double position = 0.0;
    double angle = 0.0;
    const auto& bodies = world.bodies();
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (bodies[i].is_static()) continue;
      const Body& ref = reference_.bodies()[i];
      position = std::max(position, (bodies[i].x / s_ - ref.x).norm() / kReferenceEdge);
      angle = std::max(angle, bodies[i].o.angularDistance(ref.o));
    }
    // Contact is made only on overlap, a discontinuity: once rounding puts a corner on the other
    // side of depth 0 in one run, the two runs take different contact sets from that step on.
    if (!first_difference_ && world.counters().contacts != reference_.counters().contacts) {
      first_difference_ = world.counters().steps;
    }
    if (!first_difference_) max_position_error_before_ = std::max(max_position_error_before_, position);
    max_position_error_ = std::max(max_position_error_, position);
    max_angle_error_ = std::max(max_angle_error_, angle);
    final_position_error_ = position;
    top_height_ = bodies.back().x.y();
  }

  nlohmann::json report() const override {
    return {{"scale", s_},
            {"max_position_error_rel", max_position_error_},
            {"final_position_error_rel", final_position_error_},
            {"max_orientation_error_rad", max_angle_error_},
            {"first_contact_difference_step",
             first_difference_ ? nlohmann::json(*first_difference_) : nlohmann::json()},
            {"max_position_error_before_difference_rel", max_position_error_before_},
            {"top_height_m", top_height_},
            {"nan", nonfinite_}};
  }

 private:
  double s_;
  World reference_;
  double max_position_error_ = 0.0;
  double max_position_error_before_ = 0.0;
  std::optional<std::int64_t> first_difference_;  // the step whose contacts differ first
  double final_position_error_ = 0.0;
  double max_angle_error_ = 0.0;
  double top_height_ = 0.0;
  bool nonfinite_ = false;
};

}  // namespace

WorldDef scaled_stack_world_def(double s) {
  WorldDef def = stack_world_def();
  def.dt *= std::sqrt(s);
  return def;
}

void populate_scaled_stack(World& world, double s) {
  add_ground(world);
  // populate_stack's layout: edge 2.4 m, 1.2 kg, centres (0, 2 + 3 i, 0) m.
  for (int i = 0; i < 5; ++i) {
    BodyDef cube;
    cube.shape = Shape::box(Vec3::Constant(1.2 * s));
    cube.mass = 1.2 * s * s * s;
    cube.position = Vec3(0.0, (2.0 + 3.0 * i) * s, 0.0);
    world.add_body(cube);
  }
}

WorldDef scale_001_world_def() { return scaled_stack_world_def(0.01); }
WorldDef scale_100_world_def() { return scaled_stack_world_def(100.0); }
void populate_scale_001(World& world) { populate_scaled_stack(world, 0.01); }
void populate_scale_100(World& world) { populate_scaled_stack(world, 100.0); }
std::unique_ptr<Metrics> make_scale_001_metrics(const World& world) {
  return observed<ScaleMetrics>(world, world.def(), 0.01);
}
std::unique_ptr<Metrics> make_scale_100_metrics(const World& world) {
  return observed<ScaleMetrics>(world, world.def(), 100.0);
}

}  // namespace cps::scenes
