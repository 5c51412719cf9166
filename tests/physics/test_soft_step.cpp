// The soft step as Box3D runs it (engine/src/push/soft_step.cpp) and Box3D's pyramid scenes
// (demos/scenes/box3d_pyramids.cpp).
#include "box3d_pyramids.h"
#include "constraint_graph.h"
#include "scene.h"
#include "state_hash.h"
#include "stress/stress.h"

#include "cps/world.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>
#include <numbers>
#include <vector>

using namespace cps;

namespace {

constexpr double kG = 10.0;  // m/s^2

// A column of `count` cubes of 1 m and 100 kg resting face on face on the ground, in Box3D's
// world (the pyramids' defaults).
World box3d_column(int count) {
  World world(scenes::find_scene("large_pyramid")->world_def());
  scenes::add_ground(world);
  for (int i = 0; i < count; ++i) {
    BodyDef cube;
    cube.shape = Shape::box(Vec3::Constant(0.5));
    cube.mass = 100.0;
    cube.position = Vec3(0.0, 0.5 + i, 0.0);
    world.add_body(cube);
  }
  return world;
}

// Box3D's world (the pyramids' defaults) with `count` cubes of 1 m and 100 kg face on face on a
// static cube of 1 m (Box3D's ground in its benchmark), every cube set leaning as the column
// turning about its foot at `rate` (rad/s about x).
World leaning_box3d_column(int count, double rate) {
  World world(scenes::find_scene("large_pyramid")->world_def());
  BodyDef ground;
  ground.shape = Shape::box(Vec3::Constant(0.5));
  ground.is_static = true;
  ground.position = Vec3(0.0, -0.5, 0.0);
  world.add_body(ground);
  for (int i = 0; i < count; ++i) {
    BodyDef cube;
    cube.shape = Shape::box(Vec3::Constant(0.5));
    cube.mass = 100.0;
    cube.position = Vec3(0.0, 0.5 + i, 0.0);
    cube.angular_velocity = Vec3(rate, 0.0, 0.0);
    cube.velocity = Vec3(0.0, 0.0, rate * (0.5 + i));
    world.add_body(cube);
  }
  return world;
}

}  // namespace

TEST_CASE("a leaning column of ten cubes rocks with Box3D's period", "[soft][recycling]") {
  // Box3D 0.1.0 (erincatto/box3d 30c67b5) runs this column (a headless driver, docs/findings.md):
  // after the first swing the top cube's speed across the column changes sign every 74 to 77
  // steps, a period of 148 to 154 steps (150 on average). The period measures the stiffness of
  // the lean against gravity, which the recycled manifolds' anchors set: moved with the bodies,
  // they rocked it at 170 to 174 steps. Bound: the mean period within 5 % of Box3D's.
  World world = leaning_box3d_column(10, 0.002);
  std::vector<int> turns;  // steps where the top cube's v_z changes sign
  double last = 0.0;
  for (int k = 1; k <= 900; ++k) {
    world.step();
    const double vz = world.bodies().back().velocity().z();
    if (k > 100 && vz * last < 0.0) turns.push_back(k);
    last = vz;
  }
  REQUIRE(turns.size() >= 6);
  const double period = 2.0 * (turns.back() - turns.front()) / static_cast<double>(turns.size() - 1);
  INFO("period " << period << " steps over " << turns.size() << " sign changes");
  CHECK(std::abs(period - 150.0) < 0.05 * 150.0);
}

