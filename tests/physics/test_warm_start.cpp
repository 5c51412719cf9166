// Warm starting (WorldDef::warm_start, Sec. 6.2.3): a persisting contact's or rod's rows start
// from the factor times their cached lambda (engine/src/warm_start.h).
#include "scene.h"
#include "warm_start.h"  // engine/src

#include <catch2/catch.hpp>

#include <cmath>

using namespace cps;

namespace {

constexpr double kG = 10.0;  // m/s^2

// Sum of the contact rows' lambdas of the world's last first solve (N).
double normal_force(const World& world) {
  double sum = 0.0;
  for (std::size_t r = 0; r < world.rows().size(); ++r) {
    if (world.rows()[r].kind == RowKind::contact) sum += world.lambda()[r];
  }
  return sum;
}

// A 1 kg cube resting on the ground (1 mm margin, so its contacts never flicker), `iterations`
// sweeps a solve, after 3 s.
World resting_cube(double warm_start, int iterations) {
  WorldDef def;
  def.iterations = iterations;
  def.warm_start = warm_start;
  def.contact_margin = 0.001;
  World world(def);
  world.add_body({Shape::plane(Vec3::UnitY(), 0.0), true});
  BodyDef cube;
  cube.shape = Shape::box(Vec3::Constant(0.5));
  cube.mass = 1.0;
  cube.position = Vec3(0.0, 0.5, 0.0);
  world.add_body(cube);
  for (int k = 0; k < 180; ++k) world.step();
  return world;
}

}  // namespace

TEST_CASE("warm starting carries a resting contact's solve over from step to step",
          "[warm_start]") {
  // One PGS sweep a step. From lambda = 0 a sweep over the four corner rows (contact rows
  // first, each corner seeing the ones before it through the cube's rotation) does not reach the
  // weight: the cube keeps sinking and the push holds it at a depth where push and shortfall
  // balance. Warm started with factor 1 the sweeps of successive steps add up, as more sweeps of
  // one solve would: at rest the contact rows carry the weight m g = 10 N (the smaller-of-two
  // rule changes nothing for a steady lambda).
  const World cold = resting_cube(0.0, 1);
  const World warm = resting_cube(1.0, 1);
  INFO("cold: " << normal_force(cold) << " N, warm: " << normal_force(warm) << " N");
  CHECK(normal_force(warm) == Approx(1.0 * kG).epsilon(1e-3));
  CHECK(warm.persisting_contacts() == 4);
  CHECK(cold.persisting_contacts() == 0);  // factor 0: no cache, the paper's guess 0
  // And it rests: no velocity left.
  CHECK(warm.body(1).velocity().norm() < 1e-6);
}

TEST_CASE("warm-started rods carry their solve over from step to step", "[warm_start]") {
  // Two 1 kg balls hanging at rest in a chain: a 1 m rod from a fixed point to ball 0, a 1 m rod
  // from ball 0 to ball 1. The rods hold 2 m g = 20 N and m g = 10 N. One sweep a step: from 0
  // the top rod is solved before the lower one has pulled, so it carries 10 N only and the
  // chain sags until the push makes up the rest. Warm started with factor 1 the rows keep their
  // values from step to step and hold the exact forces, with the rods at their lengths.
  const auto chain = [](double factor) {
    WorldDef def;
    def.iterations = 1;
    def.warm_start = factor;
    World world(def);
    for (int i = 0; i < 2; ++i) {
      BodyDef ball;
      ball.shape = Shape::sphere(0.2);
      ball.mass = 1.0;
      ball.position = Vec3(0.0, -1.0 - i, 0.0);
      world.add_body(ball);
    }
    world.add_distance({0, Vec3::Zero(), kWorldBody, Vec3::Zero(), 1.0});
    world.add_distance({1, Vec3::Zero(), 0, Vec3::Zero(), 1.0});
    for (int k = 0; k < 600; ++k) world.step();  // 10 s
    return world;
  };
  const World warm = chain(1.0);
  const World cold = chain(0.0);
  REQUIRE(warm.lambda().size() == 2);
  INFO("warm: " << warm.lambda()[0] << ", " << warm.lambda()[1] << " N; cold: "
                << cold.lambda()[0] << ", " << cold.lambda()[1] << " N");
  // The top rod's row pulls ball 0 up (its axis points from ball 0 to the fixed point).
  CHECK(std::abs(warm.lambda()[0]) == Approx(2.0 * kG).epsilon(1e-6));
  CHECK(std::abs(warm.lambda()[1]) == Approx(1.0 * kG).epsilon(1e-6));
  CHECK(warm.body(0).x.y() == Approx(-1.0).margin(1e-6));
  CHECK(warm.body(1).x.y() == Approx(-2.0).margin(1e-6));
  // Cold, one sweep leaves the top rod short of 20 N: the push holds it stretched.
  CHECK(cold.body(0).x.y() < -1.0 - 1e-3);
}

