// Box3D's two pyramid benchmark scenes (erincatto/box3d 0.1.0, shared/benchmarks.c:
// CreateLargePyramid, CreateManyPyramids; run by benchmark/main.c at dt 1/60 s and 4 substeps),
// built as Box3D builds them: cubes of 1 m (half extent 0.5 m) and density 100 kg/m^3 (100 kg),
// each row's neighbours touching face to face and each row resting on the one below, on the
// ground (Box3D's is a box whose top face is y = 0; here the plane y = 0). Their world is Box3D's
// default world with its default shape: the soft step at 4 substeps of one solve and one relax
// sweep, contact stiffness 30 Hz, damping ratio 10, push speed cap 3 m/s, warm starting with
// factor 1, friction 0.6 (the coupled limit mu lambda_n, as Box3D's), no restitution,
// speculative contacts within 4 linear slops (0.02 m), g = -10 m/s^2.
#include "box3d_pyramids.h"

#include "stress/stress.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace cps::scenes {
namespace {

constexpr double kHalf = 0.5;          // m: the cubes' half extent (Box3D's extent)
constexpr double kMassKg = 100.0;      // 1 m^3 at Box3D's benchmark density 100 kg/m^3
constexpr int kLargeBase = 100;        // CreateLargePyramid's baseCount
constexpr int kSmallBase = 10;         // CreateManyPyramids' baseCount
constexpr int kPyramidRows = 14;       // its rowCount
constexpr int kPyramidColumns = 14;    // its columnCount
constexpr int kBenchmarkSteps = 200;   // the steps of the scenes' default run

void add_cube(World& world, double x, double y, double z) {
  BodyDef box;
  box.shape = Shape::box(Vec3::Constant(kHalf));
  box.mass = kMassKg;
  box.position = Vec3(x, y, z);
  world.add_body(box);
}

// A wall pyramid of `base` cubes in its bottom row, centred on x = center_x, in the plane z.
void add_wall_pyramid(World& world, int base, double center_x, double z) {
  for (int i = 0; i < base; ++i) {
    const double y = (2.0 * i + 1.0) * kHalf;
    for (int j = i; j < base; ++j) {
      const double x = (i + 1.0) * kHalf + 2.0 * (j - i) * kHalf + center_x;
      add_cube(world, x, y, z);
    }
  }
}

WorldDef box3d_world_def() {
  WorldDef def;
  def.gravity = Vec3(0.0, -10.0, 0.0);
  def.dt = 1.0 / 60.0;
  def.push = PushMode::soft;
  def.soft_substeps = 4;
  def.iterations = 1;
  def.warm_start = 1.0;
  def.friction = 0.6;
  def.friction_model = FrictionModel::coupled;
  def.restitution = 0.0;
  def.contact_margin = 0.02;
  def.manifold_points = ManifoldPoints::four;
  def.contact_recycle_distance = 0.05;
  def.contact_hertz = 30.0;
  def.contact_damping_ratio = 10.0;
  def.contact_push_max_speed = 3.0;
  return def;
}

void populate_large_pyramid(World& world) {
  add_ground(world);
  add_wall_pyramid(world, kLargeBase, -kHalf * kLargeBase, 0.0);
}

void populate_many_pyramids(World& world) {
  add_ground(world);
  const double ground = kHalf * kPyramidColumns * (kSmallBase + 1.0);  // m: its half extent
  const double base_width = 2.0 * kHalf * kSmallBase;
  const double dz = 2.0 * (ground - 2.0 * kHalf) / (kPyramidRows - 1.0);
  double z = -ground + 2.0 * kHalf;
  for (int i = 0; i < kPyramidRows; ++i) {
    for (int j = 0; j < kPyramidColumns; ++j) {
      const double center_x = -ground + j * (base_width + 2.0 * kHalf) + 2.0 * kHalf;
      add_wall_pyramid(world, kSmallBase, center_x - 0.5, z);
    }
    z += dz;
  }
}

// HardCaseWatch's keys (as built = at rest; leave distance half a cube), and top_m: the highest
// point of any cube at the last observation (m).
class PyramidMetrics final : public Metrics {
 public:
  explicit PyramidMetrics(const World& world) : watch_(resting_places_as_built(world), kHalf) {}
  void observe(const World& world) override {
    watch_.observe(world);
    top_m_ = highest_point(world);
  }
  void diverged_since(double since_s) override { watch_.diverged_since(since_s); }
  nlohmann::json report() const override {
    nlohmann::json j = nlohmann::json::object();
    watch_.add_to(j);
    j["top_m"] = top_m_;
    return j;
  }

 private:
  HardCaseWatch watch_;
  double top_m_ = 0.0;
};

std::unique_ptr<Metrics> make_pyramid_metrics(const World& world) {
  return observed<PyramidMetrics>(world, world);
}

constexpr BenchTraits kBench{
    .start_s = 1.0 / 60.0,
    .seconds = 20.0 / 60.0,
    .reason = "steps 2 to 21: the wall stands as built, the window Box3D's benchmark is quoted over"};

const std::array kBenchmarkScenes = {
    Scene{.name = "large_pyramid",
          .summary = "Box3D's large_pyramid: 5050 cubes of 1 m, 100 kg, in a wall pyramid of 100 rows, with Box3D's world",
          .default_seconds = kBenchmarkSteps / 60.0,
          .world_def = &box3d_world_def,
          .populate = &populate_large_pyramid,
          .make_metrics = &make_pyramid_metrics,
          .plane_opacity = 1.0,
          .camera = CameraPreset{Vec3(0.0, 50.0, 150.0), Vec3(0.0, 45.0, 0.0), 45.0},
          .bench = kBench,
          .report = {}},
    Scene{.name = "many_pyramids",
          .summary = "Box3D's many_pyramids: 14 x 14 wall pyramids of 10 rows, 10,780 cubes of 1 m, 100 kg, with Box3D's world",
          .default_seconds = kBenchmarkSteps / 60.0,
          .world_def = &box3d_world_def,
          .populate = &populate_many_pyramids,
          .make_metrics = &make_pyramid_metrics,
          .plane_opacity = 1.0,
          .camera = CameraPreset{Vec3(0.0, 110.0, 170.0), Vec3(0.0, 0.0, 0.0), 45.0},
          .bench = kBench,
          .report = {}},
};

}  // namespace

double highest_point(const World& world) {
  double top = -kInfinity;
  for (const Body& b : world.bodies()) {
    if (b.is_static()) continue;
    double reach = b.shape.radius;
    if (b.shape.kind == ShapeKind::box) {
      // The highest corner: the y row of R times the half extents, in absolute value.
      const Mat3 R = b.rotation();
      reach = R.row(1).cwiseAbs().dot(b.shape.half_extents);
    }
    top = std::max(top, b.x.y() + reach);
  }
  return top;
}

std::span<const Scene> benchmark_scenes() { return kBenchmarkScenes; }

}  // namespace cps::scenes
