// Scaled scenes for benchmarks: the paper's scenes grown to many bodies, made on demand from a
// family name and a size (stack_40, pyramid_1000, funnel_2000, pendulum_wave_10000,
// pendulum_grid_20). They keep the paper's settings; they measure cost, not accuracy.
#include "scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <string>

namespace cps::scenes {
namespace {

// What every scaled scene reports: enough to see that the run stayed sane.
class ScaledMetrics final : public Metrics {
 public:
  void observe(const World& world) override {
    world_ = &world;
    max_penetration_ = std::max(max_penetration_, deepest_contact(world));
    max_rod_error_ = std::max(max_rod_error_, max_rod_error(world));
  }
  nlohmann::json report() const override {
    return {{"bodies", world_ ? world_->bodies().size() : 0},
            {"kinetic_energy_J", world_ ? kinetic_energy(*world_) : 0.0},
            {"max_penetration_m", max_penetration_},
            {"max_rod_error_m", max_rod_error_}};
  }

 private:
  const World* world_ = nullptr;
  double max_penetration_ = 0.0;
  double max_rod_error_ = 0.0;
};

std::unique_ptr<Metrics> scaled_metrics(const World& world) { return observed<ScaledMetrics>(world); }

// A pyramid wall of unit boxes (1 kg) with base b and b (b + 1) / 2 boxes, 2 cm apart sideways.
void populate_pyramid(World& world, int boxes) {
  add_ground(world);
  int base = 1;
  while ((base + 1) * (base + 2) / 2 <= boxes) ++base;
  for (int row = 0; row < base; ++row) {
    const int count = base - row;
    for (int k = 0; k < count; ++k) {
      BodyDef box;
      box.shape = Shape::box(Vec3::Constant(0.5));
      box.mass = 1.0;
      box.position = Vec3(1.02 * (k - 0.5 * (count - 1)), 0.5 + row, 0.0);
      world.add_body(box);
    }
  }
}

// N balls (radius 0.5 m, 1 kg) in layers of m x m above the funnel of the paper's scene.
void populate_funnel_n(World& world, int balls) {
  add_funnel_walls(world);
  const int m = std::max(4, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(balls)) / 3.0)));
  const double half = 0.6 * (m - 1);
  for (int i = 0; i < balls; ++i) {
    const int layer = i / (m * m);
    const int a = (i % (m * m)) / m;
    const int b = i % m;
    BodyDef ball;
    ball.shape = Shape::sphere(0.5);
    ball.mass = 1.0;
    ball.position = Vec3(-half + 1.2 * a, half + 2.0 + 1.2 * layer, -half + 1.2 * b);
    world.add_body(ball);
  }
}

// An N x N pendulum grid as in the paper's scene, with a 1.6 m box on every third cell.
void populate_pendulum_grid_n(World& world, int side) {
  add_ground(world);
  const double c = 0.5 * (side - 1);
  for (int i = 0; i < side; ++i) {
    for (int k = 0; k < side; ++k) {
      BodyDef ball;
      ball.shape = Shape::sphere(0.5);
      ball.mass = 1.0;
      ball.position = Vec3(i - c, 5.0, k - c);
      const int index = world.add_body(ball);
      world.add_distance({index, Vec3(0.0, 0.5, 0.0), kWorldBody, Vec3(i - c, 8.5, k - c), 3.0});
    }
  }
  for (int i = 1; i + 1 < side; i += 3) {
    for (int k = 1; k + 1 < side; k += 3) {
      BodyDef box;
      box.shape = Shape::box(Vec3::Constant(0.8));
      box.mass = 1.0;
      box.position = Vec3(i - c + 0.5, 6.35, k - c + 0.5);
      world.add_body(box);
    }
  }
}

struct Family {
  std::string_view name;
  int max_size;
  std::function<WorldDef()> world_def;
  std::function<void(World&, int)> populate;
};

const std::array<Family, 5>& families() {
  static const std::array<Family, 5> table = {{
      {"stack", 40, &stack_world_def,
       [](World& w, int n) { add_ground_and_cube_column(w, 2.0, 3.0, n); }},
      {"pyramid", 20000, &stack_world_def, &populate_pyramid},
      {"funnel", 20000, &funnel_world_def, &populate_funnel_n},
      {"pendulum_wave", 20000, &pendulum_wave_world_def, &add_pendulum_wave_rows},
      {"pendulum_grid", 100, &pendulum_grid_world_def, &populate_pendulum_grid_n},
  }};
  return table;
}

constexpr std::array<std::string_view, 5> kFamilyHelp = {
    "stack_N (N cubes, 1..40)", "pyramid_N (about N boxes, 1..20000)",
    "funnel_N (N balls, 1..20000)", "pendulum_wave_N (N pendulums, 1..20000)",
    "pendulum_grid_N (N x N pendulums, 1..100)"};

}  // namespace

std::span<const std::string_view> scaled_families() { return kFamilyHelp; }

Scene scaled_scene(std::string_view family, int n) {
  for (const Family& f : families()) {
    if (f.name != family) continue;
    if (n < 1 || n > f.max_size) {
      throw std::invalid_argument(std::string(family) + "_N: N = " + std::to_string(n) +
                                  " is out of range; allowed 1.." + std::to_string(f.max_size));
    }
    // Names live as long as the program: scenes refer to them by string_view.
    static std::mutex mutex;
    static std::deque<std::string> names;
    const std::lock_guard<std::mutex> lock(mutex);
    names.push_back(std::string(family) + "_" + std::to_string(n));
    Scene s;
    s.name = names.back();
    s.summary = "scaled for benchmarks";
    s.default_seconds = 5.0;
    s.world_def = f.world_def;
    s.populate = [populate = f.populate, n](World& w) { populate(w, n); };
    s.make_metrics = &scaled_metrics;
    return s;
  }
  throw std::invalid_argument("unknown scene family '" + std::string(family) + "'");
}

}  // namespace cps::scenes
