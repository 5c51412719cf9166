// The state hash of `cps simulate --json`: equal states hash equal, any bit of any coordinate
// changes it.
#include "scene.h"
#include "state_hash.h"

#include <catch2/catch.hpp>

#include <bit>
#include <cstdint>
#include <vector>

using namespace cps;

namespace {

// One bit of a double flipped: the nearest other double (the last bit of the mantissa).
double flip_last_bit(double x) {
  return std::bit_cast<double>(std::bit_cast<std::uint64_t>(x) ^ std::uint64_t{1});
}

std::uint64_t hash_after(const char* scene_name, double seconds) {
  const scenes::Scene* scene = scenes::find_scene(scene_name);
  REQUIRE(scene != nullptr);
  scenes::Run run = scenes::make_run(*scene);
  run.advance_to(seconds);
  return scenes::state_hash(run.world);
}

}  // namespace

TEST_CASE("the same run twice ends with the same state hash", "[state_hash]") {
  for (const char* name : {"stack", "funnel", "pendulum_grid"}) {
    INFO(name);
    CHECK(hash_after(name, 1.0) == hash_after(name, 1.0));
  }
  // A different end time is a different state.
  CHECK(hash_after("funnel", 1.0) != hash_after("funnel", 1.0 + 1.0 / 60.0));
}

TEST_CASE("flipping the last bit of any one coordinate changes the state hash", "[state_hash]") {
  const scenes::Scene* scene = scenes::find_scene("pendulum_grid");
  REQUIRE(scene != nullptr);
  scenes::Run run = scenes::make_run(*scene);
  run.advance_to(0.5);
  const std::vector<Body> bodies = run.world.bodies();
  const std::uint64_t original = scenes::state_hash(bodies);
  // Every one of the 13 numbers of a few bodies, one at a time.
  for (const std::size_t i : {std::size_t{0}, std::size_t{7}, bodies.size() - 1}) {
    for (int k = 0; k < 13; ++k) {
      std::vector<Body> changed = bodies;
      Body& b = changed[i];
      double* slots[13] = {&b.x.x(), &b.x.y(), &b.x.z(), &b.o.w(), &b.o.x(), &b.o.y(), &b.o.z(),
                           &b.p.x(), &b.p.y(), &b.p.z(), &b.l.x(), &b.l.y(), &b.l.z()};
      *slots[k] = flip_last_bit(*slots[k]);
      INFO("body " << i << ", number " << k);
      CHECK(scenes::state_hash(changed) != original);
    }
  }
  // The order of the bodies is part of the state.
  std::vector<Body> swapped = bodies;
  std::swap(swapped[1], swapped[2]);
  CHECK(scenes::state_hash(swapped) != original);
}

TEST_CASE("hashes print as 16 hex digits and parse back", "[state_hash]") {
  CHECK(scenes::format_hash(0x00ab00cd00ef0012ull) == "00ab00cd00ef0012");
  CHECK(scenes::parse_hash("00AB00cd00ef0012") == 0x00ab00cd00ef0012ull);
  CHECK(scenes::parse_hash("0x00ab00cd00ef0012") == 0x00ab00cd00ef0012ull);
  CHECK_FALSE(scenes::parse_hash("00ab00cd00ef001").has_value());   // 15 digits
  CHECK_FALSE(scenes::parse_hash("00ab00cd00ef00123").has_value()); // 17 digits
  CHECK_FALSE(scenes::parse_hash("00ab00cd00ef001g").has_value());
  CHECK_FALSE(scenes::parse_hash("").has_value());
}
