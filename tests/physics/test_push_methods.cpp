// The push methods side by side (--push baumgarte, split, split-impulse, soft, ngs, tgs, xpbd;
// engine/src/push/): each recovers the intersecting stack without throwing
// its cubes, holds a resting box still, and pulls a stretched rod back to its length.
#include "scene.h"
#include "state_hash.h"
#include "stress/stress.h"

#include "cps/parameters.h"
#include "cps/world.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

using namespace cps;

namespace {

constexpr double kG = 10.0;  // m/s^2, the scenes' gravity

// A value that is not finite counts as infinite, so that a run that blew up fails every bound
// below (std::max would drop a NaN).
double finite_or_inf(double v) { return std::isfinite(v) ? v : kInfinity; }

double largest_speed(const World& world) {
  double v = 0.0;
  for (const Body& b : world.bodies()) {
    if (!b.is_static()) v = std::max(v, finite_or_inf(b.velocity().norm()));
  }
  return v;
}

}  // namespace

TEST_CASE("every push method but the paper's Baumgarte recovers the intersecting stack without "
          "throwing a cube", "[push_methods]") {
  // The five cubes (half extent 1.2 m) start with 0.4 m overlaps, the bottom one 1.2 m into the
  // ground; at rest their centres are at 1.2, 3.6, 6.0, 8.4, 10.8 m. Bounds on the peak speed of
  // any cube over 4 s, at the scene's own (the paper's) settings:
  // - split, split-impulse, ngs keep the push out of the stored momenta, so a cube's speed
  //   comes from gravity alone, and the contacts stop it as it lands on a cube the push has
  //   lifted: below 1 m/s, the speed of a 5 cm fall (sqrt(2 g 0.05)), far below Baumgarte's
  //   (the push beta d / dt = 4.8 m/s for the 0.4 m overlaps, kept in the velocity: measured 30
  //   m/s at the top of the stack, the paper's Fig. 7 b);
  // - soft pushes each overlap out at most at contact_push_max_speed (3 m/s, Box2D v3's limit)
  //   and its relax solve takes that speed back out of the momenta, not all of it within the
  //   sweeps: below that limit.
  // Coming to rest is checked as Bullet and Box2D run these methods, warm started (factor 1)
  // with a 5 mm penetration slop: at the paper's settings (no warm start, no slop) the resting
  // contacts are pushed to depth 0, break and re-form (a jolt of about g dt = 0.17 m/s now and
  // then), and without warm starting 25 sweeps leave a 5-high column sinking and shearing in
  // the split impulse and ngs, whose velocity solve has no push to make up for it (docs/findings.md, "The
  // push factor among its rivals"). From 3 s to 4 s every cube is then slower than 0.01 m/s and
  // within 3.5 cm of its height (each of the five contacts under it may sit up to the slop deep,
  // 2.5 cm at the top, and the soft contacts give a little more under the column's weight).
  const double rest[] = {1.2, 3.6, 6.0, 8.4, 10.8};
  const scenes::Scene* scene = scenes::find_scene("intersecting_stack");
  REQUIRE(scene != nullptr);
  for (const Choice& choice : parameter("push").choices) {
    const auto push = static_cast<PushMode>(choice.value);
    for (const bool as_sources_run : {false, true}) {
      INFO("push " << choice.name << (as_sources_run ? ", warm start 1, slop 5 mm" : ""));
      scenes::Overrides o;
      o.set("push", push);
      if (as_sources_run) {
        o.set("warm_start", 1.0);
        o.set("penetration_slop", 0.005);
      }
      scenes::Run run = scenes::make_run(*scene, o);
      double peak = 0.0;
      double late_speed = 0.0;
      double late_height_error = 0.0;
      while (run.world.time() < 4.0 - 1e-9) {
        run.step();
        peak = std::max(peak, largest_speed(run.world));
        if (run.world.time() >= 3.0 - 1e-9) {
          late_speed = std::max(late_speed, largest_speed(run.world));
          int k = 0;
          for (const Body& b : run.world.bodies()) {
            if (b.is_static()) continue;
            late_height_error =
                std::max(late_height_error, finite_or_inf(std::abs(b.x.y() - rest[k++])));
          }
        }
      }
      INFO("peak speed " << peak << " m/s, from 3 s: speed " << late_speed
                         << " m/s, height error " << late_height_error << " m");
      if (push == PushMode::baumgarte) {
        CHECK(peak > 4.8);  // the push kept in the velocity throws the cubes
        continue;
      }
      // tgs keeps its push (at most max_depenetration_speed) in the momenta through the
      // substeps of a step, so a cube's positions may overshoot by up to that speed times dt
      // before the relax takes it out; it then falls back at most that far:
      // sqrt(2 g v_max dt) (1.8 m/s at 10 m/s and dt = 1/60 s). xpbd pushes the overlaps out on
      // positions alone (pre-stabilisation), so its bound is split's.
      const WorldDef& d = run.world.def();
      const double bound = push == PushMode::soft  ? d.contact_push_max_speed
                           : push == PushMode::tgs ? std::sqrt(2.0 * kG * d.max_depenetration_speed * d.dt)
                                                   : std::sqrt(2.0 * kG * 0.05);
      CHECK(peak < bound);
      if (as_sources_run) {
        CHECK(late_speed < 0.01);
        CHECK(late_height_error < 0.035);
      }
    }
  }
}

