// Scaled scenes for benchmarks: the paper's scenes grown to many bodies, made on demand from a
// family name and a size (stack_40, pyramid_1000, funnel_2000, pendulum_wave_10000,
// pendulum_grid_20). They keep the paper's settings; they measure cost, not accuracy.
#include "scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <initializer_list>
#include <limits>
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

// The camera preset of a scaled scene: the bodies and rod ends of `world` as built, with the
// points `also` (m), framed from `direction` (any length > 0) with a vertical field of view of
// 45 degrees, so that their bounding sphere (radius r) fits a 16:9 picture with 10 % margin:
// distance 1.1 r / sin(22.5 deg). The views grow with N, so every size shows its bodies.
CameraPreset framed_preset(const World& world, const Vec3& direction,
                           std::initializer_list<Vec3> also = {}) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max());
  Vec3 hi = Vec3::Constant(std::numeric_limits<double>::lowest());
  const auto grow = [&](const Vec3& a, const Vec3& b) {
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  };
  for (const Body& b : world.bodies()) {
    if (b.shape.kind == ShapeKind::box) {
      const Vec3 e = b.rotation().cwiseAbs() * b.shape.half_extents;
      grow(b.x - e, b.x + e);
    } else if (b.shape.kind == ShapeKind::sphere) {
      grow(b.x - Vec3::Constant(b.shape.radius), b.x + Vec3::Constant(b.shape.radius));
    }
  }
  for (const DistanceConstraint& d : world.distances()) {
    Vec3 p_a;
    Vec3 p_b;
    distance_endpoints(d, world.bodies(), p_a, p_b);
    grow(p_a, p_a);
    grow(p_b, p_b);
  }
  for (const Vec3& p : also) grow(p, p);
  constexpr double kPi = 3.14159265358979323846;
  constexpr double kFovDeg = 45.0;
  const double radius = std::max(0.5 * (hi - lo).norm(), 0.5);
  const double distance = 1.1 * radius / std::sin(0.5 * kFovDeg * kPi / 180.0);
  CameraPreset preset;
  preset.target = 0.5 * (lo + hi);
  preset.eye = preset.target + distance * direction.normalized();
  preset.fov_y_deg = kFovDeg;
  return preset;
}

struct Family {
  std::string_view name;
  int max_size;
  std::function<WorldDef()> world_def;
  std::function<void(World&, int)> populate;
  // The camera of a scene of this family, from its world as built.
  std::function<CameraPreset(const World&)> camera;
};

const std::array<Family, 5>& families() {
  static const std::array<Family, 5> table = {{
      // The column from the front, a little above its middle and to the side; with the
      // ground under it.
      {"stack", 40, &stack_world_def,
       [](World& w, int n) { add_ground_and_cube_column(w, 2.0, 3.0, n); },
       [](const World& w) { return framed_preset(w, Vec3(0.45, 0.25, 1.0), {Vec3::Zero()}); }},
      {"pyramid", 20000, &stack_world_def, &populate_pyramid,
       [](const World& w) { return framed_preset(w, Vec3(0.35, 0.3, 1.0), {Vec3::Zero()}); }},
      // From above the funnel's rim, the paper scene's direction (eye above all four walls,
      // y > |x| and y > |z|, so no wall hides the balls); the apex stays in view.
      {"funnel", 20000, &funnel_world_def, &populate_funnel_n,
       [](const World& w) { return framed_preset(w, Vec3(9.0, 13.5, 15.0), {Vec3::Zero()}); }},
      // One row (N <= 50): from above, tilted 4.6 degrees as the paper's Fig. 10 counterpart,
      // so the rods are seen short and the line of balls (4 cm across) runs across the
      // picture. More rows: from in front of the first row, just above the balls, looking
      // down the rows (along +z), so the near rows show their balls large and the far ones
      // recede; a view of the whole field (0.3 m per row, 120 m at N = 20000) would shrink
      // the balls below a pixel.
      {"pendulum_wave", 20000, &pendulum_wave_world_def, &add_pendulum_wave_rows,
       [](const World& w) {
         if (w.bodies().size() <= 50) return framed_preset(w, Vec3(0.0, 1.0, 0.08));
         Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max());
         Vec3 hi = Vec3::Constant(std::numeric_limits<double>::lowest());
         for (const Body& b : w.bodies()) {
           lo = lo.cwiseMin(b.x);
           hi = hi.cwiseMax(b.x);
         }
         const double mid_x = 0.5 * (lo.x() + hi.x());
         CameraPreset preset;
         preset.eye = Vec3(mid_x, hi.y() + 0.5, lo.z() - 1.9);
         preset.target = Vec3(mid_x, 0.5 * (lo.y() + hi.y()), lo.z() + 1.2);
         preset.fov_y_deg = 45.0;
         return preset;
       }},
      {"pendulum_grid", 100, &pendulum_grid_world_def, &populate_pendulum_grid_n,
       [](const World& w) { return framed_preset(w, Vec3(8.0, 8.0, 14.0)); }},
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
    // The camera scales with N: framed on the world as built (building it costs what one run's
    // set-up costs).
    World world(f.world_def());
    f.populate(world, n);
    s.camera = f.camera(world);
    return s;
  }
  throw std::invalid_argument("unknown scene family '" + std::string(family) + "'");
}

}  // namespace cps::scenes
