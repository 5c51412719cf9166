// The views of `cps render` and `cps figure` (demos/cps/draw.h): --camera fit keeps every body
// in the picture over the whole run, the planes keep one extent for the whole run, --eye,
// --target and --fov replace the camera's, and every scene's default view shows its bodies.
#include "pictures/draw.h"
#include "options/options.h"
#include "scene_file.h"

#include "cps/render/renderer.h"

#include <catch2/catch.hpp>
#include <unistd.h>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

using namespace cps;
using cps::cli::DrawStyle;
using cps::cli::View;

namespace {

constexpr float kAspect = 16.0f / 9.0f;

// The largest |NDC x| and |NDC y| (1 = the picture's edge) of the corners of every body's
// axis-aligned box, seen with `camera` in a picture of aspect kAspect, as the renderer projects
// (glm::perspective, glm::lookAt); 1e9 if a corner lies behind the eye.
double widest_ndc(const World& world, const render::Camera& camera) {
  const glm::mat4 proj = glm::perspective(glm::radians(camera.fov_y_deg), kAspect, camera.near_m,
                                          camera.far_m);
  const glm::mat4 view = glm::lookAt(camera.eye, camera.target, camera.up);
  double widest = 0.0;
  for (const Body& b : world.bodies()) {
    if (b.is_static()) continue;
    const Vec3 e = b.shape.kind == ShapeKind::box ? Vec3(b.rotation().cwiseAbs() * b.shape.half_extents)
                                                  : Vec3::Constant(b.shape.radius);
    for (int i = 0; i < 8; ++i) {
      const Vec3 c = b.x + Vec3((i & 1) ? e.x() : -e.x(), (i & 2) ? e.y() : -e.y(),
                                (i & 4) ? e.z() : -e.z());
      const glm::vec4 clip = proj * view * glm::vec4(c.x(), c.y(), c.z(), 1.0f);
      if (!(clip.w > 0.0f)) return 1e9;  // behind the eye: out of the picture
      widest = std::max({widest, static_cast<double>(std::abs(clip.x / clip.w)),
                         static_cast<double>(std::abs(clip.y / clip.w))});
    }
  }
  return widest;
}

// The largest widest_ndc over every step of `run` from its start to `seconds` (s): every frame
// of a render shows the world after a whole step.
double widest_over_run(scenes::Run run, const render::Camera& camera, double seconds) {
  double widest = widest_ndc(run.world, camera);
  while (run.world.time() + 0.5 * run.world.def().dt < seconds) {
    run.step();
    widest = std::max(widest, widest_ndc(run.world, camera));
  }
  return widest;
}

DrawStyle style_for(const scenes::Scene& scene, const std::vector<const World*>& worlds,
                    const View& view, double seconds) {
  return cli::resolve_style(scene, worlds, view, kAspect, seconds);
}

// NDC (x, y) of point p seen with `camera` at aspect kAspect; nullopt behind the eye.
std::optional<glm::vec2> ndc(const render::Camera& camera, const Vec3& p) {
  const glm::mat4 proj = glm::perspective(glm::radians(camera.fov_y_deg), kAspect, camera.near_m,
                                          camera.far_m);
  const glm::mat4 view = glm::lookAt(camera.eye, camera.target, camera.up);
  const glm::vec4 clip = proj * view * glm::vec4(p.x(), p.y(), p.z(), 1.0f);
  if (!(clip.w > 0.0f)) return std::nullopt;
  return glm::vec2(clip.x / clip.w, clip.y / clip.w);
}

// The NDC box (lo, hi) of the corners of every box body of `world`: the tower of tower_roll.
std::pair<glm::vec2, glm::vec2> boxes_ndc(const World& world, const render::Camera& camera) {
  glm::vec2 lo(1e9f);
  glm::vec2 hi(-1e9f);
  for (const Body& b : world.bodies()) {
    if (b.is_static() || b.shape.kind != ShapeKind::box) continue;
    const Vec3 e = b.rotation().cwiseAbs() * b.shape.half_extents;
    for (int i = 0; i < 8; ++i) {
      const Vec3 c = b.x + Vec3((i & 1) ? e.x() : -e.x(), (i & 2) ? e.y() : -e.y(),
                                (i & 4) ? e.z() : -e.z());
      const std::optional<glm::vec2> q = ndc(camera, c);
      if (!q) return {glm::vec2(-1e9f), glm::vec2(1e9f)};
      lo = glm::min(lo, *q);
      hi = glm::max(hi, *q);
    }
  }
  return {lo, hi};
}

// A scene file: a tower of ten 1 m boxes and, beside it, a ball of 0.3 m rolling away at 10 m/s
// (40 m in the 4 s of the file), so one body leaves while the rest stands.
const scenes::Scene& tower_roll() {
  static const scenes::Scene* scene = [] {
    std::string bodies = R"({"shape": "plane", "static": true, "normal": [0, 1, 0], "offset_m": 0})";
    for (int i = 0; i < 10; ++i) {
      bodies += ",\n{\"name\": \"box" + std::to_string(i) +
                R"(", "shape": "box", "half_extents_m": [0.5, 0.5, 0.5], "mass_kg": 1, "position_m": [0, )" +
                std::to_string(0.5 + i) + ", 0]}";
    }
    bodies += R"(,
{"name": "ball", "shape": "sphere", "radius_m": 0.3, "mass_kg": 1, "position_m": [-4, 0.3, 2],
 "velocity_mps": [10, 0, 0]})";
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("cps_view_tests_" + std::to_string(::getpid())) / "tower_roll.json";
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path) << R"({"name": "tower_roll", "seconds": 4, "bodies": [)" << bodies << "]}";
    const scenes::Scene* loaded = scenes::load_scene_file(path.string());
    std::filesystem::remove_all(path.parent_path());
    return loaded;
  }();
  REQUIRE(scene != nullptr);
  return *scene;
}

}  // namespace