TEST_CASE("a resting box does not jitter under any push method", "[push_methods]") {
  // A 1 m cube of 1 kg set down touching the ground, at the paper's settings with a 5 mm
  // penetration slop (Box2D's linear slop). Without it every method drives the depth to 0 (a
  // converged solve cancels gravity within the step, so nothing sinks the box back), the
  // collision drops the corners that reach 0, and about once a second the box falls a step onto
  // an edge: a jolt of 0.05 to 0.15 m/s, in all five methods (docs/findings.md, "The push factor among its
  // rivals"). A step of free fall gives g dt = 0.17 m/s; a box that keeps its four contacts moves
  // at the solver's residual. Bound: below 1 mm/s from 1 s to 3 s.
  for (const Choice& choice : parameter("push").choices) {
    const auto push = static_cast<PushMode>(choice.value);
    INFO("push " << choice.name);
    WorldDef def;  // the paper's settings
    def.push = push;
    def.penetration_slop = 0.005;
    World world(def);
    world.add_body(BodyDef{.shape = Shape::plane(Vec3::UnitY(), 0.0), .is_static = true});
    BodyDef box;
    box.shape = Shape::box(Vec3::Constant(0.5));
    box.mass = 1.0;
    box.position = Vec3(0.0, 0.5, 0.0);
    world.add_body(box);
    double late = 0.0;
    while (world.time() < 3.0 - 1e-9) {
      world.step();
      if (world.time() >= 1.0 - 1e-9) late = std::max(late, finite_or_inf(world.body(1).velocity().norm()));
    }
    INFO("largest speed from 1 s: " << late << " m/s, height " << world.body(1).x.y() << " m");
    CHECK(late < 1e-3);
    CHECK(std::abs(world.body(1).x.y() - 0.5) < 0.01);  // resting on the ground, the slop deep
  }
}

TEST_CASE("a stretched rod returns toward its length under every push method", "[push_methods]") {
  // A 1 kg ball on a 1 m rod from a fixed point, without gravity, started at 1.1 m (10 cm too
  // long) and at rest. Each method corrects the error: Baumgarte, split and split-impulse by
  // beta = 0.2 of it per step (0.8^30 of it left after 0.5 s), soft as a 60 Hz spring with
  // damping ratio 2 (time constant about 1 / (2 pi 60 (2 - sqrt 3)) = 0.01 s), ngs in full each
  // position iteration. Bound: after 0.5 s less than a tenth of the error is left, and it never
  // grows above the start.
  for (const Choice& choice : parameter("push").choices) {
    const auto push = static_cast<PushMode>(choice.value);
    INFO("push " << choice.name);
    WorldDef def;
    def.push = push;
    def.gravity = Vec3::Zero();
    World world(def);
    BodyDef ball;
    ball.shape = Shape::sphere(0.1);
    ball.mass = 1.0;
    ball.position = Vec3(1.1, 0.0, 0.0);
    world.add_body(ball);
    world.add_distance(DistanceConstraint{.body_a = 0, .local_a = Vec3::Zero(), .body_b = kWorldBody,
                                          .local_b = Vec3::Zero(), .length = 1.0});
    const double initial = 0.1;
    double largest = 0.0;
    while (world.time() < 0.5 - 1e-9) {
      world.step();
      largest = std::max(largest, finite_or_inf(std::abs(world.body(0).x.norm() - 1.0)));
    }
    const double left = std::abs(world.body(0).x.norm() - 1.0);
    INFO("error left after 0.5 s: " << left << " m; largest: " << largest << " m");
    CHECK(left < 0.1 * initial);
    CHECK(largest <= initial * (1.0 + 1e-9));
  }
}

