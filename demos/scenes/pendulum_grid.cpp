// The pendulum grid, paper Sec. 10.3: 5 x 5 balls, each hung from its own fixed point by a
// distance constraint (a bar), not tied to each other, holding other shapes on top: four boxes
// and a ball. Enough force on a shape on top pushes the pendulums aside and it falls through.
#include "scene.h"

#include <algorithm>
#include <cmath>

namespace cps::scenes {
namespace {

constexpr double kRadius = 0.5;     // m, grid balls and the ball on top
constexpr double kRodLength = 3.0;  // m
constexpr double kBoxHalf = 0.8;    // m (edge 1.6 m)
constexpr double kGridHalf = 2.5;   // m: the grid's footprint is |x|, |z| <= 2.5

class PendulumGridMetrics final : public Metrics {
 public:
  explicit PendulumGridMetrics(int grid_balls) : grid_balls_(grid_balls) {}

  void observe(const World& world) override {
    world_ = &world;
    max_rod_error_ = std::max(max_rod_error_, max_rod_error(world));
    max_penetration_ = std::max(max_penetration_, deepest_contact(world));
  }

  nlohmann::json report() const override {
    int on_top = 0;
    if (world_) {
      const auto& bodies = world_->bodies();
      // Bodies 1..grid_balls are the grid (0 is the ground); the rest are the shapes on top.
      double mean_y = 0.0;
      for (int i = 1; i <= grid_balls_; ++i) mean_y += bodies[static_cast<std::size_t>(i)].x.y();
      mean_y /= grid_balls_;
      for (std::size_t i = static_cast<std::size_t>(grid_balls_) + 1; i < bodies.size(); ++i) {
        const Vec3& x = bodies[i].x;
        if (x.y() > mean_y && std::abs(x.x()) <= kGridHalf && std::abs(x.z()) <= kGridHalf) ++on_top;
      }
    }
    return {{"max_rod_error_m", max_rod_error_},
            {"shapes_on_top", on_top},
            {"max_penetration_m", max_penetration_}};
  }

 private:
  int grid_balls_;
  const World* world_ = nullptr;
  double max_rod_error_ = 0.0;
  double max_penetration_ = 0.0;
};

}  // namespace

WorldDef pendulum_grid_world_def() { return stack_world_def(); }

void populate_pendulum_grid(World& world) {
  add_ground(world);
  for (int i = 0; i < 5; ++i) {
    for (int k = 0; k < 5; ++k) {
      BodyDef ball;
      ball.shape = Shape::sphere(kRadius);
      ball.mass = 1.0;
      ball.position = Vec3(i - 2.0, 5.0, k - 2.0);
      const int index = world.add_body(ball);
      DistanceConstraint rod;
      rod.body_a = index;
      rod.local_a = Vec3(0.0, kRadius, 0.0);  // the ball's top point
      rod.body_b = kWorldBody;
      rod.local_b = Vec3(i - 2.0, 5.0 + kRadius + kRodLength, k - 2.0);
      rod.length = kRodLength;
      world.add_distance(rod);
    }
  }
  for (const double x : {-1.5, 1.5}) {
    for (const double z : {-1.5, 1.5}) {
      BodyDef box;
      box.shape = Shape::box(Vec3::Constant(kBoxHalf));
      box.mass = 1.0;
      box.position = Vec3(x, 6.35, z);
      world.add_body(box);
    }
  }
  BodyDef ball;
  ball.shape = Shape::sphere(kRadius);
  ball.mass = 1.0;
  ball.position = Vec3(0.0, 6.6, 0.0);
  world.add_body(ball);
}

std::unique_ptr<Metrics> make_pendulum_grid_metrics(const World& world) {
  return observed<PendulumGridMetrics>(world, 25);
}

}  // namespace cps::scenes
