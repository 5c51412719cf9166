// Mass ratio stress scenes: a cube of ratio x 1 kg resting on a cube of 1 kg on the ground.
#include "stress/mass_ratio.h"

#include "stress/stress.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace cps::scenes {
namespace {

constexpr double kHoldOffset = 0.1;  // m: the heavy cube may wander this far off the light one
constexpr double kSettleSeconds = 5.0;
constexpr double kPenetrationGoal = 0.01;  // m: iterations_needed's goal
constexpr int kMaxIterations = 256;

class MassRatioMetrics final : public Metrics {
 public:
  void observe(const World& world) override {
    world_ = &world;
    max_penetration_ = std::max(max_penetration_, deepest_contact(world));
  }

  nlohmann::json report() const override {
    const bool finite = world_ && all_finite(*world_);
    return {{"max_penetration_m", max_penetration_},
            {"final_penetration_m", finite ? nlohmann::json(max_penetration_now(*world_)) : nlohmann::json()},
            {"holds", finite && mass_ratio_holds(*world_)},
            {"top_height_m", world_ ? world_->body(2).x.y() : 0.0}};
  }

 private:
  const World* world_ = nullptr;
  double max_penetration_ = 0.0;
};

void check_mass_ratio(double ratio) {
  if (!(std::isfinite(ratio) && ratio > 0.0)) {
    std::ostringstream s;
    s << "mass ratio " << ratio << " must be finite and > 0";
    throw std::invalid_argument(s.str());
  }
}

}  // namespace

WorldDef mass_ratio_world_def() { return stack_world_def(); }

void populate_mass_ratio(World& world, double ratio) {
  check_mass_ratio(ratio);
  add_ground(world);
  BodyDef cube;
  cube.shape = Shape::box(Vec3::Constant(kMassRatioHalfEdge));
  cube.mass = kMassRatioLightMass;
  cube.position = Vec3(0.0, kMassRatioHalfEdge, 0.0);
  world.add_body(cube);
  cube.mass = ratio * kMassRatioLightMass;
  cube.position = Vec3(0.0, 3.0 * kMassRatioHalfEdge, 0.0);
  world.add_body(cube);
}

void populate_mass_ratio_stack(World& world, double ratio, int boxes) {
  if (boxes < 2) {
    throw std::invalid_argument("a mass ratio stack needs at least 2 boxes, not " + std::to_string(boxes));
  }
  check_mass_ratio(ratio);
  add_ground(world);
  BodyDef cube;
  cube.shape = Shape::box(Vec3::Constant(kMassRatioHalfEdge));
  for (int k = 0; k < boxes; ++k) {
    cube.mass = std::pow(ratio, static_cast<double>(k) / (boxes - 1)) * kMassRatioLightMass;
    cube.position = Vec3(0.0, (2 * k + 1) * kMassRatioHalfEdge, 0.0);
    world.add_body(cube);
  }
}

void populate_mass_ratio_10(World& world) { populate_mass_ratio(world, 10.0); }
void populate_mass_ratio_100(World& world) { populate_mass_ratio(world, 100.0); }
void populate_mass_ratio_1000(World& world) { populate_mass_ratio(world, 1000.0); }

std::unique_ptr<Metrics> make_mass_ratio_metrics(const World& world) {
  return observed<MassRatioMetrics>(world);
}

bool mass_ratio_holds(const World& world) {
  const Vec3& light = world.body(1).x;
  const Vec3& heavy = world.body(2).x;
  return heavy.y() > light.y() && std::hypot(heavy.x() - light.x(), heavy.z() - light.z()) <= kHoldOffset &&
         max_penetration_now(world) < 0.5 * kMassRatioHalfEdge;
}

MassRatioOutcome run_mass_ratio(double ratio, int iterations, double seconds) {
  WorldDef def = mass_ratio_world_def();
  def.iterations = iterations;
  World world(def);
  populate_mass_ratio(world, ratio);
  MassRatioOutcome out;
  while (short_of(world, seconds)) {
    world.step();
    if (!all_finite(world)) return out;  // holds = false
    out.max_penetration_m = std::max(out.max_penetration_m, deepest_contact(world));
  }
  out.final_penetration_m = max_penetration_now(world);
  out.holds = mass_ratio_holds(world);
  out.top_height_m = world.body(2).x.y();
  return out;
}

int iterations_needed(double ratio) {
  for (int n = 1; n <= kMaxIterations; n *= 2) {
    const MassRatioOutcome o = run_mass_ratio(ratio, n, kSettleSeconds);
    if (o.holds && o.final_penetration_m < kPenetrationGoal) return n;
  }
  return -1;
}

}  // namespace cps::scenes