TEST_CASE("xpbd steps a chain as Mueller et al.'s Algorithm 2 does", "[push_methods][xpbd]") {
  // chain_20 (20 balls of 0.5 kg on 0.3 m rods centre to centre, the first from a fixed point,
  // released horizontally) under --push xpbd at its default 20 substeps, against the step of
  // Mueller et al. 2020 (Algorithm 2, Sec. 3.3) written out here for balls on rods: each
  // substep of h = dt / 20 moves every ball by v += g h, x += v h, makes one Gauss-Seidel pass
  // over the rods in order (C = |x_b - x_a| - l along their axis, each ball moved by its share
  // 1/m over the pair's 1/m_a + 1/m_b; rigid rods: no compliance), then sets v = (x - x_prev) /
  // h. A correction at a ball's centre turns nothing, and the chain has no contacts, so nothing
  // else of the step acts. Only the rounding of the two programs may differ: after 5 s of the
  // whip the balls agree within 1e-6 m (measured: to the last bit here, and within 3.5e-10 m of
  // the source's own PBD.js, docs/findings.md), where a second rod pass a substep moves them by
  // 0.65 m.
  WorldDef def = scenes::chain_world_def();
  def.push = PushMode::xpbd;
  World world(def);
  scenes::populate_chain_20(world);
  const int substeps = def.xpbd_substeps;
  REQUIRE(substeps == 20);
  const std::vector<DistanceConstraint> rods = world.distances();
  std::vector<Vec3> x;
  std::vector<Vec3> v;
  for (const Body& b : world.bodies()) {
    x.push_back(b.x);
    v.push_back(b.velocity());
  }
  const double h = def.dt / substeps;
  const int steps = 300;
  for (int step = 0; step < steps; ++step) {
    world.step();
    for (int k = 0; k < substeps; ++k) {
      const std::vector<Vec3> x_prev = x;
      for (std::size_t i = 0; i < x.size(); ++i) {
        v[i] += def.gravity * h;
        x[i] += v[i] * h;
      }
      for (const DistanceConstraint& rod : rods) {
        const auto a = static_cast<std::size_t>(rod.body_a);
        const bool fixed = rod.body_b == kWorldBody;
        const Vec3 pb = fixed ? rod.local_b : x[static_cast<std::size_t>(rod.body_b)];
        const Vec3 d = pb - x[a];
        const double length = d.norm();
        const Vec3 n = d / length;
        const double w_a = world.body(rod.body_a).inv_mass;
        const double w_b = fixed ? 0.0 : world.body(rod.body_b).inv_mass;
        const double dlambda = -(length - rod.length) / (w_a + w_b);
        x[a] -= w_a * dlambda * n;
        if (!fixed) x[static_cast<std::size_t>(rod.body_b)] += w_b * dlambda * n;
      }
      for (std::size_t i = 0; i < x.size(); ++i) v[i] = (x[i] - x_prev[i]) / h;
    }
  }
  double largest = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    largest = std::max(largest, finite_or_inf((world.body(static_cast<int>(i)).x - x[i]).norm()));
  }
  INFO("largest distance between the two runs' balls after " << steps << " steps: "
                                                               << largest << " m");
  CHECK(largest < 1e-6);
}

TEST_CASE("xpbd keeps the paper's stack on its column with its source's static friction",
          "[push_methods][xpbd]") {
  // Five cubes resting on each other under static friction (mu 0.5 against no sideways load)
  // should not move at all. One sweep a substep leaves each face a little shear; static friction
  // measured from the start of the step (E. Catto's Solver2D, the same paper in 2D) undoes it
  // within the step, measured from the start of the substep it stays and adds up. Measured over
  // 60 s after the landing (creep_m, the largest sideways move of a cube from 3 s): 0.031 m with
  // the defaults (Solver2D's 2D column of the same boxes: 0.008 m), 0.34 m measured from the
  // substep's start, and the stack leaves its column at 67 s with each point's friction right
  // after its normal as well. Bound: 0.1 m, a twelfth of the half edge, under a third of what
  // the substep anchor gives.
  const scenes::Scene* scene = scenes::find_scene("stack");
  REQUIRE(scene != nullptr);
  for (const char* anchor : {"step", "substep"}) {
    INFO("anchor " << anchor);
    scenes::Overrides o;
    o.set("push", PushMode::xpbd);
    o.set("xpbd_friction_anchor", std::string(anchor) == "step" ? XpbdFrictionAnchor::step
                                                                 : XpbdFrictionAnchor::substep);
    scenes::Run run = scenes::make_run(*scene, o);
    run.advance_to(60.0);
    const nlohmann::json m = run.metrics->report();
    INFO(m.dump());
    REQUIRE(m["creep_m"].is_number());
    const double creep = m["creep_m"].get<double>();
    if (std::string(anchor) == "step") {
      CHECK(creep < 0.1);
      CHECK(m["slide_off_time_s"].is_null());
    } else {
      CHECK(creep > 0.1);  // the substep anchor is the one that lets the column walk
    }
  }
}