TEST_CASE("camera fit keeps every cube of the intersecting stack in every frame", "[views]") {
  const scenes::Scene& scene = *scenes::find_scene("intersecting_stack");
  const double seconds = 4.0;
  const scenes::Run run = scenes::make_run(scene);
  View view;
  view.camera = "fit";
  const DrawStyle fit = style_for(scene, {&run.world}, view, seconds);
  // Inside the picture at every step of the 4 s, with the 10 % margin of the fit (the bounding
  // sphere touches the frame at 1 / 1.1 of its half width; boxes inside the sphere stay within).
  CHECK(widest_over_run(scenes::make_run(scene), fit.camera, seconds) < 1.0);
  // The framing as built (--camera auto) loses the cubes the push throws up: the check can fail.
  view.camera = "auto";
  const DrawStyle as_built = style_for(scene, {&run.world}, view, seconds);
  CHECK(widest_over_run(scenes::make_run(scene), as_built.camera, seconds) > 1.0);
  // The scene's own view (the default) keeps them in too.
  view.camera = "preset";
  const DrawStyle preset = style_for(scene, {&run.world}, view, seconds);
  CHECK(widest_over_run(scenes::make_run(scene), preset.camera, seconds) < 1.0);
}

TEST_CASE("camera fit frames every run of a comparison", "[views]") {
  const scenes::Scene& scene = *scenes::find_scene("intersecting_stack");
  const double seconds = 2.0;
  scenes::Overrides split;
  split.set("push", PushMode::split);
  const scenes::Run a = scenes::make_run(scene);
  const scenes::Run b = scenes::make_run(scene, split);
  View view;
  view.camera = "fit";
  const DrawStyle both = style_for(scene, {&a.world, &b.world}, view, seconds);
  CHECK(widest_over_run(scenes::make_run(scene), both.camera, seconds) < 1.0);
  CHECK(widest_over_run(scenes::make_run(scene, split), both.camera, seconds) < 1.0);
  // Framed on the split run alone (the cubes barely move), the Baumgarte run leaves the picture.
  const DrawStyle split_only = style_for(scene, {&b.world}, view, seconds);
  CHECK(widest_over_run(scenes::make_run(scene), split_only.camera, seconds) > 1.0);
}

namespace {

// The framing before the rule of action_bounds, for comparison: the bounding sphere of every
// body over the run (run_bounds), seen along `fit`'s direction at the fit's distance rule.
render::Camera all_bodies_camera(const render::Camera& fit, std::span<const World* const> worlds,
                                 double seconds) {
  const cli::Bounds all = cli::run_bounds(worlds, seconds);
  render::Camera camera = fit;
  const glm::vec3 lo(all.lo.x(), all.lo.y(), all.lo.z());
  const glm::vec3 hi(all.hi.x(), all.hi.y(), all.hi.z());
  const float half_v = glm::radians(0.5f * fit.fov_y_deg);
  const float half_h = std::atan(std::tan(half_v) * kAspect);
  const float distance = 1.1f * 0.5f * glm::length(hi - lo) / std::sin(std::min(half_v, half_h));
  camera.target = 0.5f * (lo + hi);
  camera.eye = camera.target + distance * glm::normalize(fit.eye - fit.target);
  camera.near_m = distance / 50.0f;
  camera.far_m = distance * 50.0f;
  return camera;
}

}  // namespace