TEST_CASE("a copied world carries its warm start cache and steps on as the original",
          "[warm_start]") {
  // World's copy constructor copies the cache: the copy's next steps start from the same
  // guesses, so both end in the same state, bit for bit. Without the cache the copy's first
  // step would start from 0 and the stack would part from the original in its last bits.
  scenes::Overrides o;
  o.set("warm_start", 0.8);
  scenes::Run run = scenes::make_run(*scenes::find_scene("stack"), o);
  run.advance_to(2.0);
  World copy = run.world;
  REQUIRE(copy.persisting_contacts() == run.world.persisting_contacts());
  for (int k = 0; k < 30; ++k) {
    run.world.step();
    copy.step();
  }
  for (std::size_t i = 0; i < copy.bodies().size(); ++i) {
    INFO("body " << i);
    CHECK(copy.bodies()[i].x == run.world.bodies()[i].x);
    CHECK(copy.bodies()[i].p == run.world.bodies()[i].p);
    CHECK(copy.bodies()[i].l == run.world.bodies()[i].l);
  }
  // The same copy with the cache dropped (factor 0 for a step) does part from it.
  World cold = run.world;
  WorldDef def = cold.def();
  def.warm_start = 0.0;
  cold.set_def(def);
  cold.step();
  def.warm_start = 0.8;
  cold.set_def(def);
  run.world.step();
  bool differs = false;
  for (std::size_t i = 0; i < cold.bodies().size(); ++i) {
    differs = differs || cold.bodies()[i].x != run.world.bodies()[i].x;
  }
  CHECK(differs);
}

TEST_CASE("after the soft step's store the sustained rule finds no older lambda, then keeps its normal one",
          "[warm_start]") {
  // A world may change its push method between steps (set_def). One manifold of two points
  // (features 1 and 2) and its two contact rows, no friction rows. The sustained rule guesses
  // the factor times the smaller of a contact row's last two lambdas. Two of its stores at 3 N
  // leave both lambdas at 3 N; a store by the manifold rule (the soft step's: normal lambdas 5
  // and 7 N) replaces them by the normal lambda alone, so the next guesses are 0, as for a
  // contact in its first step; the sustained store after it keeps 5 and 7 N as the older lambdas.
  Manifold m;
  m.body_a = 0;
  m.body_b = 1;
  Contact contact;
  contact.normal = Vec3::UnitY();
  contact.depth = 0.01;
  contact.feature = 1;
  contact.point = Vec3(-0.5, 0.0, 0.0);
  m.add(contact);
  contact.feature = 2;
  contact.point = Vec3(0.5, 0.0, 0.0);
  m.add(contact);
  const std::vector<Manifold> manifolds{m};
  std::vector<ConstraintRow> rows(2);
  for (ConstraintRow& row : rows) row.c_min = 0.0;
  WarmStartCache cache;
  std::vector<double> first;
  std::vector<double> second;
  for (int k = 0; k < 2; ++k) {
    cache.match(manifolds);
    cache.store(manifolds, rows, 0, {3.0, 3.0}, {});
  }
  cache.match(manifolds);
  cache.initial_guesses(manifolds, rows, 0, 1.0, FrictionModel::fixed, first, second);
  REQUIRE(first.size() == 2);
  CHECK(first[0] == 3.0);  // the sustained rule at work
  cache.begin_store(manifolds);
  const double normal[2] = {5.0, 7.0};
  cache.store_manifold(0, m, normal, Vec3::Zero(), 0.0);
  cache.end_store(nullptr, 0);
  cache.match(manifolds);
  CHECK(cache.matched_points() == 2);
  CHECK(cache.last_normal(0) == 5.0);
  CHECK(cache.last_normal(1) == 7.0);
  cache.initial_guesses(manifolds, rows, 0, 1.0, FrictionModel::fixed, first, second);
  REQUIRE(first.size() == 2);
  CHECK(first[0] == 0.0);
  CHECK(first[1] == 0.0);
  CHECK(second.empty());
  cache.store(manifolds, rows, 0, {6.0, 4.0}, {});
  cache.match(manifolds);
  cache.initial_guesses(manifolds, rows, 0, 0.5, FrictionModel::fixed, first, second);
  CHECK(first[0] == 0.5 * 5.0);  // the smaller of 6 and 5 N
  CHECK(first[1] == 0.5 * 4.0);  // of 4 and 7 N
}

TEST_CASE("warm_start is a world parameter in [0, 1] with the flag --warm-start",
          "[warm_start][parameters]") {
  const Parameter* p = find_parameter("warm-start");
  REQUIRE(p != nullptr);
  CHECK(p->name == "warm_start");
  CHECK(p->json_key == "warm_start");
  CHECK(std::get<double>(p->get(WorldDef{})) == 0.0);  // the paper's initial guess 0
  CHECK(std::get<double>(p->parse("0.8")) == 0.8);
  CHECK_THROWS_WITH(p->parse("1.5"), Catch::Contains("--warm-start") && Catch::Contains("[0, 1]"));
  CHECK_THROWS(p->parse("-0.1"));
  WorldDef def;
  def.warm_start = 2.0;
  CHECK_THROWS_WITH(World(def), Catch::Contains("warm_start"));
}
