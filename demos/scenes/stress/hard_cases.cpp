// The hard cases, where a solver's convergence rather than its stability decides:
// - heavy_on_light: six cubes of one density whose edges double going up, the heaviest on top
//   (mass ratio 2^15 = 32768 between the top and bottom cubes; AVBD's StackRatio, Giles et al.
//   2025, goes to 1024 in 2D).
// - heavy_rope: a block hanging on a chain of light links, 1800 times a link's mass (the ratio of
//   AVBD's HeavyRope demo, whose rope starts horizontal and swings; this one hangs at rest, so
//   the rods must carry the static load), 1.15 m above the ground.
// - stack_20_long and pyramid_20_rows_long: stack_20 and the 20-row pyramid of the scaled scenes
//   (scaled.cpp) run for kLongRunSteps steps.
// All run at the paper's settings (stack_world_def). Their metrics are HardCaseMetrics
// (stress.h); the leave distances below are half the smallest body's size.
#include "stress/stress.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cps::scenes {
namespace {

// m: half the bottom cube's edge. A cube whose centre moved sideways by half the edge of the
// cube under it has its centre of mass over that cube's edge, where it tips; the stack has sunk
// into its bottom cube by half of it.
constexpr double kHeavyOnLightLeaveM = 0.5 * kHeavyOnLightSmallestEdgeM;
// m: a link's radius, half its size: the block has sunk by that much when the 20 rods together
// have stretched by 1 % of the rope's 5 m.
constexpr double kHeavyRopeLeaveM = kHeavyRopeLinkRadiusM;
// m: half the stack's 2.4 m cube edge (tipping, as above).
constexpr double kStackLeaveM = 1.2;
// m: half the pyramid's 1 m box edge (tipping, as above).
constexpr double kPyramidLeaveM = 0.5;
// The rope hangs from this fixed point (m).
const Vec3 kRopeAnchor(0.0, 7.0, 0.0);

const Scene& scaled(const char* name) { return *find_scene(name); }

}  // namespace

WorldDef heavy_on_light_world_def() { return stack_world_def(); }

void populate_heavy_on_light(World& world) {
  add_ground(world);
  double bottom = 0.0;  // m: the top of the cubes so far
  for (int k = 0; k < kHeavyOnLightCubes; ++k) {
    const double edge = kHeavyOnLightSmallestEdgeM * std::ldexp(1.0, k);
    BodyDef cube;
    cube.shape = Shape::box(Vec3::Constant(0.5 * edge));
    cube.mass = kHeavyOnLightDensity * edge * edge * edge;
    cube.position = Vec3(0.0, bottom + 0.5 * edge, 0.0);  // resting on the one below
    world.add_body(cube);
    bottom += edge;
  }
}

std::unique_ptr<Metrics> make_heavy_on_light_metrics(const World& world) {
  return observed<HardCaseMetrics>(world, resting_places_as_built(world), kHeavyOnLightLeaveM);
}

WorldDef heavy_rope_world_def() { return stack_world_def(); }

void populate_heavy_rope(World& world) { populate_heavy_rope_ratio(world, kHeavyRopeBlockRatio); }

void populate_heavy_rope_ratio(World& world, double ratio) {
  if (!(std::isfinite(ratio) && ratio > 0.0)) {
    throw std::invalid_argument("heavy rope: block to link mass ratio " + std::to_string(ratio) +
                                " must be finite and > 0");
  }
  add_ground(world);  // 1.15 m under the block: where it lands if the rope gives way
  for (int i = 0; i < kHeavyRopeLinks; ++i) {
    BodyDef link;
    link.shape = Shape::sphere(kHeavyRopeLinkRadiusM);
    link.mass = kHeavyRopeLinkMassKg;
    link.position = kRopeAnchor - Vec3(0.0, kHeavyRopeRodLengthM * (i + 1), 0.0);
    const int index = world.add_body(link);
    DistanceConstraint rod;
    rod.body_a = index;
    rod.local_a = Vec3::Zero();
    rod.body_b = i == 0 ? kWorldBody : index - 1;
    rod.local_b = i == 0 ? kRopeAnchor : Vec3::Zero();
    rod.length = kHeavyRopeRodLengthM;
    world.add_distance(rod);
  }
  const Vec3 last_link = kRopeAnchor - Vec3(0.0, kHeavyRopeRodLengthM * kHeavyRopeLinks, 0.0);
  BodyDef block;
  block.shape = Shape::box(Vec3::Constant(kHeavyRopeBlockHalfM));
  block.mass = ratio * kHeavyRopeLinkMassKg;
  block.position = last_link - Vec3(0.0, kHeavyRopeRodLengthM + kHeavyRopeBlockHalfM, 0.0);
  const int index = world.add_body(block);
  DistanceConstraint rod;  // from the middle of the block's top face to the last link's centre
  rod.body_a = index;
  rod.local_a = Vec3(0.0, kHeavyRopeBlockHalfM, 0.0);
  rod.body_b = index - 1;
  rod.local_b = Vec3::Zero();
  rod.length = kHeavyRopeRodLengthM;
  world.add_distance(rod);
}

std::unique_ptr<Metrics> make_heavy_rope_metrics(const World& world) {
  return observed<HardCaseMetrics>(world, resting_places_as_built(world), kHeavyRopeLeaveM);
}

// stack_20 drops its cubes with 0.6 m gaps: their resting places are the column they land in.
void populate_stack_20_long(World& world) { scaled("stack_20").populate(world); }

std::unique_ptr<Metrics> make_stack_20_long_metrics(const World& world) {
  return observed<HardCaseMetrics>(world, resting_places_stacked(world), kStackLeaveM);
}

// The pyramid is built at rest (rows touching, boxes 2 cm apart sideways).
void populate_pyramid_20_rows_long(World& world) { scaled("pyramid_210").populate(world); }

std::unique_ptr<Metrics> make_pyramid_20_rows_long_metrics(const World& world) {
  return observed<HardCaseMetrics>(world, resting_places_as_built(world), kPyramidLeaveM);
}

}  // namespace cps::scenes