TEST_CASE("camera fit frames the bodies that stay in the action, not a ball rolling away",
          "[views]") {
  const scenes::Scene& scene = tower_roll();
  const double seconds = 4.0;
  scenes::Run run = scenes::make_run(scene);
  const World* worlds[] = {&run.world};
  View view;
  view.camera = "fit";
  const DrawStyle fit = cli::resolve_style(scene, worlds, view, kAspect, seconds);
  const render::Camera all = all_bodies_camera(fit.camera, worlds, seconds);
  // The tower's height as a share of the picture's (NDC spans 2), over every step: inside the
  // picture and at least 45 % of its height with the rule; framed on every body (the ball 40 m
  // away at the end) it would be under 30 %, so the check tells the rules apart.
  double least_fit = 1.0;
  double most_all = 0.0;
  double widest = 0.0;
  while (true) {
    const auto [lo, hi] = boxes_ndc(run.world, fit.camera);
    least_fit = std::min(least_fit, 0.5 * (hi.y - lo.y));
    widest = std::max({widest, static_cast<double>(-lo.x), static_cast<double>(hi.x),
                       static_cast<double>(-lo.y), static_cast<double>(hi.y)});
    const auto [alo, ahi] = boxes_ndc(run.world, all);
    most_all = std::max(most_all, 0.5 * (ahi.y - alo.y));
    if (!scenes::short_of(run.world, seconds)) break;
    run.step();
  }
  INFO("tower height share: fit at least " << least_fit << ", all bodies at most " << most_all);
  CHECK(widest < 1.0);
  CHECK(least_fit >= 0.45);
  CHECK(most_all < 0.30);
  // The ball, 40 m away at the end, has left the fitted picture.
  const std::optional<glm::vec2> ball = ndc(fit.camera, run.world.bodies().back().x);
  REQUIRE(ball);
  CHECK(std::abs(ball->x) > 1.0f);
}

TEST_CASE("action_bounds keeps every body as built and drops one far from the rest", "[views]") {
  const scenes::Scene& scene = tower_roll();
  scenes::Run run = scenes::make_run(scene);
  // As built, the median of the centres is (0, 4.5, 0); the boxes lie 0 to 5 m from it, the
  // ball 6.1 m: within 2.5 x the median distance (3 m), so every body is kept ...
  const cli::Bounds built = cli::world_bounds(run.world);
  const cli::Bounds start = cli::action_bounds(run.world, 0.0);
  CHECK(start.lo.x() == Approx(built.lo.x()));
  CHECK(start.hi.y() == Approx(built.hi.y()));
  // ... and after 2 s, the ball more than 10 m away is dropped (the tower alone: x within its
  // half width), unless the floor reaches it.
  run.advance_to(2.0);
  REQUIRE(run.world.bodies().back().x.x() > 10.0);
  const cli::Bounds later = cli::action_bounds(run.world, 0.0);
  CHECK(later.hi.x() < 1.0);
  CHECK(later.hi.y() > 9.5);
  const cli::Bounds floored = cli::action_bounds(run.world, 30.0);
  CHECK(floored.hi.x() == Approx(cli::world_bounds(run.world).hi.x()));
}

TEST_CASE("fit:panel frames each run on its own and fit:frame each time", "[views]") {
  const scenes::Scene& scene = *scenes::find_scene("intersecting_stack");
  const double seconds = 2.0;
  scenes::Overrides split;
  split.set("push", PushMode::split);
  const scenes::Run a = scenes::make_run(scene);
  const scenes::Run b = scenes::make_run(scene, split);
  const std::vector<const World*> worlds = {&a.world, &b.world};
  for (const char* name : {"fit:panel", "fit:frame"}) {
    INFO(name);
    View view;
    view.camera = name;
    const DrawStyle style = style_for(scene, worlds, view, seconds);
    REQUIRE(style.paths.size() == 2);
    // Every body of each run in its own picture at every step.
    for (std::size_t r = 0; r < 2; ++r) {
      scenes::Run run = scenes::make_run(scene, r == 0 ? scenes::Overrides{} : split);
      double widest = widest_ndc(run.world, cli::camera_at(style, r, run.world.time()));
      while (scenes::short_of(run.world, seconds)) {
        run.step();
        widest = std::max(widest, widest_ndc(run.world, cli::camera_at(style, r, run.world.time())));
      }
      CHECK(widest < 1.0);
    }
    // The split run barely moves: its camera stands at most half as far as the thrown
    // Baumgarte run's at the end.
    const float far = glm::length(cli::camera_at(style, 0, seconds).eye - cli::camera_at(style, 0, seconds).target);
    const float near = glm::length(cli::camera_at(style, 1, seconds).eye - cli::camera_at(style, 1, seconds).target);
    CHECK(near < 0.5f * far);
    // In one picture (--overlay) one camera frames both runs.
    view.one_picture = true;
    CHECK(style_for(scene, worlds, view, seconds).paths.size() == (std::string(name) == "fit:frame" ? 1u : 0u));
  }
  // fit:frame zooms out as the cubes fly up: its first camera is nearer than its last.
  View frame;
  frame.camera = "fit:frame";
  const DrawStyle style = style_for(scene, {&a.world}, frame, seconds);
  const auto distance = [&](double t) {
    const render::Camera c = cli::camera_at(style, 0, t);
    return glm::length(c.eye - c.target);
  };
  CHECK(distance(0.0) < 0.5f * distance(seconds));
}

