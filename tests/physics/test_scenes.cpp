// Whole-world behaviour: resting contact and the paper's stack (Sec. 10.1).
#include "divergence.h"
#include "pendulum_reference.h"
#include "scene.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

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

TEST_CASE("the stack settles and does not slide off within 60 s", "[world][stack]") {
  const scenes::Scene* scene = scenes::find_scene("stack");
  REQUIRE(scene != nullptr);
  scenes::Run run = scenes::make_run(*scene);
  run.advance_to(60.0);
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump());
  CHECK(m["slide_off_time_s"].is_null());
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

TEST_CASE("the stack stays on its base for 600 s with either friction model", "[world][stack]") {
  // At rest the column is in equilibrium and friction can hold it, so any sideways motion is
  // solver error. With each point's friction rows right after its contact row, PGS's residual
  // after 25 sweeps left the bottom face sliding at 3.7 mm/s on average, always the same way,
  // and the column passed the scene's 0.5 m criterion at 146 s (coupled friction: 194 s). With
  // all friction rows after all contact rows (World::build_rows) the sliding velocity the
  // friction rows set is the last thing a sweep changes: measured 0.18 m (fixed) and 0.13 m
  // (coupled) at most over 600 s. Bound: the scene's own criterion, 0.5 m off the axis.
  for (const FrictionModel model : {FrictionModel::fixed, FrictionModel::coupled}) {
    scenes::Overrides o;
    o.set("friction_model", model);
    scenes::Run run = scenes::make_run(*scenes::find_scene("stack"), o);
    run.advance_to(600.0);
    const nlohmann::json m = run.metrics->report();
    INFO(name_of(model) << ": " << m.dump());
    CHECK(m["slide_off_time_s"].is_null());
    CHECK(m["max_drift_m"].get<double>() < 0.5);
  }
}

TEST_CASE("a penetration slop leaves a resting box that deep, the push alone breaks contact",
          "[world][slop]") {
  // The push (Eq. 5.3.1) with a slop s corrects beta (d - s) / dt of a depth d > s each step and
  // nothing below s, so once the box rests the excess shrinks by the factor (1 - beta) a step
  // (0.8^240 ~ 5e-24 after 4 s): the depth converges to s, from above when the landing went
  // deeper than s. Dropped from 1 m, the box lands about |v| dt = 7.5 cm deep, so the depth
  // ends at s for every slop tried, and the four corners never lose their contact once landed.
  // With s = 0 (the paper's push at the paper's margin 0) the push drives the depth to 0, a
  // corner then has no contact for a step, the box falls back and the contact is made again:
  // it never comes to rest (the cause of the stack's creep, docs/findings.md, "Why the paper's stack
  // drifts").
  for (const double slop : {0.0, 0.001, 0.005, 0.02}) {
    WorldDef def;
    def.penetration_slop = slop;
    World world(def);
    world.add_body({Shape::plane(Vec3::UnitY(), 0.0), true});
    BodyDef box;
    box.shape = Shape::box(Vec3::Constant(0.5));
    box.mass = 1.0;
    box.position = Vec3(0.0, 1.5, 0.0);
    world.add_body(box);
    int fewest_points = 4;  // contact points a step, from 2 s (landed at 0.45 s) to 6 s
    for (int k = 0; k < 360; ++k) {
      world.step();
      if (k >= 120) {
        const int n = world.manifolds().empty() ? 0 : world.manifolds()[0].count;
        fewest_points = std::min(fewest_points, n);
      }
    }
    INFO("slop " << slop);
    const Body& b = world.body(1);
    if (slop == 0.0) {
      CHECK(fewest_points < 4);  // a corner lost its contact at least once
      continue;
    }
    CHECK(fewest_points == 4);
    // The centre rests half an edge up, less the depth: 0.5 - s, to 1e-9 m.
    CHECK(b.x.y() == Approx(0.5 - slop).margin(1e-9));
    CHECK(scenes::deepest_contact(world) == Approx(slop).margin(1e-9));
    // The solve cancels g dt = 0.17 m/s a step; 25 sweeps leave under 1e-5 of it (measured
    // 6e-8 m/s).
    CHECK(b.velocity().norm() < 1e-6);
  }
}

