// Degenerate contact geometry, each on the ground at the paper's settings:
// - degen_coincident: two balls with the same centre (the sphere-sphere normal is
//   undefined; collision.h picks +y), which must come apart;
// - degen_parallel_edges: a cube whose bottom-left edge lies exactly on the top-right edge of
//   another (exactly parallel edges: their cross product is 0, and the two face axes tie);
// - degen_edge_balance: a cube standing on one edge (turned 45 degrees about z), centre
//   exactly above the edge;
// - degen_touching_boxes: two cubes resting side by side with faces exactly touching (zero
//   depth, zero relative velocity).
// None may produce a NaN, and the energy may not rise beyond the push work (EnergyTracker).
#include "stress/stress.h"

#include <cmath>
#include <numbers>

namespace cps::scenes {
namespace {

constexpr double kHalf = 0.5;    // m: cube half edge and ball radius
constexpr double kMass = 1.0;    // kg

void add_cube(World& world, const Vec3& position, const Quat& orientation = Quat::Identity()) {
  BodyDef cube;
  cube.shape = Shape::box(Vec3::Constant(kHalf));
  cube.mass = kMass;
  cube.position = position;
  cube.orientation = orientation;
  world.add_body(cube);
}

// EnergyMetrics plus the distance between the centres of bodies 1 and 2 (m), when both exist.
class DegenerateMetrics final : public EnergyMetrics {
 public:
  nlohmann::json report() const override {
    nlohmann::json j = EnergyMetrics::report();
    if (world_ && world_->bodies().size() > 2 && !energy_.nonfinite()) {
      j["centre_distance_m"] = (world_->body(2).x - world_->body(1).x).norm();
    }
    return j;
  }
};

}  // namespace

WorldDef degenerate_world_def() { return stack_world_def(); }

void populate_coincident_spheres(World& world) {
  add_ground(world);
  for (int i = 0; i < 2; ++i) {
    BodyDef ball;
    ball.shape = Shape::sphere(kHalf);
    ball.mass = kMass;
    ball.position = Vec3(0.0, 2.0, 0.0);  // the same point for both
    world.add_body(ball);
  }
}

void populate_parallel_edges(World& world) {
  add_ground(world);
  add_cube(world, Vec3(0.0, kHalf, 0.0));
  // One edge length right and up: its edge x = 0.5, y = 1 (along z) is the lower cube's.
  add_cube(world, Vec3(2.0 * kHalf, 3.0 * kHalf, 0.0));
}

void populate_edge_balance(World& world) {
  add_ground(world);
  // Turned 45 degrees about z: the lowest edge (along z) is half a face diagonal below the centre.
  add_cube(world, Vec3(0.0, kHalf * std::numbers::sqrt2, 0.0),
           Quat(Eigen::AngleAxisd(std::numbers::pi / 4.0, Vec3::UnitZ())));
}

void populate_touching_boxes(World& world) {
  add_ground(world);
  add_cube(world, Vec3(-kHalf, kHalf, 0.0));
  add_cube(world, Vec3(kHalf, kHalf, 0.0));  // the faces x = 0 coincide
}

std::unique_ptr<Metrics> make_degenerate_metrics(const World& world) {
  return observed<DegenerateMetrics>(world);
}

}  // namespace cps::scenes
