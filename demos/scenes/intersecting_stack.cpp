// The intersecting stack test, paper Sec. 10.2: the stack's cubes with centres 2 m apart
// (0.4 m overlaps), the bottom one 1.2 m into the ground. With the push factor kept in the
// velocity (baumgarte) the cubes fly apart; with the single frame push factor (split) they come
// to rest (the paper's Fig. 7 b and c, at 0.5 s).
#include "scene.h"
#include "stress/stress.h"

#include <algorithm>
#include <optional>

namespace cps::scenes {
namespace {

// m: half the cubes' 2.4 m edge, the hard cases' leave distance (stress.h, HardCaseWatch): a cube
// that moved sideways by half the edge of the one under it has its centre over that edge.
constexpr double kLeaveM = 1.2;

// When the stack has recovered: the first time from which, for kRecoveredHoldS, every contact the
// steps find is at most kRecoveredOverlapM deep and every movable body is slower than
// kRecoveredSpeedMps. A hold window, not "to the end of the run", so that the time does not move
// with the run's length (a run shorter than the window after it cannot show a recovery).
// 1 cm is under 0.5 % of a cube's 2.4 m edge; 0.1 m/s is under the 0.17 m/s that gravity adds
// in one 1/60 s step, so a body that stays under it is held, neither falling nor thrown (the
// bounds of the scene's test of the paper's Fig. 7 c, tests/physics/test_scenes.cpp).
constexpr double kRecoveredOverlapM = 0.01;
constexpr double kRecoveredSpeedMps = 0.1;
constexpr double kRecoveredHoldS = 0.5;

// The heights and speeds at the end, the recovery time, and the hard cases' measures with the
// column resting on the ground as the resting places (the cubes start away from them, so
// arrival_s is when the push has brought them there).
class IntersectingStackMetrics final : public Metrics {
 public:
  explicit IntersectingStackMetrics(const World& world)
      : watch_(resting_places_stacked(world), kLeaveM) {}

  void observe(const World& world) override {
    world_ = &world;
    watch_.observe(world);
    if (world.time() <= 0.0) return;  // as built: no step has looked for the overlaps yet
    double speed = 0.0;
    for (const Body& b : world.bodies()) {
      if (!b.is_static()) speed = std::max(speed, b.velocity().norm());
    }
    last_overlap_ = deepest_contact(world);
    const bool at_rest = last_overlap_ <= kRecoveredOverlapM && speed <= kRecoveredSpeedMps;
    if (!at_rest) {
      rest_since_.reset();
    } else if (!rest_since_) {
      rest_since_ = world.time();
    }
    if (!recovered_at_ && rest_since_ &&
        world.time() - *rest_since_ + 0.5 * world.def().dt >= kRecoveredHoldS) {
      recovered_at_ = rest_since_;
    }
  }

  void diverged_since(double since_s) override {
    watch_.diverged_since(since_s);
    if (recovered_at_ && *recovered_at_ >= since_s) recovered_at_.reset();
  }

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
    nlohmann::json j = {{"heights_m", heights},
                        {"speeds_mps", speeds},
                        {"max_speed_mps", max_speed},
                        {"overlap_end_m", last_overlap_},
                        {"recovered", recovered_at_.has_value()},
                        {"at_rest_end", rest_since_.has_value()},
                        {"recovery_time_s", recovered_at_ ? nlohmann::json(*recovered_at_) : nlohmann::json()}};
    watch_.add_to(j);
    return j;
  }

 private:
  const World* world_ = nullptr;
  HardCaseWatch watch_;
  double last_overlap_ = 0.0;           // m, the deepest contact of the last step
  std::optional<double> rest_since_;    // s, the start of the current time at rest
  std::optional<double> recovered_at_;  // s, the start of the first kRecoveredHoldS at rest
};

}  // namespace

WorldDef intersecting_stack_world_def() {
  WorldDef def = stack_world_def();  // same cubes and settings as Sec. 10.1
  return def;
}

// Centres 2 m apart (0.4 m overlaps), the bottom one at the ground (1.2 m into it).
void populate_intersecting_stack(World& world) { add_ground_and_cube_column(world, 0.0, 2.0, 5); }

std::unique_ptr<Metrics> make_intersecting_stack_metrics(const World& world) {
  return observed<IntersectingStackMetrics>(world, world);
}

}  // namespace cps::scenes