TEST_CASE("with a penetration slop and warm starting at 1 the stack stands for 600 s",
          "[world][stack][warm_start][slop]") {
  // Without a slop the push drives resting depths to 0, corners lose their contact for a step,
  // their rows restart from 0 and the column rocks and creeps (docs/findings.md, "Why the paper's stack
  // drifts"). With a 5 mm slop every point persists, a warm start at 1 starts each solve at
  // last step's answer and the cubes stand still once landed. Measured: creep 0.3 mm after the
  // landing (0.3 m without a slop). Bound: 1 cm, the target set for a standing column.
  scenes::Overrides o;
  o.set("penetration_slop", 0.005);
  o.set("warm_start", 1.0);
  scenes::Run run = scenes::make_run(*scenes::find_scene("stack"), o);
  run.advance_to(600.0);
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump());
  CHECK(m["slide_off_time_s"].is_null());
  CHECK(m["creep_m"].get<double>() < 0.01);
  // Every point of the last step persisted from the step before.
  std::size_t points = 0;
  for (const Manifold& mf : run.world.manifolds()) points += static_cast<std::size_t>(mf.count);
  CHECK(points >= 20);  // 5 faces, at least 4 points each
  CHECK(run.world.persisting_contacts() == points);
}

TEST_CASE("with a penetration slop the funnel at contact margin 0 comes to rest",
          "[world][funnel][warm_start][slop]") {
  // At margin 0 without a slop the balls the push lifts clear lose their contact for a step and
  // fall back: 9e-3 J of kinetic energy at 10 s cold, 4e-4 J warm started at 0.8. A 1 mm slop
  // keeps their contacts (measured 3e-7 J at 0.8). Bound: 1e-4 J, the target for a pile at rest
  // (a ball of the funnel moving at 1 cm/s carries 5e-5 J).
  for (const double factor : {0.8, 1.0}) {
    scenes::Overrides o;
    o.set("contact_margin", 0.0);
    o.set("penetration_slop", 0.001);
    o.set("warm_start", factor);
    scenes::Run run = scenes::make_run(*scenes::find_scene("funnel"), o);
    run.advance_to(10.0);
    INFO("warm start " << factor);
    CHECK(scenes::kinetic_energy(run.world) < 1e-4);
  }
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
  // Values outside the ranges that keep a step finite (body.h), checked with the floating point
  // traps on (the checks themselves must not raise): each message names the value and the range.
  bad.orientation = Quat::Identity();
  bad.mass = 1e-310;  // subnormal: 1 / m would be inf
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("mass") && Catch::Contains("[1e-06, 1e+09] kg"));
  bad.mass = 1e300;  // m v would overflow
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("mass 1e+300"));
  bad.mass = 1.0;
  CHECK_THROWS_WITH(Shape::box(Vec3::Constant(1e-200)), Catch::Contains("[0.0001, 100000] m"));
  CHECK_THROWS_WITH(Shape::sphere(1e10), Catch::Contains("radius 1e+10"));
  CHECK_THROWS_WITH(Shape::plane(Vec3::UnitY(), 1e300), Catch::Contains("offset"));
  bad.velocity = Vec3(INFINITY, 0, 0);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("velocity"));
  bad.velocity = Vec3(1e10, 0, 0);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("velocity") && Catch::Contains("100000 m/s"));
  bad.velocity = Vec3::Zero();
  bad.angular_velocity = Vec3(0, 0, -1e6);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("angular velocity"));
  bad.angular_velocity = Vec3::Zero();
  bad.position = Vec3(0, 2e9, 0);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("position"));
  // World parameters outside the table's ranges: a step that cannot stay finite.
  def = {};
  def.dt = 1e308;
  CHECK_THROWS_WITH(World(def), Catch::Contains("dt = 1e+308"));
  def = {};
  def.gravity = Vec3(0, -1e308, 0);
  CHECK_THROWS_WITH(World(def), Catch::Contains("gravity"));
  CHECK(world.bodies().empty());
}

