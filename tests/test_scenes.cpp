// Whole-world behaviour: resting contact and the paper's stack (Sec. 10.1).
#include "scene.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace cps;

TEST_CASE("a box dropped on the ground comes to rest with penetration under 1 cm", "[world]") {
  World world;  // paper settings: g = -10, dt = 1/60, 25 iterations, beta = 0.2, mu = 0.5
  world.add_body({Shape::plane(Vec3::UnitY(), 0.0), true});
  BodyDef box;
  box.shape = Shape::box(Vec3::Constant(0.5));
  box.mass = 1.0;
  box.position = Vec3(0.0, 2.0, 0.0);
  box.orientation = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 0, 1).normalized()));  // lands on a corner
  world.add_body(box);
  double deepest_late = 0.0;
  for (int k = 0; k < 600; ++k) {  // 10 s
    world.step();
    if (world.time() > 5.0) deepest_late = std::max(deepest_late, scenes::deepest_contact(world));
  }
  const Body& b = world.body(1);
  CHECK(b.velocity().norm() < 1e-3);
  CHECK(b.angular_velocity().norm() < 1e-3);
  CHECK(deepest_late < 0.01);
  // It rests on a face: the centre is half an edge above the ground, less the penetration.
  CHECK(b.x.y() == Approx(0.5).margin(0.01));
  CHECK(std::abs((b.rotation().transpose() * Vec3::UnitY()).cwiseAbs().maxCoeff() - 1.0) < 1e-3);
}

TEST_CASE("the stack settles and does not topple within 60 s", "[world][stack]") {
  const scenes::Scene* scene = scenes::find_scene("stack");
  REQUIRE(scene != nullptr);
  scenes::Run run = scenes::make_run(*scene);
  run.advance_to(60.0);
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump());
  CHECK(m["topple_time_s"].is_null());
  CHECK(m["max_tilt_deg"].get<double>() < 10.0);
  // Resting heights: half an edge (1.2 m) plus an edge (2.4 m) per cube below, within 2 cm
  // (the push factor leaves a few millimetres of penetration per contact).
  int i = 0;
  for (const Body& b : run.world.bodies()) {
    if (b.is_static()) continue;
    CHECK(b.x.y() == Approx(1.2 + 2.4 * i).margin(0.02));
    CHECK(b.velocity().norm() < 0.01);
    ++i;
  }
  CHECK(i == 5);
}

TEST_CASE("invalid parameters and bodies are rejected and leave the world unchanged",
          "[world][validation]") {
  WorldDef def;
  def.dt = -0.01;
  CHECK_THROWS_WITH(World(def), Catch::Contains("dt") && Catch::Contains("-0.01"));
  def = {};
  def.beta = 1.5;
  CHECK_THROWS_WITH(World(def), Catch::Contains("beta"));
  def = {};
  def.iterations = 0;
  CHECK_THROWS_AS(World(def), std::invalid_argument);

  World world;
  BodyDef bad;
  bad.shape = Shape::box(Vec3::Ones());
  bad.mass = -1.0;
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("mass") && Catch::Contains("-1"));
  bad.mass = 1.0;
  bad.position = Vec3(NAN, 0, 0);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("position"));
  bad.position = Vec3::Zero();
  bad.orientation = Quat(2.0, 0.0, 0.0, 0.0);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("unit quaternion"));
  CHECK_THROWS_WITH(Shape::box(Vec3(1.0, 0.0, 1.0)), Catch::Contains("half extents"));
  CHECK(world.bodies().empty());
}
