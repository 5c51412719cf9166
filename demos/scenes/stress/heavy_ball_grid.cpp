// heavy_ball_grid: the pendulum grid (paper Sec. 10.3) hit by a 50 kg ball. The paper says
// enough force on a shape on top pushes the pendulums aside and it falls through; this scene
// checks that it does, without NaN and without energy from nowhere.
#include "stress/stress.h"

#include <algorithm>
#include <cmath>

namespace cps::scenes {
namespace {

constexpr int kGridBalls = 25;        // bodies 1..25 of populate_pendulum_grid
constexpr double kBallRadius = 0.5;   // m
constexpr double kBallMass = 50.0;    // kg
// Dropped between the two boxes at z = +1.5 m (they span |x| >= 0.7 m), over the gap between
// the grid balls at (0, 1) and (0, 2) m, clear of the ball on top at (0, 0): it lands on two
// pendulums and has to push them apart.
const Vec3 kDropPoint(0.0, 8.0, 1.5);  // m

double mean_grid_height(const World& world) {
  double y = 0.0;
  for (int i = 1; i <= kGridBalls; ++i) y += world.body(i).x.y();
  return y / kGridBalls;
}

class HeavyBallGridMetrics final : public Metrics {
 public:
  void observe(const World& world) override {
    world_ = &world;
    energy_.observe(world);
    if (energy_.nonfinite()) return;
    max_rod_error_ = std::max(max_rod_error_, max_rod_error(world));
    max_penetration_ = std::max(max_penetration_, deepest_contact(world));
    if (!fall_time_ && fell_through(world)) fall_time_ = world.time();
  }

  nlohmann::json report() const override {
    nlohmann::json j = nlohmann::json::object();
    energy_.add_to(j);
    j["ball_height_m"] = world_ ? world_->bodies().back().x.y() : 0.0;
    j["fell_through"] = world_ && !energy_.nonfinite() && fell_through(*world_);
    j["fall_through_time_s"] = fall_time_ ? nlohmann::json(*fall_time_) : nlohmann::json();
    j["max_rod_error_m"] = max_rod_error_;
    j["max_penetration_m"] = max_penetration_;
    return j;
  }

 private:
  // The heavy ball's centre is below the mean height of the grid balls' centres.
  static bool fell_through(const World& world) {
    return world.bodies().back().x.y() < mean_grid_height(world);
  }

  const World* world_ = nullptr;
  EnergyTracker energy_;
  double max_rod_error_ = 0.0;
  double max_penetration_ = 0.0;
  std::optional<double> fall_time_;
};

}  // namespace

void populate_heavy_ball_grid(World& world) {
  populate_pendulum_grid(world);
  BodyDef ball;
  ball.shape = Shape::sphere(kBallRadius);
  ball.mass = kBallMass;
  ball.position = kDropPoint;
  world.add_body(ball);  // the last body
}

std::unique_ptr<Metrics> make_heavy_ball_grid_metrics(const World& world) {
  return observed<HeavyBallGridMetrics>(world);
}

}  // namespace cps::scenes