namespace {

scenes::Run run_scene(const char* name, const scenes::Overrides& o = {}) {
  const scenes::Scene* scene = scenes::find_scene(name);
  REQUIRE(scene != nullptr);
  return scenes::make_run(*scene, o);
}

}  // namespace

TEST_CASE("a run that drives bodies through the ground is flagged diverged, and reports no "
          "slide-off after it", "[scene][stack]") {
  scenes::Overrides o;
  o.set("dt", 1.0);  // s: the cubes fall 5 m or more in one step and sink through the ground
  scenes::Run run = run_scene("stack", o);
  run.advance_to(10.0);
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump());
  REQUIRE(m["diverged"].get<bool>());
  // A cube (edge 2.4 m) more than its edge deep: by the second step it has fallen 2 g dt^2 = 20 m.
  CHECK(m["diverged_at_s"].get<double>() <= 2.0);
  CHECK(m["slide_off_time_s"].is_null());
  // The paper's stack does not diverge.
  scenes::Run paper = run_scene("stack");
  paper.advance_to(2.0);
  CHECK_FALSE(paper.metrics->report()["diverged"].get<bool>());
}

TEST_CASE("a stack that rocks past 10 deg on landing and stands has not slid off",
          "[scene][stack]") {
  scenes::Overrides o;
  o.set("beta", 0.9);  // a stiff push: the landing tilts a cube by 11 deg for a moment
  scenes::Run run = run_scene("stack", o);
  run.advance_to(6.0);
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump());
  CHECK(m["max_tilt_deg"].get<double>() > 10.0);  // the transient the slide-off must not count
  CHECK(m["slide_off_time_s"].is_null());
  CHECK_FALSE(m["diverged"].get<bool>());
  // Standing at the end: every cube's centre within 0.5 m of the axis.
  for (const Body& b : run.world.bodies()) {
    if (!b.is_static()) CHECK(std::hypot(b.x.x(), b.x.z()) < 0.5);
  }
}

TEST_CASE("intersecting stack at 0.5 s: split comes to rest, baumgarte flies apart",
          "[scene][intersecting_stack]") {
  // The paper's Fig. 7 (b) and (c).
  scenes::Overrides split;
  split.set("push", PushMode::split);
  scenes::Run rest = run_scene("intersecting_stack", split);
  rest.advance_to(0.5);
  int i = 0;
  for (const Body& b : rest.world.bodies()) {
    if (b.is_static()) continue;
    INFO("cube " << i);
    CHECK(b.velocity().norm() < 0.1);
    CHECK(b.x.y() == Approx(1.2 + 2.4 * i).margin(0.02));  // resting heights 1.2, 3.6, ... 10.8
    ++i;
  }
  scenes::Overrides baumgarte;
  baumgarte.set("push", PushMode::baumgarte);
  scenes::Run fly = run_scene("intersecting_stack", baumgarte);
  fly.advance_to(0.5);
  CHECK(fly.world.bodies().back().velocity().norm() > 5.0);
}

TEST_CASE("max_penetration_m is the deepest contact over the whole run in every scene that "
          "reports it", "[scene]") {
  for (const char* name : {"stack", "intersecting_stack", "funnel", "pendulum_grid", "sphere_in_box",
                           "heavy_on_light"}) {
    INFO(name);
    scenes::Run run = run_scene(name);
    double deepest = 0.0;  // m, over the steps so far, up to a divergence (metrics stop there)
    bool diverged = false;
    while (scenes::short_of(run.world, 1.5)) {
      run.step();
      diverged = diverged || scenes::divergence_sign(run.world).has_value();
      if (!diverged) deepest = std::max(deepest, scenes::deepest_contact(run.world));
    }
    const nlohmann::json m = run.metrics->report();
    REQUIRE(m.contains("max_penetration_m"));
    CHECK(m["max_penetration_m"].get<double>() >= deepest);
    // Not trivially: something penetrated on the way.
    CHECK(deepest > 0.0);
  }
}