TEST_CASE("Box3D's wall of base 40 stays in its plane for 1500 steps", "[soft][slow]") {
  // CreateLargePyramid's layout with a base of 40 cubes (820) in Box3D's world. Box3D 0.1.0 keeps
  // it standing for 1500 steps: highest point 39.889 m, no centre more than 4 mm from the plane
  // z = 0 it is built in (docs/findings.md). Bound: no centre 1 cm from the plane, the highest
  // point within 1 cm of Box3D's. cps with the recycled anchors moved with the bodies leaned the
  // wall 3 m out of its plane by step 1000.
  World world(scenes::find_scene("large_pyramid")->world_def());
  scenes::add_ground(world);
  constexpr int kBase = 40;
  for (int i = 0; i < kBase; ++i) {
    for (int j = i; j < kBase; ++j) {
      BodyDef cube;
      cube.shape = Shape::box(Vec3::Constant(0.5));
      cube.mass = 100.0;
      cube.position = Vec3(0.5 * (i + 1.0) + (j - i) - 0.5 * kBase, i + 0.5, 0.0);
      world.add_body(cube);
    }
  }
  double out_of_plane = 0.0;
  for (int k = 0; k < 1500; ++k) {
    world.step();
    for (const Body& b : world.bodies()) {
      const double z = std::abs(b.x.z());
      if (!(z <= out_of_plane)) out_of_plane = z;  // a NaN is kept, and fails the check below
    }
  }
  const double top = scenes::highest_point(world);
  INFO("largest distance from the plane " << out_of_plane << " m, highest point " << top << " m");
  CHECK(out_of_plane < 0.01);
  CHECK(std::abs(top - 39.889) < 0.01);
}

TEST_CASE("the soft step's column settles at its soft contacts' static deflection",
          "[push_methods][soft]") {
  // At rest a soft row's update dP = -m (mass scale) (0 + bias rate C) - (impulse scale) P is 0
  // (b3MakeSoft's coefficients): C = -P / (m h omega^2), a spring of stiffness k_eff omega^2 with
  // k_eff = 1 / m the row's inverse effective mass. Each face-on-face interface has four corner
  // points, r = (+-0.5, +-0.5, +-0.5) m from the centres, so (r x n) I^-1 (r x n) = 0.5 x 6 / m for
  // each body (I = m / 6 for a cube of 1 m): k_eff = 8 / m between two cubes, 4 / m on the ground.
  // The interface under cube j carries the weight of the (count - j) cubes over it, a quarter per
  // point (P = F h). Stiffness: 30 Hz (Box3D's cap at an eighth of the 240 Hz substep rate is
  // also 30 Hz), twice that against the static ground. So the top cube sinks by
  //   sum_j (count - j) m g / 4 x k_eff / omega^2.
  constexpr int kCount = 10;
  constexpr double kMass = 100.0;
  World world = box3d_column(kCount);
  const double omega = 2.0 * std::numbers::pi * 30.0;
  double sink = kCount * kMass * kG / 4.0 * (4.0 / kMass) / std::pow(2.0 * omega, 2);  // the ground
  for (int j = 1; j < kCount; ++j) sink += (kCount - j) * kMass * kG / 4.0 * (8.0 / kMass) / (omega * omega);
  const double top0 = world.bodies().back().x.y();
  // One sweep a solve leaves the column rocking sideways at first (9 mm/s at 3 s); it is still by
  // 20 s.
  while (world.time() < 20.0) world.step();
  for (const Manifold& m : world.manifolds()) {
    if (m.contacts[0].depth > 0.0) CHECK(m.count == 4);  // the corners of each loaded face
  }
  const Body& top = world.bodies().back();
  INFO("analytic sink " << sink << " m, top cube at " << top.x.y() << " m");
  CHECK(top.velocity().norm() < 1e-5);  // at rest
  // 26 mm, to 0.1 %: the closed form leaves out the cubes' rotation in the rocking's wake.
  CHECK(top0 - top.x.y() == Approx(sink).epsilon(1e-3));
}