TEST_CASE("track:BODY keeps the body at the picture's centre", "[views]") {
  const scenes::Scene& scene = tower_roll();
  const double seconds = 4.0;
  scenes::Run run = scenes::make_run(scene);
  std::vector<const World*> worlds = {&run.world};
  View view;
  view.camera = "track:ball";
  const DrawStyle style = style_for(scene, worlds, view, seconds);
  REQUIRE(style.paths.size() == 1);
  const render::Camera start = cli::camera_at(style, 0, 0.0);
  // The ball rolls 25 m; the camera's target follows its centre averaged over 0.5 s, which for
  // a steady roll is the centre itself, and off by at most 10 m/s x 0.125 s = 1.25 m in the
  // first and last 0.25 s, where the window is cut short. The distance stays.
  double worst = 0.0;
  while (true) {
    const render::Camera c = cli::camera_at(style, 0, run.world.time());
    const Vec3 x = run.world.bodies().back().x;
    worst = std::max(worst, static_cast<double>(glm::length(c.target - glm::vec3(x.x(), x.y(), x.z()))));
    CHECK(glm::length(c.eye - c.target) == Approx(glm::length(start.eye - start.target)).epsilon(1e-5));
    const std::optional<glm::vec2> q = ndc(c, x);
    REQUIRE(q);
    CHECK(std::abs(q->x) < 0.25f);
    CHECK(std::abs(q->y) < 0.25f);
    if (!scenes::short_of(run.world, seconds)) break;
    run.step();
  }
  CHECK(worst <= 1.3);
  CHECK(run.world.bodies().back().x.x() > 20.0);
  // By index: body 11 is the ball too (the plane is body 0).
  const scenes::Run fresh = scenes::make_run(scene);
  worlds = {&fresh.world};
  const DrawStyle style_fresh = style_for(scene, worlds, view, seconds);
  CHECK(cli::camera_at(style_fresh, 0, 2.0).target == cli::camera_at(style, 0, 2.0).target);
  view.camera = "track:11";
  const DrawStyle by_index = style_for(scene, worlds, view, seconds);
  CHECK(cli::camera_at(by_index, 0, 2.0).target == cli::camera_at(style, 0, 2.0).target);
  // A name that is no body's is refused with the nearest name; an index past the end too.
  view.camera = "track:bal";
  try {
    style_for(scene, worlds, view, seconds);
    FAIL("track:bal was accepted");
  } catch (const cli::UsageError& e) {
    CHECK(std::string(e.what()).find("did you mean 'ball'") != std::string::npos);
  }
  view.camera = "track:12";
  CHECK_THROWS_AS(style_for(scene, worlds, view, seconds), cli::UsageError);
  CHECK(cli::check_camera_name("track:") != "");
  CHECK(cli::check_camera_name("fit:frames").find("fit:frame") != std::string::npos);
  CHECK(cli::check_camera_name("fit:frame") == "");
}

TEST_CASE("a rod's fixed end is drawn as a pin, hidden with the rods", "[views]") {
  const scenes::Scene& scene = *scenes::find_scene("pendulum_grid");
  const scenes::Run run = scenes::make_run(scene);
  std::size_t fixed_ends = 0;
  for (const DistanceConstraint& d : run.world.distances()) {
    for (int body : {d.body_a, d.body_b}) {
      fixed_ends += body == kWorldBody || run.world.bodies()[static_cast<std::size_t>(body)].is_static();
    }
  }
  REQUIRE(fixed_ends > 0);
  std::size_t balls = 0;
  for (const Body& b : run.world.bodies()) balls += b.shape.kind == ShapeKind::sphere;
  DrawStyle style = cli::resolve_style(scene, run.world, View{}, kAspect);
  const render::DrawList with = cli::draw_list(run.world, style);
  CHECK(with.spheres.size() == balls + fixed_ends);
  // Each pin sits on a rod's end that is no body's centre, smaller than the ball it holds.
  std::size_t pins_on_rod_ends = 0;
  for (const render::SphereItem& s : with.spheres) {
    for (const render::LineItem& rod : with.lines) {
      if (s.center == rod.a || s.center == rod.b) ++pins_on_rod_ends;
    }
  }
  CHECK(pins_on_rod_ends >= fixed_ends);
  style.overlays.rods = false;
  CHECK(cli::draw_list(run.world, style).spheres.size() == balls);
}