TEST_CASE("funnel at 10 s: the balls are at rest without deep penetration", "[scene][funnel]") {
  scenes::Run run = run_scene("funnel");
  run.advance_to(10.0);
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump());
  CHECK(m["kinetic_energy_J"].get<double>() < 1e-3);
  CHECK(m["final_penetration_m"].get<double>() < 5e-3);
  // The deepest contact of the run is a ball landing (measured: 0.15 m), less than its radius.
  CHECK(m["max_penetration_m"].get<double>() < 0.5);
  CHECK(m["final_penetration_m"].get<double>() <= m["max_penetration_m"].get<double>());
  // Every ball is inside the funnel (y > |x|, y > |z|, less the penetration) and below its start.
  for (const Body& b : run.world.bodies()) {
    if (b.is_static()) continue;
    CHECK(b.x.y() + 5e-3 > std::abs(b.x.x()) + 0.5 * std::sqrt(2.0));
    CHECK(b.x.y() < 8.0);
  }
}

TEST_CASE("pendulum grid at 10 s: the four boxes stay on top, rods hold", "[scene][pendulum_grid]") {
  scenes::Run run = run_scene("pendulum_grid");
  run.advance_to(10.0);
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump());
  CHECK(m["max_rod_error_m"].get<double>() < 5e-3);
  const auto& bodies = run.world.bodies();
  double mean_y = 0.0;
  for (int i = 1; i <= 25; ++i) mean_y += bodies[static_cast<std::size_t>(i)].x.y() / 25.0;
  int boxes_on_top = 0;
  for (const Body& b : bodies) {
    if (b.shape.kind != ShapeKind::box) continue;
    if (b.x.y() > mean_y + 0.5 && std::abs(b.x.x()) < 2.5 && std::abs(b.x.z()) < 2.5) ++boxes_on_top;
  }
  CHECK(boxes_on_top == 4);
  CHECK(m["shapes_on_top"].get<int>() >= 4);
}

TEST_CASE("pendulum wave: rods hold, phases follow the reference, the wave realigns",
          "[scene][pendulum_wave]") {
  // Tolerances derived for dt = 1/600 s:
  // - semi-implicit Euler runs a harmonic swing fast by (w dt)^2 / 24; the fastest pendulum
  //   (w = 2 pi 100 / 60 s = 10.5 rad/s) gains 1.3e-5 of its 103 swings in 62 s, 0.47 degrees:
  //   the phase error against the reduced-coordinate reference, the largest over the run, is
  //   held to 0.55 degrees (measured 0.49: the next-order terms);
  // - at realignment every pendulum is within that of its ideal phase, so the spread is held to
  //   twice the phase bound, 1 degree;
  // - a 15 degree swing lengthens every period alike by theta0^2 / 16 (0.43 %), so the wave
  //   realigns at T (1 + theta0^2 / 16) = 60.257 s; the next term (11 theta0^4 / 3072) moves it
  //   by 1 ms, so 0.05 s is ample.
  scenes::Run run = run_scene("pendulum_wave");
  run.advance_to(62.0);
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump());
  CHECK(m["max_rod_error_rel"].get<double>() < 1e-3);
  CHECK(m["max_phase_error_deg"].get<double>() < 0.55);
  REQUIRE(m["realign_spread_deg"].is_number());
  CHECK(m["realign_spread_deg"].get<double>() < 1.0);
  const double theta0 = 15.0 * M_PI / 180.0;
  CHECK(m["realign_time_s"].get<double>() == Approx(60.0 * (1.0 + theta0 * theta0 / 16.0)).margin(0.05));
  // No collision detection at all in this scene.
  CHECK(run.world.counters().pairs_tested == 0);
  CHECK(run.world.counters().contacts == 0);
}

TEST_CASE("each scene runs only the stages it needs", "[scene][counters]") {
  SECTION("the stack solves once per step with baumgarte, twice with split") {
    for (const PushMode push : {PushMode::baumgarte, PushMode::split}) {
      scenes::Overrides o;
      o.set("push", push);
      scenes::Run run = run_scene("stack", o);
      run.advance_to(3.0);  // the cubes are resting on each other: every step has contacts
      const std::int64_t before = run.world.counters().solves;
      for (int k = 0; k < 10; ++k) run.step();
      CHECK(run.world.counters().solves - before == (push == PushMode::split ? 20 : 10));
    }
  }
  SECTION("mu = 0 builds no friction rows") {
    scenes::Overrides o;
    o.set("friction", 0.0);
    scenes::Run run = run_scene("stack", o);
    run.advance_to(3.0);
    REQUIRE(!run.world.rows().empty());
    for (const ConstraintRow& r : run.world.rows()) CHECK(r.kind == RowKind::contact);
  }
}