TEST_CASE("every push method has its row, and its row says what its steps do",
          "[push_methods][parameters]") {
  // The row of each push choice (PushTraits) is what the work estimate, the energy advice, the
  // comparisons and World::step read: checked against the table and against the steps
  // themselves. A method whose row says it solves A lambda = b solves it every step of a pile; one
  // whose row says it does not never does (World::step prepares no solver for it).
  const scenes::Scene* scene = scenes::find_scene("pyramid_10");
  REQUIRE(scene != nullptr);
  for (const Choice& c : parameter("push").choices) {
    CAPTURE(c.name);
    REQUIRE(c.push != nullptr);
    const PushTraits& traits = *c.push;
    CHECK(&push_traits(static_cast<PushMode>(c.value)) == &traits);
    CHECK(traits.make != nullptr);
    CHECK(traits.push_in_momenta == !traits.energy_rise_cause.empty());
    WorldDef def;
    def.push = static_cast<PushMode>(c.value);
    if (traits.substeps.empty()) {
      CHECK(push_substeps(def) == 1);
    } else {
      const Parameter* substeps = find_parameter(traits.substeps);
      REQUIRE(substeps != nullptr);
      CHECK(substeps->type == ParameterType::integer);
      CHECK(substeps->min >= 1.0);
      substeps->set(def, 7);
      CHECK(push_substeps(def) == 7);
    }
    scenes::Run run = scenes::make_run(*scene);
    WorldDef stepped = run.world.def();
    stepped.push = def.push;
    run.world.set_def(stepped);
    for (int k = 0; k < 4; ++k) run.world.step();
    std::vector<Vec3> before;
    for (const Body& b : run.world.bodies()) before.push_back(b.x);
    run.world.step();
    CHECK(run.world.counters().rows > 0);
    // A push in the rows' right-hand side moves no body past its velocity: x2 - x1 = v2 dt, to
    // round-off of the positions (the stress scenes measure its work on the rows for that reason).
    if (traits.push_in_rows) {
      CHECK(traits.push_in_momenta);
      CHECK(traits.solves_system);
      double beyond = 0.0;
      for (std::size_t i = 0; i < before.size(); ++i) {
        const Body& b = run.world.bodies()[i];
        beyond = std::max(beyond, (b.x - before[i] - b.velocity() * stepped.dt).norm());
      }
      CHECK(beyond <= 1e-12);
    }
    if (traits.solves_system) {
      CHECK(run.world.counters().solves >= 5);
    } else {
      CHECK(run.world.counters().solves == 0);
    }
  }
  // Only the push parameter's choices carry a row.
  for (const Parameter& p : world_parameters()) {
    if (p.name == "push") continue;
    for (const Choice& c : p.choices) CHECK(c.push == nullptr);
  }
}