TEST_CASE("Box3D's pyramid scenes are built as Box3D's benchmark builds them", "[scenes][soft]") {
  for (const auto& [name, boxes] : {std::pair{"large_pyramid", 5050}, std::pair{"many_pyramids", 10780}}) {
    INFO(name);
    const scenes::Scene* scene = scenes::find_scene(name);
    REQUIRE(scene != nullptr);
    const WorldDef def = scene->world_def();
    CHECK(def.push == PushMode::soft);
    CHECK(def.soft_relax == SoftRelax::continue_solve);
    CHECK(def.soft_substeps == 4);
    CHECK(def.iterations == 1);
    CHECK(def.warm_start == 1.0);
    CHECK(def.friction == 0.6);
    CHECK(def.friction_model == FrictionModel::coupled);
    CHECK(def.contact_margin == 0.02);
    CHECK(def.dt == Approx(1.0 / 60.0));
    World world(def);
    scene->populate(world);
    int movable = 0;
    double lowest = 1e9;
    for (const Body& b : world.bodies()) {
      if (b.is_static()) continue;
      ++movable;
      CHECK(b.mass == 100.0);
      lowest = std::min(lowest, b.x.y());
    }
    CHECK(movable == boxes);
    CHECK(lowest == 0.5);  // the bottom row rests on the ground
    // Neighbours touch face to face: the first two cubes of the bottom row are 1 m apart.
    CHECK((world.bodies()[2].x - world.bodies()[1].x).norm() == Approx(1.0).margin(1e-12));
    scenes::Run run = scenes::make_run(*scene);
    run.step();
    CHECK(scenes::all_finite(run.world));
    CHECK(scenes::deepest_contact(run.world) < 0.01);
  }
}

TEST_CASE("Box3D's pyramids stand 200 steps under the soft step at Box3D's settings",
          "[soft][slow]") {
  // Box3D 0.1.0 (erincatto/box3d 30c67b5), built and run headless on the same scenes at the same
  // settings: large_pyramid's top at 99.309 m after 200 steps (it settles 0.69 m into its soft
  // contacts), many_pyramids' at 9.993 m with no cube moved more than 7.4 mm (docs/benchmarks.md).
  // Bound: the top within 0.1 m of Box3D's; in many_pyramids no cube farther than 1 cm from its
  // place.
  {
    scenes::Run run = scenes::make_run(*scenes::find_scene("large_pyramid"));
    for (int k = 0; k < 200; ++k) run.step();
    const double top = scenes::highest_point(run.world);
    INFO("large_pyramid's top " << top << " m");
    CHECK(std::abs(top - 99.309) < 0.1);
  }
  {
    scenes::Run run = scenes::make_run(*scenes::find_scene("many_pyramids"));
    for (int k = 0; k < 200; ++k) run.step();
    const nlohmann::json m = run.metrics->report();
    INFO(m.dump());
    CHECK(m.at("final_displacement_m").get<double>() < 0.01);
    CHECK(std::abs(m.at("top_m").get<double>() - 9.993) < 0.01);
  }
}

TEST_CASE("the constraint graph's colours share no moving body, and the overflow takes only "
          "what fits in no colour", "[soft][colour]") {
  // Random constraints among 40 bodies, one in five static (-1), many per body, so that some
  // bodies fill every colour: each constraint's colour is checked against the bodies already in
  // it, and the overflow against every colour open to it. Two moving bodies take the first free
  // of colours 0 to 19; one moving body the last free of 22 down to 1 (Box3D's rule,
  // StaticColours::last) or the first free of 0 to 22 (StaticColours::first).
  constexpr int kBodies = 40;
  for (const StaticColours statics : {StaticColours::last, StaticColours::first}) {
    const bool last = statics == StaticColours::last;
    CAPTURE(last);
    ConstraintGraph graph;
    graph.reset(kBodies, statics);
    std::vector<std::vector<bool>> in(ConstraintGraph::kColours, std::vector<bool>(kBodies, false));
    std::uint64_t seed = 12345;
    const auto next = [&seed](int n) {
      seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
      return static_cast<int>((seed >> 33) % static_cast<std::uint64_t>(n));
    };
    int overflow = 0;
    for (int k = 0; k < 2000; ++k) {
      int a = next(kBodies);
      int b = next(kBodies);
      if (a == b) continue;
      if (next(5) == 0) b = -1;
      const int colour = graph.add(a, b);
      REQUIRE(colour >= 0);
      REQUIRE(colour <= ConstraintGraph::kOverflow);
      const auto free_for = [&](int c) { return !in[c][a] && (b < 0 || !in[c][b]); };
      // The colours open to this constraint.
      const int lowest = b < 0 && last ? 1 : 0;
      const int end = b >= 0 ? ConstraintGraph::kDynamicColours : ConstraintGraph::kOverflow;
      if (colour == ConstraintGraph::kOverflow) {
        ++overflow;
        for (int c = lowest; c < end; ++c) CHECK_FALSE(free_for(c));
        continue;
      }
      CHECK(free_for(colour));
      CHECK(colour >= lowest);
      CHECK(colour < end);
      if (b < 0 && last) {
        for (int c = colour + 1; c < end; ++c) CHECK_FALSE(free_for(c));  // the last free one
      } else {
        for (int c = lowest; c < colour; ++c) CHECK_FALSE(free_for(c));  // the first free one
      }
      in[colour][a] = true;
      if (b >= 0) in[colour][b] = true;
    }
    CHECK(overflow > 0);  // the test reaches the overflow
    CHECK(graph.add(-1, -1) == ConstraintGraph::kOverflow);
  }
}