TEST_CASE("each paper scene's bench window is spent doing what the scene exists for",
          "[scene][bench]") {
  // `cps bench` times a scene over Scene::bench. A window where the bodies fly free would time
  // the integrator alone, so: at every step of the window, two movable bodies are in contact,
  // or (a scene of rods) rows are built for its distance constraints.
  for (const scenes::Scene& scene : scenes::paper_scenes()) {
    INFO(scene.name);
    scenes::Run run = scenes::make_run(scene);
    const double dt = run.world.def().dt;
    REQUIRE(scene.bench.start_s >= 0.0);
    REQUIRE(scene.bench.seconds > 0.0);
    run.advance_to(scene.bench.start_s);
    const auto steps = static_cast<int>(std::lround(scene.bench.seconds / dt));
    REQUIRE(steps >= 1);
    const bool rods = !run.world.distances().empty();
    int steps_without_work = 0;
    for (int k = 0; k < steps; ++k) {
      run.step();
      int between_movable = 0;
      for (const Manifold& m : run.world.manifolds()) {
        if (!run.world.body(m.body_a).is_static() && !run.world.body(m.body_b).is_static()) {
          between_movable += m.count;
        }
      }
      const bool working = rods ? run.world.rows().size() >= run.world.distances().size()
                                : between_movable > 0;
      if (!working) ++steps_without_work;
    }
    CHECK(steps_without_work == 0);
  }
}

TEST_CASE("every scene's report compares trajectories at a frame time within its horizon",
          "[scenes][report]") {
  for (const scenes::Scene& s : scenes::all_scenes()) {
    INFO(s.name);
    const double t = s.report_trajectory_time_s();
    CHECK(t > 0.0);
    CHECK(t <= s.report_horizon_s());
    // A whole number of the scene's steps (1/60 s for the paper's): runs at 1, 4 and 16
    // substeps all step onto it exactly, so a trajectory error never holds the motion of a
    // fraction of a step.
    const double steps = t / s.world_def().dt;
    CHECK(std::abs(steps - std::round(steps)) < 1e-9 * steps);
    CHECK_FALSE(s.report.trajectory_reason.empty());
  }
  // The paper's scenes judged by a trajectory have a time chosen for them.
  for (const scenes::Scene& s : scenes::paper_scenes()) {
    INFO(s.name);
    CHECK((s.report.has_reference_solution || s.report.trajectory_time_s.has_value()));
  }
}

namespace {

// Positions (m) of the movable bodies of `name` at time t (s), stepped with PGS, Baumgarte push,
// fixed friction, `iterations` and dt (s).
std::vector<Vec3> positions_at(const char* name, int iterations, double dt, double t) {
  scenes::Overrides o;
  o.set("solver", SolverKind::pgs);
  o.set("push", PushMode::baumgarte);
  o.set("friction_model", FrictionModel::fixed);
  o.set("iterations", iterations);
  o.set("dt", dt);
  scenes::Run run = run_scene(name, o);
  run.advance_to(t);
  std::vector<Vec3> x;
  for (const Body& b : run.world.bodies()) {
    if (!b.is_static()) x.push_back(b.x);
  }
  return x;
}

double rms_between(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double sq = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sq += (a[i] - b[i]).squaredNorm();
  return std::sqrt(sq / static_cast<double>(a.size()));
}

}  // namespace

