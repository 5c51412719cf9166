// The energy watch (demos/scenes/energy_rise.h): a bouncing cradle under the Baumgarte push gains
// and warns, the split push does not; the lift of a position-only push is not a gain; the paper's
// scenes at their defaults warn only where the push throws bodies (the intersecting stack).
#include "divergence.h"
#include "energy_rise.h"
#include "scene_file.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <string>

using namespace cps;
using namespace cps::scenes;

namespace {

// Newton's cradle (tests/data/cradle.json): five 1 kg balls of radius 0.1 m on 1 m rods from
// fixed points 0.2 m apart (touching), the first raised 60 degrees (0.5 m: 5 J above its lowest
// point), restitution 1.
const std::string kCradle = CPS_TEST_DATA "/cradle.json";

// The watch's result over `seconds` (s) of `scene` with `overrides`.
EnergyRise watched(const Scene& scene, double seconds, const Overrides& overrides = {}) {
  Run run = make_run(scene, overrides);
  const auto tracker = watch_energy_rise(run);
  run.advance_to(seconds);
  return tracker->result();
}

}  // namespace

TEST_CASE("a free fall never rises, and its scale is the height it fell", "[energy_rise]") {
  // Semi-implicit Euler loses m g^2 dt^2 / 2 a step in free fall: the rise is 0.
  const SceneFile file = parse_scene_file(
      R"({"bodies": [{"shape": "sphere", "radius_m": 0.1, "mass_kg": 2, "position_m": [0, 10, 0]}]})",
      "fall");
  const Scene scene = scene_of(file, "fall");
  Run run = make_run(scene);
  const auto tracker = watch_energy_rise(run);
  run.advance_to(1.0);
  const EnergyRise e = tracker->result();
  CHECK(e.rise_J() == 0.0);
  CHECK(e.lift_J < 1e-9);  // the positions move with the stored momenta (round-off only)
  CHECK_FALSE(e.warns());
  // The scale: m |g| (h0 - lowest h) = 2 kg x 10 m/s^2 x the drop (above the size term, 2 J).
  const double drop = 10.0 - run.world.bodies()[0].x.y();
  CHECK(e.scale_J == Approx(2.0 * 10.0 * drop).epsilon(1e-12));
  CHECK(e.scale_J > 2.0 * 10.0 * 0.1);
}

TEST_CASE("a bouncing cradle gains under the Baumgarte push and warns, under split it does not",
          "[energy_rise]") {
  const SceneFile file = read_scene_file(kCradle);
  const Scene scene = scene_of(file, "cradle.json");
  const EnergyRise baumgarte = watched(scene, 4.0);
  INFO("baumgarte: rise " << baumgarte.rise_J() << " J of " << baumgarte.scale_J << " J");
  // 5 J to spare (the raised ball); restitution 1 and a converged solve would keep it. The push
  // feeds the rod corrections into the velocities: 4.7 times the scale within 4 s.
  CHECK(baumgarte.fraction() > 2.0 * kEnergyRiseWarnFraction);
  CHECK(baumgarte.scale_J == Approx(5.0).margin(0.5));
  CHECK(baumgarte.lift_J < 1e-9);  // its positions move with the stored momenta (round-off)
  const std::string warning = energy_rise_warning("cradle.json", scene.world_def(), baumgarte);
  CHECK(warning.find("cradle.json: the energy (kinetic + potential) rose") == 0);
  CHECK(warning.find("--push baumgarte") != std::string::npos);
  CHECK(warning.find("try --push split") != std::string::npos);

  Overrides split;
  split.set("push", PushMode::split);
  const EnergyRise fixed = watched(scene, 4.0, split);
  INFO("split: rise " << fixed.rise_J() << " J of " << fixed.scale_J << " J");
  CHECK(fixed.fraction() < 0.1 * kEnergyRiseWarnFraction);
  WorldDef def = scene.world_def();
  def.push = PushMode::split;
  CHECK(energy_rise_warning("cradle.json", def, fixed).empty());
}

TEST_CASE("the split push lifting the intersecting stack out of its overlaps is no gain",
          "[energy_rise]") {
  const Scene& scene = *find_scene("intersecting_stack");
  Overrides split;
  split.set("push", PushMode::split);
  const EnergyRise e = watched(scene, 4.0, split);
  // The cubes (1.2 kg) rise by the overlaps below them: 1.2, 1.6, 2.0, 2.4 and 2.8 m, 10 m in
  // all, 120 J lifted by the positions alone, never given to the velocities.
  CHECK(e.lift_J > 119.0);
  CHECK(e.fraction() < 0.01);
  // The Baumgarte push throws them: 12.6 times the scale.
  CHECK(watched(scene, 1.0).fraction() > 10.0);
}