TEST_CASE("the pendulum wave's row spans at least half the picture's width", "[views]") {
  // The default view of render (16:9) and the one of figure paper's Fig. 10 (3:2): the balls'
  // centres from the first to the last span at least 1 in NDC (half of the picture's width),
  // as built and at 5 s, when the wave has spread.
  const scenes::Scene& scene = *scenes::find_scene("pendulum_wave");
  scenes::Run run = scenes::make_run(scene);
  const DrawStyle style = cli::resolve_style(scene, run.world, View{}, kAspect);
  for (double t : {0.0, 5.0}) {
    run.advance_to(t);
    float lo = 1e9f;
    float hi = -1e9f;
    for (const Body& b : run.world.bodies()) {
      if (b.shape.kind != ShapeKind::sphere) continue;
      const std::optional<glm::vec2> q = ndc(style.camera, b.x);
      REQUIRE(q);
      lo = std::min(lo, q->x);
      hi = std::max(hi, q->x);
    }
    INFO("t = " << t << " s: the row spans NDC x " << lo << " to " << hi);
    CHECK(hi - lo >= 1.0f);
    CHECK(lo > -1.0f);
    CHECK(hi < 1.0f);
  }
}

TEST_CASE("velocity arrows show the push factor's velocity after one step, and none for split",
          "[views]") {
  // After one step of the intersecting stack, the push factor (Sec. 5.3) has put the overlap
  // into the cubes' velocities (several m/s up); the single frame push factor (Sec. 8.1) moved
  // them apart without any, so its arrows stay short (gravity's dt g = 0.16 m/s at most, plus
  // round-off). Each arrow is a shaft and two barbs; the shaft is v x 0.1 s, starting outside
  // the body's bounding sphere on the eye's side.
  const scenes::Scene& scene = *scenes::find_scene("intersecting_stack");
  for (const PushMode push : {PushMode::baumgarte, PushMode::split}) {
    scenes::Overrides o;
    o.set("push", push);
    scenes::Run run = scenes::make_run(scene, o);
    DrawStyle style = cli::resolve_style(scene, run.world, View{}, kAspect);
    style.overlays.rods = false;
    style.overlays.velocities = true;
    CHECK(cli::draw_list(run.world, style).lines.empty());  // at rest as built
    run.step();
    const render::DrawList list = cli::draw_list(run.world, style);
    double longest = 0.0;
    std::size_t moving = 0;
    for (const Body& b : run.world.bodies()) {
      if (b.is_static()) continue;
      const Vec3 v = b.velocity();
      if ((cli::kVelocityArrow_s * v).norm() >= 1e-3) ++moving;
      longest = std::max(longest, v.norm());
      // The shaft of this body: the line whose vector is v x 0.1 s.
      bool found = false;
      for (const render::LineItem& l : list.lines) {
        const glm::vec3 d = l.b - l.a;
        const Vec3 shaft(d.x, d.y, d.z);
        if ((shaft - cli::kVelocityArrow_s * v).norm() < 1e-4) {
          found = true;
          const Vec3 start(l.a.x, l.a.y, l.a.z);
          CHECK((start - b.x).norm() >= b.shape.half_extents.norm());
          const glm::vec3 eye = list.camera.eye;
          CHECK((start - b.x).dot(Vec3(eye.x, eye.y, eye.z) - b.x) > 0.0);
        }
      }
      if ((cli::kVelocityArrow_s * v).norm() >= 1e-3) CHECK(found);
    }
    CHECK(list.lines.size() == 3 * moving);
    INFO("push " << static_cast<int>(push) << ": fastest cube " << longest << " m/s");
    if (push == PushMode::baumgarte) {
      CHECK(longest > 5.0);
    } else {
      CHECK(longest < 0.2);
    }
  }
}