TEST_CASE("a scene's report headline is its trajectory error only where the trajectory is not "
          "chaotic at its trajectory time", "[scenes][report]") {
  // At the paper's settings (25 iterations, 1/60 s) the trajectory error e is the distance from
  // the report's reference (256 iterations, 16 substeps: report/run.h). Runs at 24 and 26
  // iterations differ from the 25's by about one iteration's solver change: where they end much
  // nearer it than e, e measures the method (here the 60 Hz step); where they end as far from it
  // as e, a change in the last digits decides where the bodies go, and e measures luck.
  for (const char* name : {"stack", "funnel", "pendulum_grid"}) {
    INFO(name);
    const scenes::Scene& s = *scenes::find_scene(name);
    const double t = s.report_trajectory_time_s();
    const std::vector<Vec3> paper = positions_at(name, 25, 1.0 / 60.0, t);
    const double e = rms_between(paper, positions_at(name, 256, 1.0 / 960.0, t));
    const double neighbours = std::max(rms_between(paper, positions_at(name, 24, 1.0 / 60.0, t)),
                                       rms_between(paper, positions_at(name, 26, 1.0 / 60.0, t)));
    INFO("error " << e << " m, neighbours " << neighbours << " m");
    if (s.report.primary_measure == "trajectory_error_m") {
      CHECK(neighbours < 0.2 * e);
    } else {
      CHECK(neighbours >= 0.5 * e);
    }
  }
}

namespace {

// The times (s) a sampled angle passes 0 upwards, by linear interpolation between samples.
void add_crossing(double t0, double a0, double t1, double a1, std::vector<double>& crossings) {
  if (a0 < 0.0 && a1 >= 0.0) crossings.push_back(t0 + (t1 - t0) * (-a0) / (a1 - a0));
}

}  // namespace

TEST_CASE("the pendulum wave's reference step is converged: RK4's error falls as step^4 and "
          "its phase error over 62 s is under 2e-6 deg", "[scene][pendulum_wave]") {
  // The scene's shortest rod (period 60 s / 100, the fastest swing) released at 15 deg, sampled
  // as the scene samples it (every 0.02 s to 62 s). RK4's global error is C h^4, so against a
  // fifth of the step the difference is the error at h to 1 - 1/625, and at 2h it is 16 times
  // that.
  const double h = scenes::kPendulumWaveReferenceStep;
  const scenes::PinnedBallPendulum p{scenes::rod_length_for_period(60.0 / 100.0, 0.02, 10.0), 0.02, 10.0};
  const double w = scenes::slow_mode_frequency(p);
  const double release = 15.0 * M_PI / 180.0;
  const auto phases = [&](double step) {
    std::vector<double> out;
    scenes::PendulumState s{release, release, 0.0, 0.0};
    for (int k = 1; k <= 3100; ++k) {
      s = scenes::integrate_rk4(p, s, 0.02, step);
      const auto [angle, rate] = scenes::centre_angle_and_rate(p, s);
      out.push_back(scenes::swing_phase(angle, rate, w));
    }
    return out;
  };
  const std::vector<double> fine = phases(h / 5.0);
  const auto largest_difference = [&](const std::vector<double>& coarse) {
    double largest = 0.0;  // deg
    for (std::size_t k = 0; k < fine.size(); ++k) {
      largest = std::max(largest, std::abs(std::remainder(coarse[k] - fine[k], 2.0 * M_PI)) * 180.0 / M_PI);
    }
    return largest;
  };
  const double at_h = largest_difference(phases(h));
  const double at_2h = largest_difference(phases(2.0 * h));
  INFO("phase difference against step / 5: " << at_h << " deg at the step, " << at_2h << " deg at twice it");
  CHECK(at_h < 2e-6);
  CHECK(at_h > 0.0);
  CHECK(at_2h / at_h == Approx(16.0).epsilon(0.25));
}