TEST_CASE("the paper's scenes at their defaults warn only where the push throws bodies",
          "[energy_rise]") {
  for (const Scene& scene : paper_scenes()) {
    // The pendulum wave over 10 s of its 62 (600 Hz); the others over their default duration.
    const double seconds = scene.name == "pendulum_wave" ? 10.0 : scene.default_seconds;
    const EnergyRise e = watched(scene, seconds);
    INFO(scene.name << ": rise " << e.rise_J() << " J of " << e.scale_J << " J");
    CHECK(e.warns() == (scene.name == "intersecting_stack"));
  }
}

TEST_CASE("the warning names when the rise passed the threshold, not the round-off peak of the "
          "plateau after it", "[energy_rise]") {
  // spin_1000: bodies spinning about axes that are not principal, no contact: the integrator's
  // kinetic energy rises within the first steps and then holds, its largest value a round-off
  // peak seconds later.
  const EnergyRise e = watched(*find_scene("spin_1000"), 3.0);
  INFO("passed at " << e.warn_time_s << " s, largest at " << e.max_time_s << " s");
  REQUIRE(e.warns());
  CHECK(e.warn_time_s <= 0.15);
  CHECK(e.warn_time_s <= e.max_time_s);
  const std::string warning = energy_rise_warning("spin_1000", find_scene("spin_1000")->world_def(), e);
  char passed[64];
  std::snprintf(passed, sizeof passed, "it passed that at t = %.3g s", e.warn_time_s);
  CHECK(warning.find(passed) != std::string::npos);
}

TEST_CASE("a light body thrown out while a heavy one moves warns, though the total barely rises",
          "[energy_rise]") {
  // No gravity; a 1000 kg ball coasting at 0.5 m/s (125 J, the scale) and, far from it, two
  // 0.1 kg balls overlapping by 0.2 m at rest: the Baumgarte push (beta d / dt = 2.4 m/s) throws
  // them apart at 1.2 m/s each with 0.14 J, about a thousandth of the scale, faster than the
  // fastest start, 0.5 m/s, the fastest anything could move without a gain.
  const SceneFile file = parse_scene_file(R"({"world": {"gravity_mps2": [0, 0, 0]}, "bodies": [
      {"shape": "sphere", "radius_m": 1, "mass_kg": 1000, "position_m": [0, 0, 0], "velocity_mps": [0.5, 0, 0]},
      {"shape": "sphere", "radius_m": 0.2, "mass_kg": 0.1, "position_m": [0, 0, 20]},
      {"shape": "sphere", "radius_m": 0.2, "mass_kg": 0.1, "position_m": [0.2, 0, 20]}]})",
                                          "thrown");
  const Scene scene = scene_of(file, "thrown");
  const EnergyRise e = watched(scene, 0.5);
  REQUIRE(e.thrown.has_value());
  INFO("body " << e.thrown->body << ", " << e.thrown->speed_mps << " m/s past " << e.thrown->limit_mps);
  CHECK(e.fraction() < 0.01);
  CHECK(e.warns());
  CHECK(e.thrown->mass_kg == 0.1);
  // The limit: the fastest start (0.5 m/s) with the 50 % margin on kinetic energy.
  CHECK(e.thrown->limit_mps == Approx(0.5 * std::sqrt(1.5)).epsilon(1e-12));
  CHECK(e.thrown->speed_mps == Approx(1.2).epsilon(1e-6));
  CHECK(energy_rise_warning("thrown", scene.world_def(), e).find("was thrown at") != std::string::npos);
  // Under the split push the overlap is undone in the positions: nothing is thrown.
  Overrides split;
  split.set("push", PushMode::split);
  const EnergyRise calm = watched(scene, 0.5, split);
  CHECK_FALSE(calm.thrown.has_value());
  CHECK_FALSE(calm.warns());
}

TEST_CASE("heavy_on_light under the paper's push warns: the smallest cube is driven through the "
          "ground", "[energy_rise]") {
  // The 0.1 m cube under 37 t of cubes sinks more than its edge into the ground within 0.2 s.
  Run run = make_run(*find_scene("heavy_on_light"));
  const auto tracker = watch_energy_rise(run);
  run.advance_to(1.0);
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump());
  REQUIRE(m["diverged"].get<bool>());
  CHECK(m["diverged_at_s"].get<double>() < 0.5);
  REQUIRE(run.divergence != nullptr);
  REQUIRE(run.divergence->found().has_value());
  CHECK(run.divergence->found()->at_s == m["diverged_at_s"].get<double>());
  const std::string warning = divergence_warning("heavy_on_light", *run.divergence->found());
  CHECK(warning.find("heavy_on_light: the run diverged at t = ") == 0);
  CHECK(warning.find("driven through") != std::string::npos);
}