TEST_CASE("stage timing accounts for a step's time once, by stage, and changes no result",
          "[push_methods][stages]") {
  // The stages are disjoint intervals inside the steps, so their sum is bounded by the wall time
  // of the steps around them; each is >= 0 (other up to the round-off of the subtraction that
  // makes it); a method's own stages are seen (all but the paper's methods' relax: one solve);
  // and timing reads a clock, never the physics: the state is bit for bit that of a run without.
  const scenes::Scene* scene = scenes::find_scene("pyramid_100");
  REQUIRE(scene != nullptr);
  for (const char* push : {"baumgarte", "split", "soft", "tgs", "xpbd"}) {
    CAPTURE(push);
    scenes::Run timed = scenes::make_run(*scene);
    WorldDef def = timed.world.def();
    def.push = static_cast<PushMode>(parameter("push").find_choice(push)->value);
    timed.world.set_def(def);
    scenes::Run plain = scenes::make_run(*scene);
    plain.world.set_def(def);
    CHECK(timed.world.stage_times().total() == 0.0);  // never turned on
    timed.world.set_stage_timing(true);
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < 20; ++k) timed.world.step();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (int k = 0; k < 20; ++k) plain.world.step();
    const StageTimes t = timed.world.stage_times();
    CHECK(t.total() <= wall);
    for (const double s : {t.collide, t.rows, t.prepare, t.solve, t.relax, t.integrate, t.store}) {
      CHECK(s >= 0.0);
    }
    CHECK(t.other >= -1e-9);
    CHECK(t.collide > 0.0);
    CHECK(t.rows > 0.0);
    CHECK(t.integrate > 0.0);
    const std::string p = push;
    if (p != "xpbd") CHECK(t.solve > 0.0);
    if (p == "split" || p == "soft" || p == "tgs") CHECK(t.relax > 0.0);
    if (p == "baumgarte") CHECK(t.relax == 0.0);
    CHECK(scenes::state_hash(timed.world) == scenes::state_hash(plain.world));
    // Turned off, the sums stay; turned on again, they start from 0.
    timed.world.set_stage_timing(false);
    timed.world.step();
    CHECK(timed.world.stage_times().collide == t.collide);
    timed.world.set_stage_timing(true);
    CHECK(timed.world.stage_times().total() == 0.0);
  }
}

TEST_CASE("a push method's runs are bit for bit the same under every value of a setting it does "
          "not read", "[push_methods][parameters]") {
  // Each push method's row (PushTraits::reads, and solves_system for the assembly and the row
  // precision, which only the solve of A lambda = b uses) says which settings of the solve it
  // reads; cps's comparisons, its report and the state-hash check skip the runs that differ
  // only in the others. So each other value must give the same state hash as the scene's own,
  // on a pile with friction and on a chain of rods.
  struct Unread {
    const char* name;
    bool (*unread)(const PushTraits&);
  };
  const Unread settings[] = {
      {"solver", [](const PushTraits& t) { return !t.reads.solver; }},
      {"assembly", [](const PushTraits& t) { return !t.solves_system; }},
      {"row_precision", [](const PushTraits& t) { return !t.solves_system; }},
      {"friction_model", [](const PushTraits& t) { return !t.reads.friction_model; }},
      {"warm_start", [](const PushTraits& t) { return !t.reads.warm_start; }},
  };
  int compared = 0;
  for (const char* scene_name : {"pyramid_10", "chain_20"}) {
    const scenes::Scene* scene = scenes::find_scene(scene_name);
    REQUIRE(scene != nullptr);
    for (const Choice& c : parameter("push").choices) {
      REQUIRE(c.push != nullptr);
      const auto run = [&](const Parameter* p, const ParameterValue* v) {
        scenes::Run r = scenes::make_run(*scene);
        WorldDef def = r.world.def();
        def.push = static_cast<PushMode>(c.value);
        if (p != nullptr) p->set(def, *v);
        r.world.set_def(def);
        for (int k = 0; k < 60; ++k) r.world.step();
        // Equal hashes of two blown-up runs would prove nothing: every state stays finite.
        for (const Body& b : r.world.bodies()) {
          REQUIRE(b.x.allFinite());
          REQUIRE(b.velocity().allFinite());
        }
        return scenes::state_hash(r.world);
      };
      const std::uint64_t base = run(nullptr, nullptr);
      for (const Unread& s : settings) {
        if (!s.unread(*c.push)) continue;
        const Parameter& p = parameter(s.name);
        std::vector<ParameterValue> values;
        if (p.type == ParameterType::choice) {
          for (const Choice& v : p.choices) values.emplace_back(v.value);
        } else {
          values = {ParameterValue(0.0), ParameterValue(0.5), ParameterValue(1.0)};
        }
        for (const ParameterValue& v : values) {
          CAPTURE(scene_name, c.name, s.name, p.format(v));
          CHECK(run(&p, &v) == base);
          ++compared;
        }
      }
    }
  }
  // soft, xpbd and avbd each leave some settings unread (a table where every method read every
  // setting would leave this test nothing to compare).
  CHECK(compared > 0);
}