TEST_CASE("contact forces: the ground's equal the stack's change of momentum less its weight, drawn as arrows", "[views]") {
  // Over one step of the paper's push (the first solve's lambda is the whole contact impulse),
  // the forces the ground's contacts put on the bottom cube, F, change the column's momentum P
  // with gravity: F dt = P(t + dt) - P(t) - M g dt, to round-off; forces between cubes cancel
  // in the sum. Near rest (4 s) F is close to the weight.
  const scenes::Scene& scene = *scenes::find_scene("stack");
  scenes::Run run = scenes::make_run(scene);
  DrawStyle style = cli::resolve_style(scene, run.world, View{}, kAspect);
  style.overlays.forces = true;
  CHECK(cli::contact_forces(run.world).empty());  // no step yet: no rows
  CHECK(cli::draw_list(run.world, style).lines.empty());
  run.advance_to(4.0);
  const auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (const Body& b : run.world.bodies()) p += b.p;
    return p;
  };
  const Vec3 before = momentum();
  run.step();
  const Vec3 after = momentum();
  double mass = 0.0;
  for (const Body& b : run.world.bodies()) mass += b.mass;
  const WorldDef& def = run.world.def();
  const std::vector<Vec3> forces = cli::contact_forces(run.world);
  Vec3 from_ground = Vec3::Zero();
  std::size_t k = 0;
  for (const Manifold& m : run.world.manifolds()) {
    for (int i = 0; i < m.count; ++i, ++k) {
      REQUIRE(k < forces.size());
      if (run.world.body(m.body_a).is_static()) from_ground += forces[k];
    }
  }
  CHECK(forces.size() == k);
  const Vec3 expected = (after - before) / def.dt - mass * def.gravity;
  INFO("ground force " << from_ground.transpose() << " N, momentum balance " << expected.transpose() << " N");
  CHECK((from_ground - expected).norm() < 1e-9 * mass * def.gravity.norm());
  CHECK(from_ground.y() == Approx(-mass * def.gravity.y()).epsilon(0.05));
  // An arrow (shaft and two barbs) for each point whose arrow is at least 1 mm.
  style.overlays.rods = false;
  const render::DrawList list = cli::draw_list(run.world, style);
  CHECK(list.lines.size() % 3 == 0);
  CHECK(list.lines.size() >= 3 * 4);
  CHECK(list.lines.size() <= 3 * k);
}

TEST_CASE("run_bounds holds every body at every step and leaves the worlds unchanged", "[views]") {
  const scenes::Scene& scene = *scenes::find_scene("intersecting_stack");
  scenes::Run run = scenes::make_run(scene);
  const World* worlds[] = {&run.world};
  const cli::Bounds bounds = cli::run_bounds(worlds, 1.0);
  CHECK(run.world.time() == 0.0);
  REQUIRE(bounds.any);
  const cli::Bounds start = cli::world_bounds(run.world);
  while (run.world.time() + 0.5 * run.world.def().dt < 1.0) {
    run.step();
    const cli::Bounds now = cli::world_bounds(run.world);
    CHECK((now.lo.array() >= bounds.lo.array()).all());
    CHECK((now.hi.array() <= bounds.hi.array()).all());
  }
  // The cubes rise: the run's bounds reach far above the column as built (its top at 11.6 m).
  CHECK(bounds.hi.y() > start.hi.y() + 5.0);
}

TEST_CASE("the planes keep one square for the whole run", "[views]") {
  const scenes::Scene& scene = *scenes::find_scene("intersecting_stack");
  scenes::Run run = scenes::make_run(scene);
  const DrawStyle style = cli::resolve_style(scene, run.world, View{}, kAspect);
  const render::DrawList first = cli::draw_list(run.world, style);
  run.advance_to(2.0);  // the cubes have flown apart
  const render::DrawList later = cli::draw_list(run.world, style);
  REQUIRE(first.planes.size() == 1);
  REQUIRE(later.planes.size() == 1);
  CHECK(later.planes[0].center_hint == first.planes[0].center_hint);
  CHECK(later.planes[0].half_size == first.planes[0].half_size);
  // Around the bodies as built, at least 3 x the diagonal of the column and 30 m, and at least
  // 40 eye-target distances, so that the ground reaches the horizon.
  const cli::Bounds b = cli::world_bounds(scenes::make_run(scene).world);
  const glm::vec3 centre = 0.5f * (glm::vec3(b.lo.x(), b.lo.y(), b.lo.z()) +
                                    glm::vec3(b.hi.x(), b.hi.y(), b.hi.z()));
  CHECK(glm::length(first.planes[0].center_hint - centre) < 1e-4f);
  CHECK(first.planes[0].half_size >= std::max(30.0, 3.0 * (b.hi - b.lo).norm()));
  CHECK(first.planes[0].half_size >= 40.0f * glm::length(style.camera.eye - style.camera.target));
}