TEST_CASE("the soft step ends in the same state on 1, 2 and 3 threads", "[soft][threads]") {
  // The rows of a colour share no moving body and each thread sweeps a share of every colour
  // between barriers, so the updates, and their floating-point results, are the same for every
  // thread count: the state hash after 60 steps is equal bit for bit. A pile (contacts with
  // friction) and a chain of rods (rows to the world and between bodies), with both relax
  // variants.
  for (const char* name : {"pyramid_100", "chain_20"}) {
    for (const SoftRelax relax : {SoftRelax::continue_solve, SoftRelax::restart}) {
      CAPTURE(name, static_cast<int>(relax));
      std::uint64_t hashes[3] = {};
      for (int threads = 1; threads <= 3; ++threads) {
        const scenes::Scene* scene = scenes::find_scene(name);
        REQUIRE(scene != nullptr);
        scenes::Run run = scenes::make_run(*scene);
        WorldDef def = run.world.def();
        def.push = PushMode::soft;
        def.soft_relax = relax;
        def.warm_start = 1.0;
        def.threads = threads;
        run.world.set_def(def);
        for (int k = 0; k < 60; ++k) run.world.step();
        hashes[threads - 1] = scenes::state_hash(run.world);
      }
      CHECK(hashes[1] == hashes[0]);
      CHECK(hashes[2] == hashes[0]);
    }
  }
}

TEST_CASE("the soft step's rows, written when asked for, are the rows its step began with", "[soft]") {
  // The soft step prepares its points from the manifolds and leaves the contact and friction
  // rows unwritten until World::rows asks for them; they are then written from the bodies as they
  // were at the start of the step. A copy of the world taken before the step and stepped under the
  // paper's push builds them at once from the same state (the collide stage and the warm start's
  // match do not depend on the push), so the two must be equal bit for bit, in every step of a
  // run with landings that bounce (the world's restitution or a body's own), sliding and a rod.
  const auto bits = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  for (const double warm : {0.0, 1.0}) {
    for (const FrictionModel model : {FrictionModel::fixed, FrictionModel::coupled}) {
      for (const double world_restitution : {0.0, 0.4}) {
        CAPTURE(warm, static_cast<int>(model), world_restitution);
        WorldDef def;
        def.push = PushMode::soft;
        def.warm_start = warm;
        def.friction_model = model;
        def.restitution = world_restitution;
        def.restitution_threshold = 0.5;
        World world(def);
        scenes::add_ground(world);
        for (int i = 0; i < 3; ++i) {
          BodyDef box;
          box.shape = Shape::box(Vec3(0.3, 0.2, 0.25));
          box.mass = 2.0 + i;
          box.position = Vec3(0.1 * i, 1.0 + 0.6 * i, 0.05 * i);
          box.orientation = Quat(Eigen::AngleAxisd(0.3 * i, Vec3(1.0, 2.0, 0.5).normalized()));
          box.velocity = Vec3(1.5, 0.0, 0.0);
          world.add_body(box);
        }
        BodyDef ball;
        ball.shape = Shape::sphere(0.2);
        ball.position = Vec3(-1.0, 1.5, 0.0);
        ball.restitution = 0.9;
        world.add_body(ball);
        world.add_distance(DistanceConstraint{.body_a = 3, .local_a = Vec3(0.3, 0.2, 0.0), .body_b = kWorldBody,
                                              .local_b = Vec3(0.8, 3.5, 0.0), .length = 1.5});
        WorldDef paper = def;
        paper.push = PushMode::baumgarte;
        std::size_t compared = 0;
        std::size_t bouncing = 0;
        for (int step = 0; step < 90; ++step) {
          World eager(world);
          eager.set_def(paper);
          world.step();
          eager.step();
          const std::vector<ConstraintRow>& rows = world.rows();
          const std::vector<ConstraintRow>& expected = eager.rows();
          REQUIRE(world.manifolds().size() == eager.manifolds().size());
          REQUIRE(rows.size() == expected.size());
          for (std::size_t r = 0; r < rows.size(); ++r) {
            CAPTURE(step, r);
            const ConstraintRow& x = rows[r];
            const ConstraintRow& y = expected[r];
            REQUIRE(x.kind == y.kind);
            REQUIRE(x.body_a == y.body_a);
            REQUIRE(x.body_b == y.body_b);
            REQUIRE(x.normal_row == y.normal_row);
            for (int k = 0; k < 12; ++k) REQUIRE(bits(x.j[k], y.j[k]));
            REQUIRE(bits(x.push, y.push));
            REQUIRE(bits(x.bias, y.bias));
            REQUIRE(bits(x.restitution, y.restitution));
            REQUIRE(bits(x.c_min, y.c_min));
            REQUIRE(bits(x.c_max, y.c_max));
            REQUIRE(bits(x.mu, y.mu));
            bouncing += x.restitution > 0.0 ? 1 : 0;
          }
          compared += rows.size();
        }
        CHECK(compared > 1000);
        CHECK(bouncing > 0);  // the ball's own restitution at least
      }
    }
  }
}