TEST_CASE("the pendulum wave's phase error is a phase: it matches the zero crossings of the "
          "exact pendulum and is not bounded by the swing", "[scene][pendulum_wave]") {
  // At dt = 1/60 s semi-implicit Euler runs the fastest pendulum (100 swings in 60 s) fast by
  // about (w dt)^2 / 24 of its rate: tens of degrees of phase over the 62 s, while the swing
  // angles can differ by at most twice the 15 degree amplitude.
  scenes::Overrides o;
  o.set("dt", 1.0 / 60.0);
  scenes::Run run = run_scene("pendulum_wave", o);
  constexpr double kEnd = 62.0;  // s
  const int n = 49;              // the fastest pendulum
  const DistanceConstraint rod = run.world.distances()[n];
  REQUIRE(rod.body_b == kWorldBody);
  const auto angle = [&] {
    const Vec3 d = run.world.body(rod.body_a).x - rod.local_b;
    return std::atan2(d.z(), -d.y());
  };
  std::vector<double> sim;  // s, upward zero crossings of the simulated swing
  double t0 = run.world.time();
  double a0 = angle();
  while (scenes::short_of(run.world, kEnd)) {
    run.step();
    const double a1 = angle();
    add_crossing(t0, a0, run.world.time(), a1, sim);
    t0 = run.world.time();
    a0 = a1;
  }
  // The exact pendulum's crossings: the reduced model by RK4, sampled every 1 ms.
  const scenes::PinnedBallPendulum p{rod.length, 0.02, 10.0};
  const double release = 15.0 * M_PI / 180.0;
  scenes::PendulumState s{release, release, 0.0, 0.0};
  std::vector<double> exact;
  double r0 = scenes::centre_angle(p, s);
  for (int k = 1; k * 1e-3 <= kEnd; ++k) {
    s = scenes::integrate_rk4(p, s, 1e-3, 1e-4);
    const double r1 = scenes::centre_angle(p, s);
    add_crossing((k - 1) * 1e-3, r0, k * 1e-3, r1, exact);
    r0 = r1;
  }
  REQUIRE(exact.size() >= 100);
  REQUIRE(sim.size() >= exact.size());
  const double period = (exact.back() - exact.front()) / static_cast<double>(exact.size() - 1);
  double largest = 0.0;  // deg, the largest phase error at a crossing
  for (std::size_t k = 0; k < exact.size(); ++k) {
    largest = std::max(largest, 360.0 * std::abs(exact[k] - sim[k]) / period);
  }
  const nlohmann::json m = run.metrics->report();
  INFO(m.dump() << "\nphase error at the zero crossings: " << largest << " deg");
  CHECK(largest > 2.0 * 15.0);  // past what an angle difference can show
  // The metric samples every 0.02 s and takes the worst pendulum: at least this one's, and
  // within a crossing's interpolation (a step, dt / period of a turn) plus 2 % of it.
  const double metric = m["max_phase_error_deg"].get<double>();
  CHECK(metric >= largest - 360.0 * (1.0 / 60.0) / period);
  CHECK(metric <= 1.02 * largest + 360.0 * (1.0 / 60.0) / period);
  CHECK(m["max_angle_error_deg"].get<double>() <= 2.0 * 15.0 + 1.0);
  CHECK(m["final_angle_error_deg"].get<double>() <= 2.0 * 15.0 + 1.0);
}

TEST_CASE("the intersecting stack's recovery time does not move with the run's length",
          "[scene][intersecting_stack]") {
  // Under the split push the stack comes to rest within about 1.2 s; before the hold window the
  // time was "at rest from then to the end", which a later flicker over 0.1 m/s moved (1.93,
  // 2.30, 3.42 and 10.0 s for runs of 2, 3, 4 and 10 s).
  scenes::Overrides split;
  split.set("push", PushMode::split);
  std::vector<double> times;
  for (const double seconds : {3.0, 4.0, 10.0}) {
    scenes::Run run = run_scene("intersecting_stack", split);
    run.advance_to(seconds);
    const nlohmann::json m = run.metrics->report();
    INFO(seconds << " s: " << m.dump());
    REQUIRE(m["recovered"].get<bool>());
    times.push_back(m["recovery_time_s"].get<double>());
    // A recovery held 0.5 s within the run.
    CHECK(times.back() + 0.5 <= seconds + 1e-9);
  }
  CHECK(times[0] == times[1]);
  CHECK(times[0] == times[2]);
  // Under the Baumgarte push the cubes fly apart: no recovery within 1 s.
  scenes::Run thrown = run_scene("intersecting_stack");
  thrown.advance_to(1.0);
  CHECK_FALSE(thrown.metrics->report()["recovered"].get<bool>());
}