TEST_CASE("eye and target and fov replace the camera's and an eye on the target is refused",
          "[views]") {
  const scenes::Scene& scene = *scenes::find_scene("stack");
  const scenes::Run run = scenes::make_run(scene);
  View view;
  view.eye = Vec3(10.0, 8.0, 20.0);
  view.target = Vec3(0.0, 3.0, 0.0);
  view.fov_y_deg = 30.0;
  const DrawStyle style = cli::resolve_style(scene, run.world, view, kAspect);
  CHECK(style.camera.eye == glm::vec3(10.0f, 8.0f, 20.0f));
  CHECK(style.camera.target == glm::vec3(0.0f, 3.0f, 0.0f));
  CHECK(style.camera.fov_y_deg == 30.0f);
  const float d = glm::length(style.camera.eye - style.camera.target);
  CHECK(style.camera.near_m < d);
  CHECK(style.camera.far_m > d);
  // Only --target: the preset's eye stays.
  View target_only;
  target_only.target = Vec3(1.0, 2.0, 3.0);
  const DrawStyle preset = cli::resolve_style(scene, run.world, View{}, kAspect);
  const DrawStyle moved = cli::resolve_style(scene, run.world, target_only, kAspect);
  CHECK(moved.camera.eye == preset.camera.eye);
  CHECK(moved.camera.target == glm::vec3(1.0f, 2.0f, 3.0f));
  // With fit, a narrower field of view puts the eye farther away.
  View wide;
  wide.camera = "fit";
  View narrow = wide;
  narrow.fov_y_deg = 20.0;
  const DrawStyle w = cli::resolve_style(scene, run.world, wide, kAspect);
  const DrawStyle n = cli::resolve_style(scene, run.world, narrow, kAspect);
  CHECK(glm::length(n.camera.eye - n.camera.target) >
        1.5f * glm::length(w.camera.eye - w.camera.target));
  View same;
  same.eye = Vec3(1.0, 2.0, 3.0);
  same.target = Vec3(1.0, 2.0, 3.0);
  CHECK_THROWS_AS(cli::resolve_style(scene, run.world, same, kAspect), cli::UsageError);
}

#ifndef CPS_VIEW_TESTS_NO_GL
namespace {

// The share of the picture (0..1) the bodies of `world` cover in `style`'s view: the world is
// drawn with every box and sphere in pure magenta and without rods, and the pixels whose red
// and blue both exceed green by 40 (of 255) are counted: the ground (grey, r = g = b), its
// shadows (darker grey) and the sky (0.86, 0.90, 0.95: green above red) never pass, shaded
// magenta always does (green stays 0), also seen through the funnel's translucent walls.
double body_share(render::Renderer& renderer, const World& world, const DrawStyle& style) {
  render::DrawList list = cli::draw_list(world, style);
  list.lines.clear();
  for (render::BoxItem& b : list.boxes) b.color = glm::vec3(1.0f, 0.0f, 1.0f);
  for (render::SphereItem& s : list.spheres) s.color = glm::vec3(1.0f, 0.0f, 1.0f);
  const render::Image image = renderer.draw(list);
  long long covered = 0;
  for (std::size_t i = 0; i + 2 < image.pixels.size(); i += 3) {
    const int r = image.pixels[i];
    const int g = image.pixels[i + 1];
    const int b = image.pixels[i + 2];
    if (r - g > 40 && b - g > 40) ++covered;
  }
  return static_cast<double>(covered) / (image.width * image.height);
}

}  // namespace

