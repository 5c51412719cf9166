// AVBD (--push avbd, engine/src/push/avbd.cpp) on the hard cases: the mass ratios
// that PGS with every other push method loses within 0.1 s (docs/findings.md, "The hard cases").
// The resting box, the intersecting stack and the stretched rod are checked for every push
// method, avbd included, in test_push_methods.cpp.
//
//   build/tests/cps_tests "[avbd]"
#include "scene.h"

#include "cps/parameters.h"
#include "cps/world.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace cps;

namespace {

// Runs `name` for its default duration with push avbd and the overrides `o`; returns the
// scene's metrics.
nlohmann::json run_avbd(const char* name, scenes::Overrides o) {
  const scenes::Scene* scene = scenes::find_scene(name);
  REQUIRE(scene != nullptr);
  o.set("push", PushMode::avbd);
  scenes::Run run = scenes::make_run(*scene, o);
  run.advance_to(scene->default_seconds);
  nlohmann::json m = run.metrics->report();
  m["run_s"] = run.world.time();
  return m;
}

}  // namespace

TEST_CASE("avbd holds heavy_on_light and heavy_rope for their whole runs once the penalty "
          "starts at the heavy bodies' scale",
          "[avbd][hard_cases]") {
  // The demo's smallest penalty, 1 N/m, is for bodies of about 1 kg: a row must reach about
  // M / dt^2 to hold a body of mass M (the inertia term of the 6 x 6 block), 1.2e8 N/m for the
  // 32768 kg cube at dt = 1/60 s, and the ramp beta |C| = 1e5 x (a few mm) per sweep gets there
  // only after the light cubes have been crushed. Starting the penalties at 1e6 N/m, more than
  // M / dt^2 of the 180 kg block (6.5e5 N/m), both cases hold at the paper's 25 iterations: the
  // scene's own criterion (no body further than its leave distance from where it started, no
  // NaN) over the whole 10 s.
  for (const char* name : {"heavy_on_light", "heavy_rope"}) {
    INFO(name);
    scenes::Overrides o;
    o.set("avbd_k_start", 1.0e6);
    const nlohmann::json m = run_avbd(name, o);
    INFO(m.dump());
    CHECK(m["nan"] == false);
    CHECK(m["holds"] == true);
    CHECK(m["survival_s"].get<double>() == Approx(m["run_s"].get<double>()));
  }
}

TEST_CASE("avbd at the demo's defaults holds heavy_rope at 25 iterations", "[avbd][hard_cases]") {
  // The rods start at their length, so the ramp from 1 N/m stiffens them while the rope takes
  // the block's weight: the rope stretches, but the block ends within the leave distance (one
  // link radius, 5 cm) of where it started.
  const nlohmann::json m = run_avbd("heavy_rope", scenes::Overrides{});
  INFO(m.dump());
  CHECK(m["nan"] == false);
  CHECK(m["holds"] == true);
  CHECK(m["final_displacement_m"].get<double>() < m["leave_distance_m"].get<double>());
}

namespace {

// The centre heights (m, above the ground's top face, bottom to top) of a demo scene's boxes at
// t (s), at the scene's own settings (the demo's).
std::vector<double> demo_heights(const char* name, double t) {
  const scenes::Scene* scene = scenes::find_scene(name);
  REQUIRE(scene != nullptr);
  scenes::Run run = scenes::make_run(*scene);
  run.advance_to(t);
  std::vector<double> heights;
  for (const Body& b : run.world.bodies()) {
    if (!b.is_static()) heights.push_back(b.x.y());
  }
  return heights;
}

}  // namespace

TEST_CASE("the AVBD 3D demo's Stack and Stack Ratio rest where the demo's own solver leaves them",
          "[avbd][avbd_demo]") {
  // The reference: the demo (savant117/avbd-demo3d at 7701bd4, its solver built headless with a
  // driver that runs sceneStack and sceneStackRatio at the demo's defaults; docs/findings.md,
  // "AVBD against its 3D demo"), its centre heights less the ground box's top face (z = 0.5),
  // printed to 0.1 mm. The bound, 1 mm, is twenty times the rounding of the printed digits; a
  // cube sunk or lifted by one contact's resting depth (the demo's margin, 1 cm) fails it
  // tenfold.
  struct Reference {
    const char* scene;
    double t;
    std::vector<double> heights;
  };
  const Reference references[] = {
      {"avbd_stack", 5.0, {0.4899, 1.4791, 2.4688, 3.4592, 4.4424, 5.4263, 6.4148, 7.3994, 8.3795, 9.3551}},
      {"avbd_stack", 10.0, {0.4896, 1.4792, 2.4687, 3.4583, 4.4476, 5.4369, 6.4264, 7.4158, 8.4050, 9.3941}},
      {"avbd_stack_ratio", 5.0, {0.4775, 1.9550, 4.9327, 10.9115}},
      {"avbd_stack_ratio", 10.0, {0.4790, 1.9580, 4.9370, 10.9166}},
  };
  for (const Reference& r : references) {
    INFO(r.scene << " at " << r.t << " s");
    const std::vector<double> heights = demo_heights(r.scene, r.t);
    REQUIRE(heights.size() == r.heights.size());
    for (std::size_t i = 0; i < heights.size(); ++i) {
      INFO("box " << i);
      CHECK(std::isfinite(heights[i]));
      CHECK(std::abs(heights[i] - r.heights[i]) < 1e-3);
    }
  }
}

