// The parameter table: every world parameter defined once, parsed and checked the same way by
// the engine's validation and by the command line.
#include "cps/parameters.h"
#include "cps/world.h"

#include <catch2/catch.hpp>

#include <set>
#include <string>

using namespace cps;

TEST_CASE("the parameter table names each parameter, flag and JSON key once", "[parameters]") {
  std::set<std::string> names, flags, keys;
  for (const Parameter& p : world_parameters()) {
    INFO(p.name);
    CHECK(names.insert(std::string(p.name)).second);
    if (!p.flag.empty()) CHECK(flags.insert(std::string(p.flag)).second);
    CHECK(keys.insert(std::string(p.json_key)).second);
    CHECK(!p.help.empty());
    REQUIRE(p.get != nullptr);
    REQUIRE(p.set != nullptr);
    // The defaults of WorldDef are allowed, and set(get()) keeps them.
    const WorldDef defaults;
    CHECK_FALSE(p.check(p.get(defaults)).has_value());
    WorldDef copy;
    p.set(copy, p.get(defaults));
    CHECK(p.format(p.get(copy)) == p.format(p.get(defaults)));
    // Units are the JSON key's suffix.
    if (p.unit == "s") CHECK(p.json_key.ends_with("_s"));
    if (p.unit == "m") CHECK(p.json_key.ends_with("_m"));
    if (p.unit == "m/s") CHECK(p.json_key.ends_with("_mps"));
  }
  CHECK(find_parameter("contact-margin") == &parameter("contact_margin"));
  CHECK(find_parameter("contact_margin_m") == &parameter("contact_margin"));
  CHECK(find_parameter("no_such_thing") == nullptr);
  CHECK_THROWS_AS(parameter("no_such_thing"), std::invalid_argument);
}

TEST_CASE("parameters parse whole decimal numbers and known names only", "[parameters]") {
  const Parameter& dt = parameter("dt");
  CHECK(std::get<double>(dt.parse("0.01")) == 0.01);
  CHECK(std::get<double>(dt.parse("1e-3")) == 1e-3);
  // A time step may be a fraction, and means exactly that quotient.
  CHECK(std::get<double>(dt.parse("1/60")) == 1.0 / 60.0);
  for (const char* bad : {"0", "-1", "nan", "inf", "abc", "1/0", "1/", "/60", "1s", "0x10", "", " 1", "1e308"}) {
    INFO(bad);
    CHECK_THROWS_WITH(dt.parse(bad), Catch::Contains("--dt"));
  }
  // Only a time takes a fraction.
  CHECK_THROWS_WITH(parameter("beta").parse("1/5"), Catch::Contains("--beta"));
  const Parameter& iterations = parameter("iterations");
  CHECK(std::get<int>(iterations.parse("25")) == 25);
  for (const char* bad : {"0", "1.5", "0x10", "4294967297", "1x", "-3"}) {
    INFO(bad);
    CHECK_THROWS_WITH(iterations.parse(bad), Catch::Contains("--iterations"));
  }
  const Parameter& push = parameter("push");
  CHECK(std::get<int>(push.parse("split")) == static_cast<int>(PushMode::split));
  CHECK_THROWS_WITH(push.parse("sideways"), Catch::Contains("baumgarte, split"));
  CHECK(name_of(PushMode::split) == "split");
  CHECK(name_of(Assembly::explicit_matrices) == "explicit");
  CHECK(name_of(FrictionModel::coupled) == "coupled");
  // Every choice's name parses back to its value.
  for (const Parameter& p : world_parameters()) {
    for (const Choice& c : p.choices) CHECK(std::get<int>(p.parse(c.name)) == c.value);
  }
  const Parameter& gravity = parameter("gravity");
  CHECK(std::get<Vec3>(gravity.parse("0,-9.81,0")) == Vec3(0.0, -9.81, 0.0));
  CHECK_THROWS_AS(gravity.parse("0,-9.81"), std::invalid_argument);
  CHECK_THROWS_AS(gravity.parse("0,nan,0"), std::invalid_argument);
}

TEST_CASE("the engine validates a WorldDef against the table, naming the parameter", "[parameters]") {
  WorldDef def;
  def.beta = 1.5;
  CHECK_THROWS_WITH(World(def), Catch::Contains("beta = 1.5") && Catch::Contains("[0, 1]"));
  def = {};
  def.dt = 0.0;
  CHECK_THROWS_WITH(World(def), Catch::Contains("dt = 0") && Catch::Contains("[1e-06, 1]"));
  def = {};
  def.iterations = 0;
  CHECK_THROWS_WITH(World(def), Catch::Contains("iterations = 0"));
  def = {};
  def.gravity = Vec3(0.0, kInfinity, 0.0);
  CHECK_THROWS_WITH(World(def), Catch::Contains("gravity"));
  def = {};
  def.push = static_cast<PushMode>(99);  // no such push method
  CHECK_THROWS_WITH(World(def), Catch::Contains("push"));
  // A bad value leaves the world's parameters as they were.
  World world;
  WorldDef bad;
  bad.restitution = -0.1;
  CHECK_THROWS_AS(world.set_def(bad), std::invalid_argument);
  CHECK(world.def().restitution == 0.0);
}