// Every listed scene's default view (--camera preset, 16:9) at 64x36 pixels shows its bodies:
// they cover at least 1 % of the picture (23 of 2304 pixels: a subject seen clearly, not a
// speck; a picture that shows only a wall, the underside of the funnel or empty sky gives 0).
// The scaled scenes are checked at N = 1, 100 and the family's largest size (40, 20000, 20000,
// 20000, 100) as built (t = 0); the paper and stress scenes as built and at the end of their
// default run. Exceptions, by geometry, each with its own bound:
// - stack_N: the column is 2.4 m wide and about 3 N m tall, so a 16:9 view that holds it covers
//   at most 2.4 / (3 N x 16 / 9) of the picture (0.9 % at N = 40): at least half that bound.
// - intersecting_stack: its default view holds the cubes' whole 4 s flight (up to about 55 m
//   high, checked above), so five 2.4 m cubes cover little of it: at least 0.2 %.
// - lines of small balls: chain_20 (a 20-ball chain seen whole while it swings),
//   pendulum_wave_1 (one 4 cm ball on a 0.35 m rod) and heavy_rope (20 balls of 10 cm and a
//   0.6 m block on a 7 m rope): at least 0.05 % (two pixels: seen).
// - random at the end of its run: bodies thrown at up to 50 m/s have left any view that shows
//   them at a readable size (--camera fit frames them); checked as built only.
TEST_CASE("every scene's default view shows its bodies", "[views][render]") {
  render::Renderer renderer(64, 36);
  std::vector<std::pair<std::string, double>> cases;  // scene name, time (s)
  for (const scenes::Scene& s : scenes::all_scenes()) {
    cases.emplace_back(std::string(s.name), 0.0);
    // The long runs (10,000 steps, stack_20_long and pyramid_20_rows_long): at 20 s, after the
    // stack's fall at 4 s and while the pyramid stands; their whole run (40 s of the pyramid)
    // showed its bodies too when measured, but costs the test most of its time.
    const bool long_run = s.name.size() > 5 && s.name.substr(s.name.size() - 5) == "_long";
    cases.emplace_back(std::string(s.name), long_run ? 20.0 : s.default_seconds);
  }
  const std::array<std::pair<const char*, int>, 5> families = {
      {{"stack", 40}, {"pyramid", 20000}, {"funnel", 20000}, {"pendulum_wave", 20000},
       {"pendulum_grid", 100}}};
  for (const auto& [family, largest] : families) {
    for (int n : {1, 100, largest}) {
      if (n > largest) continue;
      cases.emplace_back(std::string(family) + "_" + std::to_string(n), 0.0);
    }
  }
  for (const auto& [name, t] : cases) {
    const scenes::Scene* scene = scenes::find_scene(name);
    REQUIRE(scene != nullptr);
    scenes::Run run = scenes::make_run(*scene);
    const DrawStyle style = cli::resolve_style(*scene, run.world, View{}, kAspect);
    run.advance_to(t);
    const double share = body_share(renderer, run.world, style);
    if (name == "random" && t > 0.0) continue;
    double least = 0.01;
    if (name.rfind("stack_", 0) == 0 && name.find("dt") == std::string::npos) {
      const int n = std::stoi(name.substr(6));
      least = std::min(least, 0.5 * 2.4 / (3.0 * n * 16.0 / 9.0));
    }
    if (name == "intersecting_stack") least = 0.002;
    if (name == "chain_20" || name == "pendulum_wave_1" || name == "heavy_rope") least = 0.0005;
    INFO(name << " at t = " << t << " s: bodies cover " << 100.0 * share << " % (at least "
              << 100.0 * least << " %)");
    CHECK(share >= least);
  }
}

// The rows of the picture (as a share of its height) between the first and the last that hold
// a magenta pixel, drawn as body_share draws: the bodies' height in the picture.
double body_height_share(render::Renderer& renderer, const render::DrawList& drawn) {
  render::DrawList list = drawn;
  list.lines.clear();
  list.spheres.clear();  // tower_roll's ball: only the tower is measured
  for (render::BoxItem& b : list.boxes) b.color = glm::vec3(1.0f, 0.0f, 1.0f);
  const render::Image image = renderer.draw(list);
  int first = -1;
  int last = -1;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::size_t i = 3 * (static_cast<std::size_t>(y) * image.width + x);
      const int r = image.pixels[i];
      const int g = image.pixels[i + 1];
      const int b = image.pixels[i + 2];
      if (r - g > 40 && b - g > 40) {
        if (first < 0) first = y;
        last = y;
        break;
      }
    }
  }
  return first < 0 ? 0.0 : static_cast<double>(last - first + 1) / image.height;
}

TEST_CASE("camera fit draws the tower a ball rolls away from at least 45 % of the picture tall",
          "[views][render]") {
  // Measured from the image (160x90): at 0, 2 and 4 s the tower of tower_roll spans at least
  // 45 % of the picture's height under fit; framed on every body (the ball 25 m away at the end),
  // under 30 %.
  render::Renderer renderer(160, 90);
  const scenes::Scene& scene = tower_roll();
  scenes::Run run = scenes::make_run(scene);
  const World* worlds[] = {&run.world};
  View view;
  view.camera = "fit";
  const DrawStyle fit = cli::resolve_style(scene, worlds, view, kAspect, 4.0);
  DrawStyle all = fit;
  all.camera = all_bodies_camera(fit.camera, worlds, 4.0);
  for (double t : {0.0, 2.0, 4.0}) {
    run.advance_to(t);
    const double with_fit = body_height_share(renderer, cli::draw_list(run.world, fit));
    const double with_all = body_height_share(renderer, cli::draw_list(run.world, all));
    INFO("t = " << t << " s: the tower spans " << 100.0 * with_fit << " % of the height under fit, "
                << 100.0 * with_all << " % framed on every body");
    CHECK(with_fit >= 0.45);
    CHECK(with_fit < 1.0);
    CHECK(with_all < 0.30);
  }
}
#endif