TEST_CASE("the AVBD demo's Dynamic Friction slabs stop near v0^2 / (2 mu g)", "[avbd][avbd_demo]") {
  // Coulomb friction stops a slab sent at v0 = 10 m/s after v0^2 / (2 mu g), mu = sqrt(mu_box
  // 0.5) the pair's (g = 10 m/s^2). The friction of a new contact builds up over the first steps
  // (its penalty starts at 1 N/m), so the bound is two steps' travel at v0, 2 v0 dt = 0.33 m; the
  // demo's own solver is within it (0.31 m beyond at mu 1, 0.09 m short at mu 0.5:
  // docs/findings.md). The slab without friction slides 10 m/s x 5 s.
  const scenes::Scene* scene = scenes::find_scene("avbd_dynamic_friction");
  REQUIRE(scene != nullptr);
  scenes::Run run = scenes::make_run(*scene);
  std::vector<double> start;
  for (const Body& b : run.world.bodies()) {
    if (!b.is_static()) start.push_back(b.x.x());
  }
  run.advance_to(5.0);
  std::size_t i = 0;
  for (const Body& b : run.world.bodies()) {
    if (b.is_static()) continue;
    const double mu = std::sqrt(b.friction * 0.5);
    const double slid = b.x.x() - start[i++];
    INFO("slab of mu_box " << b.friction << ": slid " << slid << " m");
    REQUIRE(std::isfinite(slid));
    if (mu > 0.0) {
      CHECK(std::abs(slid - 100.0 / (2.0 * mu * 10.0)) < 2.0 * 10.0 * run.world.def().dt);
      CHECK(b.velocity().norm() < 1e-2);
    } else {
      CHECK(slid == Approx(50.0).margin(1e-6));
    }
  }
}

TEST_CASE("the AVBD demo's Heavy Rope closes its 0.5 m joint gap as the demo does and holds the cube",
          "[avbd][avbd_demo]") {
  // The demo builds the cube's joint 0.5 m open and closes it slowly, alpha = 0.99 leaving each
  // step's rows 99 % of their error of the step's start: the demo's own solver (docs/findings.md,
  // "AVBD against its 3D demo") has its largest gap 0.3039 m at 1 s and 0.2087 m at 2 s, printed
  // to 0.1 mm. Bound 1 cm, 5 % of the gap: alpha 0.95 leaves 0.037 m at 1 s, 0.999 0.50 m. From
  // 6 s, every gap under 0.05 m, a twentieth of a link (the demo's 0.041 m at 5 s, 0.016 m at 10
  // s), and the cube never down on the ground (its centre at least its half edge, 2.5 m, above).
  const scenes::Scene* scene = scenes::find_scene("avbd_heavy_rope");
  REQUIRE(scene != nullptr);
  scenes::Run run = scenes::make_run(*scene);
  REQUIRE(run.world.bodies().back().mass == Approx(125.0));
  const auto gap_now = [&run] { return run.metrics->report()["max_joint_gap_m"].get<double>(); };
  run.advance_to(1.0);
  CHECK(std::abs(gap_now() - 0.3039) < 0.01);
  run.advance_to(2.0);
  CHECK(std::abs(gap_now() - 0.2087) < 0.01);
  double largest_late = 0.0;
  double lowest = run.world.bodies().back().x.y();
  for (int k = 5; k <= 20; ++k) {
    run.advance_to(0.5 * k);
    const double gap = gap_now();
    REQUIRE(std::isfinite(gap));
    if (0.5 * k >= 6.0) largest_late = std::max(largest_late, gap);
    lowest = std::min(lowest, run.world.bodies().back().x.y());
  }
  INFO("largest gap from 6 s " << largest_late << " m, lowest cube centre " << lowest << " m");
  CHECK(largest_late < 0.05);
  CHECK(lowest > 2.5);
}