TEST_CASE("the soft step's lambda, written when asked for, holds boxes at rest on a slope", "[soft]") {
  // Two boxes resting one on the other on the ground under gravity tilted 20 degrees from the
  // normal (a slope), friction 0.6 > tan 20 degrees, warm started as Box3D always is: at rest
  // (still to round-off: each substep's impulses are the last's) the rows' forces J^T lambda on
  // each box (the last substep's impulses over h, written from the soft step's impulses when
  // World::lambda asks for them) balance its weight. (Their torques balance it only to about
  // 1e-6: a manifold's friction, solved at its centre, is shared out among its points.)
  const double slope = 20.0 * std::numbers::pi / 180.0;
  WorldDef def;
  def.push = PushMode::soft;
  def.warm_start = 1.0;
  def.friction = 0.6;
  def.friction_model = FrictionModel::coupled;  // Box3D's (the fixed limit counts one box's weight)
  def.gravity = kG * Vec3(std::sin(slope), -std::cos(slope), 0.0);
  World world(def);
  scenes::add_ground(world);
  const Vec3 half(0.6, 0.3, 0.4);
  for (int i = 0; i < 2; ++i) {
    BodyDef box;
    box.shape = Shape::box(half);
    box.mass = 5.0 + 3.0 * i;
    box.position = Vec3(0.1 * i, half.y() * (1 + 2 * i), -0.05 * i);
    box.orientation = Quat(Eigen::AngleAxisd(0.2 * i, Vec3::UnitY()));
    world.add_body(box);
  }
  while (world.time() < 5.0) world.step();
  const std::vector<ConstraintRow>& rows = world.rows();
  const std::vector<double>& lambda = world.lambda();
  REQUIRE(lambda.size() == rows.size());
  for (int b = 1; b <= 2; ++b) {
    CAPTURE(b);
    const Body& body = world.bodies()[static_cast<std::size_t>(b)];
    Vec3 force = body.mass * def.gravity;
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const ConstraintRow& row = rows[r];
      if (row.body_a == b) force += lambda[r] * row.j.segment<3>(0);
      if (row.body_b == b) force += lambda[r] * row.j.segment<3>(6);
    }
    const double weight = body.mass * kG;
    INFO("speed " << body.velocity().norm() << " m/s; force left " << force.transpose() << " N");
    CHECK(body.velocity().norm() < 1e-12);
    CHECK(force.norm() < 1e-12 * weight);
  }
}
