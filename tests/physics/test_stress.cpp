// Stress scenes: stiff and extreme cases. Each test states the bound it checks and where
// the bound comes from. Floating point exceptions are trapped (fp_trap.cpp): a NaN, an overflow
// or a division by zero anywhere in a step aborts the test case.
//
//   build/tests/cps_tests "[stress]"                               all of them (about 5 s)
//   CPS_RANDOM_SEEDS=10000 build/tests/cps_tests "[random]"        the random piles, 10000 seeds
//                                                                  (default 200; ~4 minutes)
//
// Energies are E = KE + PE with PE = -m g . x (J). The energy bound used throughout is derived in
// demos/scenes/stress/stress.h (EnergyTracker): over a step the rows change E by
// dt lambda . (J v2) - 1/2 |v2 - v1|^2_M, and a converged solve makes lambda_r (j_r . v2) the
// push work lambda_r t_r for contacts and rods and <= 0 for friction; so
//   E(t) <= E(0) + W(t) + R(t)
// with W the push work summed over the steps (dt sum max(0, lambda t) with baumgarte; the lift
// -m g . dx_push of the single frame push factor with split) and R the rotation term of boxes
// whose inertia is not isotropic (0 for spheres and cubes). Nothing else may add energy. It is
// checked over the run and, tighter, step by step (dE <= dW + dR: a step's own dissipation
// -1/2 |v2 - v1|^2_M cannot hide a gain made in another step).
#include "scene.h"
#include "stress/mass_ratio.h"
#include "stress/stress.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cfenv>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>
#include <string>

using namespace cps;

namespace {

constexpr double kG = 10.0;          // m/s^2, |g| of every scene
constexpr double kPaperDt = 1.0 / 60.0;
constexpr double kPaperBeta = 0.2;
// The Baumgarte steady-state ceiling g dt^2 / beta (m) at the paper's settings: each step gravity
// sinks a resting pair by at most g dt^2 if the solver supplied none of the missing support, and
// the push recovers beta d per step, so d settles at or below g dt^2 / beta = 13.9 mm.
constexpr double kBaumgarteCeiling = kG * kPaperDt * kPaperDt / kPaperBeta;

const scenes::Scene& scene(const char* name) {
  const scenes::Scene* s = scenes::find_scene(name);
  REQUIRE(s != nullptr);
  return *s;
}

// Tolerance of the energy bound (J): the solve stops after a fixed number of sweeps, so the
// complementarity lambda_r (j_r . v2) = lambda_r t_r holds only up to the solver's residual, and
// E is a sum rounded at ~1e-16 of its terms. Both are held to 2e-5 of the energies involved
// (max |E|, W, R, plus 1 J). Measured per step over 10000 random piles: at most 1.6e-7 of that
// with baumgarte and 7.0e-6 with split (seed 3350: a 386 kg box on a 0.12 kg stick; with 400
// sweeps instead of 25 it falls to 3e-15, so it is the solver's residual); 2e-9 in the stress
// scenes. Over the run the bound has the dissipation as margin besides (never above 0).
double energy_tolerance(const scenes::EnergyTracker& e) {
  return 2e-5 * (std::max(std::abs(e.initial()), std::abs(e.max())) + e.push_work() +
                 e.rotation_drift() + 1.0);
}

bool energy_bound_holds(const scenes::EnergyTracker& e) {
  return !e.nonfinite() && e.max_unaccounted() <= energy_tolerance(e) &&
         e.max_step_excess() <= energy_tolerance(e);
}

// E(t) <= E(0) + W(t) + R(t) over the run and step by step (tolerance above).
void check_energy_bound(const scenes::EnergyTracker& e) {
  INFO("E(0) = " << e.initial() << " J, max E - E(0) = " << e.max_gain() << " J, push work W = "
                 << e.push_work() << " J, rotation term R = " << e.rotation_drift()
                 << " J, max(E - E(0) - W - R) = " << e.max_unaccounted()
                 << " J, max step (dE - dW - dR) = " << e.max_step_excess() << " J");
  CHECK_FALSE(e.nonfinite());
  CHECK(e.max_unaccounted() <= energy_tolerance(e));
  CHECK(e.max_step_excess() <= energy_tolerance(e));
}

// E(t) <= E(0) + W(t) + R(t) over the run only, for a method whose rows are springs kept from step
// to step, which may give back in one step what an earlier step stored (tolerance above).
void check_run_energy_bound(const scenes::EnergyTracker& e) {
  INFO("E(0) = " << e.initial() << " J, max E - E(0) = " << e.max_gain() << " J, push work W = "
                 << e.push_work() << " J, rotation term R = " << e.rotation_drift()
                 << " J, max(E - E(0) - W - R) = " << e.max_unaccounted() << " J");
  CHECK_FALSE(e.nonfinite());
  CHECK(e.max_unaccounted() <= energy_tolerance(e));
}

// Steps `run` until `seconds` (s), checking after every step that every body is finite (the fp
// trap catches most of it earlier; this catches what slips through as a stored NaN).
void advance_checked(scenes::Run& run, double seconds) {
  while (run.world.time() + 0.5 * run.world.def().dt < seconds) {
    run.step();
    if (!scenes::all_finite(run.world)) {
      FAIL("a body state is not finite at t = " << run.world.time() << " s");
    }
  }
}

// A scene run to `seconds` (s): every step checked for finite states, its metrics and an
// EnergyTracker fed alongside.
struct CheckedRun {
  scenes::Run run;
  scenes::EnergyTracker energy;
  nlohmann::json metrics;
};

CheckedRun run_checked(const char* name, double seconds, const scenes::Overrides& o = {}) {
  CheckedRun c{scenes::make_run(scene(name), o), {}, {}};
  c.energy.observe(c.run.world);
  while (c.run.world.time() + 0.5 * c.run.world.def().dt < seconds) {
    c.run.step();
    c.energy.observe(c.run.world);
    if (!scenes::all_finite(c.run.world)) {
      FAIL(name << ": a body state is not finite at t = " << c.run.world.time() << " s");
    }
  }
  c.metrics = c.run.metrics->report();
  return c;
}

// ENGINE ISSUE (see the stress report): Eigen's allFinite() tests x - x == x - x, and inf - inf
// raises FE_INVALID, so the engine's own validation of an infinite input (body.cpp require_finite
// and Shape::box, WorldDef::validate's gravity) trips the floating point trap before it can throw
// its std::invalid_argument. Within this guard FE_INVALID is masked, so the test checks the throw.
class MaskInvalid {
 public:
  MaskInvalid() : saved_(fegetexcept()) { fedisableexcept(FE_INVALID); }
  ~MaskInvalid() {
    std::feclearexcept(FE_INVALID);
    feenableexcept(saved_);
  }
  MaskInvalid(const MaskInvalid&) = delete;
  MaskInvalid& operator=(const MaskInvalid&) = delete;

 private:
  int saved_;
};

double number(const nlohmann::json& j, const char* key) {
  INFO("key " << key << " in " << j.dump());
  REQUIRE(j.contains(key));
  REQUIRE(j[key].is_number());
  return j[key].get<double>();
}

}  // namespace

TEST_CASE("every stress scene is listed once and builds and steps and reports its metrics",
          "[stress][table]") {
  std::set<std::string> names;
  for (const scenes::Scene& s : scenes::paper_scenes()) names.insert(std::string(s.name));
  for (const scenes::Scene& s : scenes::stress_scenes()) {
    INFO("scene " << s.name);
    CHECK(names.insert(std::string(s.name)).second);  // unique among all scenes
    REQUIRE(scenes::find_scene(s.name) != nullptr);
    CHECK(scenes::find_scene(s.name)->summary == s.summary);
    CHECK(!s.summary.empty());
    CHECK(s.default_seconds > 0.0);
    scenes::Run run = scenes::make_run(s);
    for (int k = 0; k < 10; ++k) run.step();
    CHECK(scenes::all_finite(run.world));
    const nlohmann::json m = run.metrics->report();
    CHECK(m.is_object());
    CHECK(!m.empty());
  }
  for (const char* name :
       {"mass_ratio_10", "mass_ratio_100", "mass_ratio_1000", "heavy_ball_grid", "stack_dt_0.1",
        "pendulum_wave_dt_0.1", "spin_100", "spin_1000", "sphere_in_box", "chain_20", "scale_0.01",
        "scale_100", "degen_coincident", "degen_parallel_edges", "degen_edge_balance",
        "degen_touching_boxes", "random"}) {
    INFO("scene " << name);
    CHECK(names.count(name) == 1);
  }
}

// ---- 1. Mass ratios ----

TEST_CASE("mass ratio 10 holds at 25 iterations within the Baumgarte ceiling",
          "[stress][mass_ratio]") {
  // A 1D model of the column (mass_ratio.h): Gauss-Seidel from 0 on the ground row and the cube
  // row reduces the error by rho = R / (1 + R) per sweep, so the pair sinks by rho^N g dt^2 per
  // step and the push recovers beta d: d = rho^N g dt^2 / beta, 1.28 mm for R = 10, N = 25. The
  // 3D column converges slower (four corner rows per face, coupled through the rotations):
  // measured 2.7 mm at 10 s, 6.4 mm at the worst step. What the push factor guarantees whatever
  // the solver supplies is the ceiling g dt^2 / beta = 13.9 mm: asserted on both.
  const CheckedRun c = run_checked("mass_ratio_10", 10.0);
  REQUIRE(c.run.world.def().iterations == 25);
  const nlohmann::json& m = c.metrics;
  const double rho = 10.0 / 11.0;
  INFO(m.dump() << "\n1D model: " << std::pow(rho, 25) * kBaumgarteCeiling << " m");
  CHECK(m["holds"].get<bool>());
  CHECK(number(m, "max_penetration_m") < kBaumgarteCeiling);
  CHECK(number(m, "final_penetration_m") < kBaumgarteCeiling);
  // The heavy cube's centre rests at 1.5 m less the two penetrations.
  CHECK(number(m, "top_height_m") == Approx(1.5).margin(2.0 * kBaumgarteCeiling));
}

TEST_CASE("mass ratios 100 and 1000 at 25 iterations stay finite and gain no energy",
          "[stress][mass_ratio]") {
  // At R = 100 and 1000, 25 PGS sweeps leave most of the load unsupported (rho^25 = 0.78 and
  // 0.975 in the 1D model): whether the pair holds is measured (the report), not asserted. What
  // is guaranteed is what the rows may do: no NaN, and no energy beyond the push work.
  for (const char* name : {"mass_ratio_100", "mass_ratio_1000"}) {
    INFO("scene " << name);
    const CheckedRun c = run_checked(name, 10.0);
    INFO(c.metrics.dump());
    check_energy_bound(c.energy);
  }
}

TEST_CASE("the iterations a mass ratio needs grow with the ratio and 10 needs at most 25",
          "[stress][mass_ratio]") {
  // The 1D model (mass_ratio.h) needs N > ln 0.72 / ln(R / (1 + R)): 4, 33 and 329 for
  // R = 10, 100, 1000 - more iterations for a larger ratio. -1 (none up to 256) counts as more
  // than 256.
  const auto needed = [](double ratio) {
    const int n = scenes::iterations_needed(ratio);
    return n < 0 ? INT_MAX : n;
  };
  const int n10 = needed(10.0);
  const int n100 = needed(100.0);
  const int n1000 = needed(1000.0);
  INFO("iterations needed: ratio 10: " << n10 << ", 100: " << n100 << ", 1000: " << n1000
                                       << " (INT_MAX: none up to 256)");
  CHECK(n10 <= 25);
  CHECK(n10 <= n100);
  CHECK(n100 <= n1000);
}

// ---- 2. Heavy ball on the pendulum grid ----

TEST_CASE("a 50 kg ball falls through the pendulum grid without NaN or energy gain",
          "[stress][heavy_ball_grid]") {
  // Paper Sec. 10.3: enough force pushes the pendulums aside. The rods and contacts do no work
  // except the push factor's correction, so E(t) <= E(0) + W(t) (top of this file).
  const CheckedRun c = run_checked("heavy_ball_grid", scene("heavy_ball_grid").default_seconds);
  const nlohmann::json& m = c.metrics;
  INFO(m.dump());
  CHECK(m["fell_through"].get<bool>());
  CHECK_FALSE(m["nan"].get<bool>());
  check_energy_bound(c.energy);
}

// ---- 3. Large time step ----

TEST_CASE("the stack and the pendulum wave at dt = 0.1 s keep their energy bounded",
          "[stress][large_dt]") {
  // E(t) <= E(0) + W(t): gravity's work is in the potential already, the push factor's term
  // beta d / dt (contacts) and -beta C / dt (rods) is the only source (top of this file).
  // Measured: neither ever rises above E(0) at all.
  for (const char* name : {"stack_dt_0.1", "pendulum_wave_dt_0.1"}) {
    const scenes::Scene& s = scene(name);
    INFO("scene " << name);
    REQUIRE(s.world_def().dt == 0.1);
    const CheckedRun c = run_checked(name, s.default_seconds);
    INFO(c.metrics.dump());
    check_energy_bound(c.energy);
    CHECK(number(c.metrics, "energy_growth_J") == Approx(c.energy.max_gain()));
  }
}

// ---- 4. Fast spin ----

TEST_CASE("a free spinning box keeps |o| = 1 and l exactly and its energy within what l allows",
          "[stress][spin]") {
  // Without torque Eq. 3.2.2 adds tau dt = 0 to l: l may not change at all (round-off of a few
  // ulp at most). o is normalised every step: | |o| - 1 | is a few ulp. The kinetic energy
  // 1/2 l . R I_body^-1 R^T l at fixed l lies in [|l|^2 / (2 I_max), |l|^2 / (2 I_min)] for any
  // rotation R, so the relative drift cannot exceed energy_drift_bound_rel. Nothing guarantees
  // that the exact rotation step (Eq. 12.4.1) drifts less than the linear one: both turn the box
  // about the step's initial w, and at 100 and 1000 rad/s both drive it within a few steps to
  // spin about its axis of least inertia, the ceiling of the bound (measured: 1.100 for both).
  for (const char* name : {"spin_100", "spin_1000"}) {
    for (const RotationUpdate rotation : {RotationUpdate::linear, RotationUpdate::exact}) {
      scenes::Overrides o;
      o.set("rotation", rotation);
      scenes::Run run = scenes::make_run(scene(name), o);
      // The first step from o0 = 1 turns by w0 = I^-1 l0 (l does not change): Eq. 3.2.4 then
      // normalise, or the axis-angle step of Eq. 12.4.1, even at |w0| dt = 17 rad.
      const Vec3 w0 = run.world.body(0).angular_velocity();
      const double dt = run.world.def().dt;
      Quat expected;
      if (rotation == RotationUpdate::linear) {
        expected = Quat(1.0, 0.5 * w0.x() * dt, 0.5 * w0.y() * dt, 0.5 * w0.z() * dt).normalized();
      } else {
        const double half = 0.5 * w0.norm() * dt;
        const Vec3 axis = w0.normalized() * std::sin(half);
        expected = Quat(std::cos(half), axis.x(), axis.y(), axis.z());
      }
      run.step();
      CHECK(run.world.body(0).o.angularDistance(expected) < 1e-12);
      advance_checked(run, 10.0);
      const nlohmann::json m = run.metrics->report();
      INFO(name << (rotation == RotationUpdate::linear ? " linear: " : " exact: ") << m.dump());
      CHECK(number(m, "max_quat_norm_error") < 1e-12);
      CHECK(number(m, "angular_momentum_drift_rel") <= 4.0 * std::numeric_limits<double>::epsilon());
      CHECK(number(m, "energy_drift_rel") <= number(m, "energy_drift_bound_rel") + 1e-12);
      CHECK_FALSE(m["nan"].get<bool>());
    }
  }
}

// ---- 5. Deep overlap ----

TEST_CASE("a ball started inside a box is pushed out without being thrown", "[stress][sphere_in_box]") {
  const scenes::Scene& s = scene("sphere_in_box");
  REQUIRE(s.world_def().push == PushMode::split);
  const double d0 = 0.7;  // m: 0.3 m below the top face plus the 0.4 m radius
  SECTION("split: the push moves positions only, so nothing leaves fast") {
    // The stored momenta come from the solve without the push (Sec. 8.1): they see gravity and
    // contacts that only stop approach. The push moves a body by beta d < d per step, so it never
    // opens a gap; a body gains g dt = 0.17 m/s per step only while a contact flickers (depth
    // crossing 0). Bound: 3 such steps, 3 g dt = 0.5 m/s (measured g dt: the first step, when
    // the box's exactly touching ground contact is not yet detected). Baumgarte would throw the
    // ball at beta d0 / dt = 8.4 m/s.
    const CheckedRun c = run_checked("sphere_in_box", s.default_seconds);
    const nlohmann::json& m = c.metrics;
    INFO(m.dump());
    check_energy_bound(c.energy);
    CHECK(number(m, "max_speed_mps") <= 3.0 * kG * kPaperDt);
    CHECK(number(m, "final_penetration_m") < kBaumgarteCeiling);
    CHECK(number(m, "sphere_height_m") == Approx(2.4).margin(kBaumgarteCeiling));  // on top
  }
  SECTION("baumgarte: the ball leaves at no more than the push target") {
    // The contact row targets a separation speed of beta d / dt and d only shrinks from d0, so
    // no body is faster than beta d0 / dt plus one step of gravity (8.57 m/s; measured 7.47 m/s:
    // the 10 kg box takes 1/11 of it). It flies up and lands back on the box.
    scenes::Overrides o;
    o.set("push", PushMode::baumgarte);
    const CheckedRun c = run_checked("sphere_in_box", s.default_seconds, o);
    const nlohmann::json& m = c.metrics;
    INFO(m.dump());
    check_energy_bound(c.energy);
    CHECK(number(m, "max_speed_mps") <= kPaperBeta * d0 / kPaperDt + kG * kPaperDt);
    CHECK(number(m, "max_speed_mps") > 0.5 * kPaperBeta * d0 / kPaperDt);  // and it does leave
    CHECK(number(m, "final_penetration_m") < kBaumgarteCeiling);
  }
}

TEST_CASE("the intersecting stack with the single frame push factor never moves fast",
          "[stress][sphere_in_box][intersecting_stack]") {
  // Paper Sec. 10.2 (0.4 m overlaps, 1.2 m into the ground). Same argument and bound as the ball
  // in the box with split: 3 g dt = 0.5 m/s over the whole 4 s (measured 0.28 m/s, the column
  // rocking while it rises; with baumgarte the top cube leaves at 30.8 m/s).
  scenes::Overrides o;
  o.set("push", PushMode::split);
  scenes::Run run = scenes::make_run(scene("intersecting_stack"), o);
  double max_speed = 0.0;
  while (run.world.time() < 4.0 - 1e-9) {
    run.step();
    REQUIRE(scenes::all_finite(run.world));
    for (const Body& b : run.world.bodies()) max_speed = std::max(max_speed, b.velocity().norm());
  }
  INFO("max speed " << max_speed << " m/s");
  CHECK(max_speed <= 3.0 * kG * kPaperDt);
  CHECK(scenes::max_penetration_now(run.world) < kBaumgarteCeiling);
}

// ---- 6. Long chain ----

TEST_CASE("a 20 link chain stretches no more than the speeds of its links allow", "[stress][chain]") {
  // Each step the ends of a link move by v2 dt; the solve sets their radial relative speed to
  // -beta C / dt, and a tangential relative speed u lengthens the link to
  // sqrt((l + (1 - beta) C)^2 + (u dt)^2) <= l + (1 - beta) C + (u dt)^2 / (2 l). Summed as a
  // geometric series: C <= (u_max dt)^2 / (2 l beta) with u_max the largest tangential relative
  // speed of a link's ends over the run (the whip of the free end: 16.7 m/s, bound 0.65 m;
  // measured 0.27 m, 89 % of the 0.3 m link; more sweeps do not help, a smaller dt does: it is the
  // step, not PGS). And no energy beyond the push work.
  const scenes::Scene& s = scene("chain_20");
  scenes::Run run = scenes::make_run(s);
  scenes::EnergyTracker energy;
  energy.observe(run.world);
  const double l = 0.3;
  const double dt = run.world.def().dt;
  const double beta = run.world.def().beta;
  double u_max = 0.0;
  while (run.world.time() + 0.5 * dt < s.default_seconds) {
    run.step();
    energy.observe(run.world);
    REQUIRE(scenes::all_finite(run.world));
    for (const DistanceConstraint& d : run.world.distances()) {
      Vec3 p_a;
      Vec3 p_b;
      distance_endpoints(d, run.world.bodies(), p_a, p_b);
      const Vec3 n = (p_b - p_a).normalized();
      const Vec3 v_b = d.body_b == kWorldBody ? Vec3::Zero() : run.world.body(d.body_b).velocity();
      const Vec3 v = v_b - run.world.body(d.body_a).velocity();
      u_max = std::max(u_max, (v - n * n.dot(v)).norm());
    }
  }
  const nlohmann::json m = run.metrics->report();
  const double bound = (u_max * dt) * (u_max * dt) / (2.0 * l * beta);
  INFO(m.dump() << "\nu_max " << u_max << " m/s, bound " << bound << " m");
  CHECK(number(m, "max_stretch_m") <= bound);
  CHECK(number(m, "max_stretch_rel") == Approx(number(m, "max_stretch_m") / l));
  CHECK_FALSE(m["nan"].get<bool>());
  check_energy_bound(energy);
}

// ---- 7. Scaled units ----

TEST_CASE("the stack scaled by a power of 4 follows the unscaled stack exactly", "[stress][scale]") {
  // x -> s x, t -> sqrt(s) t, m -> s^3 m maps every equation onto itself (scale.cpp). For
  // s = 4^k every scaled input is the unscaled one times a power of 2 (sqrt(s) = 2^k), so every
  // product, quotient, sum and square root is too, rounding included: the runs agree bit for bit
  // (no absolute tolerance anywhere in the engine acts on this scene).
  for (const double s : {0.25, 4.0, 16.0}) {
    World scaled(scenes::scaled_stack_world_def(s));
    scenes::populate_scaled_stack(scaled, s);
    World unscaled(scenes::stack_world_def());
    scenes::populate_stack(unscaled);
    double worst = 0.0;
    for (int k = 0; k < 600; ++k) {  // 10 s of the unscaled stack
      scaled.step();
      unscaled.step();
      for (std::size_t i = 1; i < scaled.bodies().size(); ++i) {
        worst = std::max(worst, (scaled.bodies()[i].x / s - unscaled.bodies()[i].x).cwiseAbs().maxCoeff());
        worst = std::max(worst, (scaled.bodies()[i].o.coeffs() - unscaled.bodies()[i].o.coeffs()).cwiseAbs().maxCoeff());
      }
    }
    INFO("s = " << s);
    CHECK(worst == 0.0);
  }
}

TEST_CASE("the stack at 1/100 and 100 times the size agrees with the stack in scaled units",
          "[stress][scale]") {
  // For s = 0.01 and 100 the scaled inputs round differently (relative 1e-16). The landing's
  // impacts can amplify that until the first step whose contact set differs (contact is made only
  // on overlap, a discontinuity; with each point's friction rows after its contact row that was
  // step 110, a corner 2e-7 m deep in the scaled runs just clear in the unscaled one, and the
  // error before it 1.6e-6 and 1.8e-6 of the 2.4 m edge). Bound before it: 1e-5. After it the
  // runs settle the same column through different contact flickers and differ by the column's
  // resting jitter and lean: bound 0.05 m = 0.021 of the edge (it was 0.0021 then; with the rows
  // ordered as World::build_rows orders them now the contact sets never part: 1.1e-11, 4.8e-12).
  for (const char* name : {"scale_0.01", "scale_100"}) {
    const scenes::Scene& sc = scene(name);
    const CheckedRun c = run_checked(name, sc.default_seconds);
    const scenes::Run& run = c.run;
    const nlohmann::json& m = c.metrics;
    INFO(name << ": " << m.dump());
    const double s = number(m, "scale");
    CHECK(run.world.def().dt == Approx(kPaperDt * std::sqrt(s)).epsilon(1e-15));
    CHECK(run.world.counters().steps == 600);  // the equivalent of 10 s
    CHECK(number(m, "max_position_error_before_difference_rel") < 1e-5);
    CHECK(number(m, "max_position_error_rel") < 0.05 / 2.4);
    CHECK_FALSE(m["nan"].get<bool>());
  }
}

// ---- 8. Degenerate geometry ----

TEST_CASE("degenerate contacts give no NaN and no energy beyond the push work", "[stress][degenerate]") {
  for (const char* name : {"degen_coincident", "degen_parallel_edges", "degen_edge_balance",
                           "degen_touching_boxes"}) {
    const scenes::Scene& s = scene(name);
    INFO("scene " << name);
    const CheckedRun c = run_checked(name, s.default_seconds);
    const nlohmann::json& m = c.metrics;
    INFO(m.dump());
    check_energy_bound(c.energy);
    // Every scene comes to rest without deep overlap (the Baumgarte ceiling).
    CHECK(number(m, "final_penetration_m") < kBaumgarteCeiling);
    for (const Body& b : c.run.world.bodies()) CHECK(b.velocity().norm() < 0.05);
  }
}

TEST_CASE("coincident balls separate and touching boxes stay put", "[stress][degenerate]") {
  SECTION("coincident centres: the +y normal of collision.h takes them apart") {
    const CheckedRun c = run_checked("degen_coincident", 5.0);
    const nlohmann::json& m = c.metrics;
    INFO(m.dump());
    // Two balls of radius 0.5 m: centres 1 m apart, less the resting penetration.
    CHECK(number(m, "centre_distance_m") > 1.0 - kBaumgarteCeiling);
  }
  SECTION("two cubes touching face to face at rest: zero-depth contacts add nothing") {
    // Depth 0 and relative velocity 0 give a target of 0 for the side contact: lambda = 0, the
    // cubes stay exactly 1 m apart and at rest (up to the solver's round-off). The ground
    // contacts get a 1 mm margin: at margin 0 (the paper's rule) a converged push drives each
    // ground depth to 0 (down to 1e-16 m after 140 steps) and then round-off decides which
    // corners count as touching; when some lose their contact before the others, the cube
    // falls a step of g dt^2 on that side and tips (measured: three corners lost at step 210
    // with 100 sweeps). That is the margin-0 rule, not the zero-depth side contact tested here.
    scenes::Overrides o;
    o.set("contact_margin", 0.001);
    const CheckedRun c = run_checked("degen_touching_boxes", 5.0, o);
    const nlohmann::json& m = c.metrics;
    INFO(m.dump());
    CHECK(number(m, "centre_distance_m") == Approx(1.0).margin(1e-6));
    for (const Body& b : c.run.world.bodies()) {
      if (b.is_static()) continue;
      CHECK(b.velocity().norm() < 1e-6);
      CHECK(std::hypot(b.x.x(), b.x.z()) == Approx(0.5).margin(1e-6));
    }
  }
}

// ---- 9. Random piles ----

TEST_CASE("random piles never give a NaN or energy beyond the push work", "[stress][random]") {
  // Seeds 0 .. N-1, N = $CPS_RANDOM_SEEDS or 200. Each seed is populate_random(world, seed) at the
  // paper's settings, 5 s, with the push factor in the velocity (baumgarte) and with the single
  // frame push factor (split). Bound: E(t) <= E(0) + W(t) + R(t) (top of this file), over the
  // run and step by step. Over 10000 seeds in both modes: no NaN, no trapped exception, the
  // bound held (tolerance above); the tightest seed reaches E(t) - E(0) = 0.998 (W + R): the
  // bound is sharp, not slack.
  //
  // Warm started too (factor 0.8 and 1; Sec. 6.2.3), where a guess carried over from the step
  // before can leave a row pushing while its points already part faster than its target: that
  // would show here as energy beyond the bound. Measured over 100 seeds: the largest step excess
  // is 0.003 of the tolerance (0.8 and 1), 1e-6 of it from lambda = 0.
  int seeds = 200;
  if (const char* env = std::getenv("CPS_RANDOM_SEEDS")) seeds = std::atoi(env);
  REQUIRE(seeds >= 0);
  for (int seed = 0; seed < seeds; ++seed) {
    for (const double warm : {0.0, 0.8, 1.0}) {
    for (const PushMode push : {PushMode::baumgarte, PushMode::split}) {
      WorldDef def = scenes::stack_world_def();
      def.push = push;
      def.warm_start = warm;
      World world(def);
      scenes::populate_random(world, static_cast<std::uint64_t>(seed));
      scenes::EnergyTracker e;
      e.observe(world);
      for (int k = 0; k < 300 && !e.nonfinite(); ++k) {
        world.step();
        e.observe(world);
      }
      INFO("seed " << seed << " (" << (push == PushMode::split ? "split" : "baumgarte")
                   << ", warm start " << warm << "): replay with CPS_RANDOM_SEEDS=" << seed + 1
                   << " build/tests/cps_tests \"[random]\", or scenes::populate_random(world, "
                   << seed << ") in a stack_world_def() world");
      if (!energy_bound_holds(e)) check_energy_bound(e);  // reports the failure with its numbers
    }
    }
  }
  SUCCEED(seeds << " seeds");
}

// ---- 9b. Warm starting ----

TEST_CASE("warm starting at 0.8 adds no energy beyond the push work in the stiff scenes",
          "[stress][warm_start]") {
  // A warm start (Sec. 6.2.3) begins each persisting row at a guess from the steps before. A
  // guess larger than this step's answer that the fixed 25 sweeps do not take back leaves the
  // row pushing while its points part faster than its target, or a rod pulling while its ends
  // approach: energy that E(t) <= E(0) + W(t) + R(t) (top of this file) does not allow, step by
  // step. The scenes where a stale guess is largest: the chain's whip (rod forces change fast),
  // heavy on light (mass ratios 10 and 100: slow convergence), the stack at dt = 0.1 s (each
  // landing an impulse), the ball in the box (split: both solves warm started). Measured with
  // factor 1 the bound breaks: largest step excess 1.94 J in chain_20 (tolerance 0.031 J), 3.41 J
  // in mass_ratio_100 (0.106 J), 0.17 J at dt = 0.1 s (0.014 J); and at 0.8 with the last lambda
  // as the guess instead of the smaller of the last two (warm_start.h) 1.75 J at dt = 0.1 s. With
  // 0.8 and the smaller of two, every one holds (largest 0.0143 J in chain_20, tolerance 0.035 J).
  for (const char* name : {"chain_20", "mass_ratio_10", "mass_ratio_100", "stack_dt_0.1",
                           "sphere_in_box", "heavy_ball_grid"}) {
    INFO("scene " << name);
    scenes::Overrides o;
    o.set("warm_start", 0.8);
    const CheckedRun c = run_checked(name, std::min(10.0, scene(name).default_seconds), o);
    INFO(c.metrics.dump());
    check_energy_bound(c.energy);
  }
}

// ---- 10. Input validation ----

TEST_CASE("bad bodies and rods are rejected by name and leave the world unchanged",
          "[stress][validation]") {
  // Cases not already in test_scenes.cpp and test_constraints.cpp.
  World world;
  BodyDef ok;
  ok.shape = Shape::sphere(0.5);
  ok.position = Vec3(0.0, 1.0, 0.0);
  world.add_body(ok);
  world.add_distance({0, Vec3::Zero(), kWorldBody, Vec3(0.0, 2.0, 0.0), 1.0});
  const Body before = world.body(0);

  const auto unchanged = [&] {
    CHECK(world.bodies().size() == 1);
    CHECK(world.distances().size() == 1);
    CHECK(world.body(0).x == before.x);
    CHECK(world.body(0).p == before.p);
  };

  BodyDef bad = ok;
  bad.mass = 0.0;
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("mass") && Catch::Contains("0"));
  unchanged();
  bad.mass = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(world.add_body(bad), std::invalid_argument);
  unchanged();

  // A shape given by hand (not through Shape::box / Shape::sphere) is validated by add_body.
  bad = ok;
  bad.shape.kind = ShapeKind::box;
  bad.shape.half_extents = Vec3(0.5, 0.0, 0.5);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("half extents"));
  unchanged();
  bad.shape.half_extents = Vec3(0.5, -0.5, 0.5);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("half extents") && Catch::Contains("-0.5"));
  unchanged();
  bad = ok;
  bad.shape.radius = 0.0;
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("radius") && Catch::Contains("0"));
  unchanged();
  CHECK_THROWS_WITH(Shape::sphere(0.0), Catch::Contains("radius"));
  CHECK_THROWS_WITH(Shape::sphere(-1.0), Catch::Contains("radius") && Catch::Contains("-1"));
  {
    const MaskInvalid mask;  // ENGINE ISSUE: see MaskInvalid
    CHECK_THROWS_WITH(Shape::box(Vec3(1.0, std::numeric_limits<double>::infinity(), 1.0)),
                      Catch::Contains("half extents") && Catch::Contains("inf"));
    bad = ok;
    bad.velocity = Vec3(std::numeric_limits<double>::infinity(), 0.0, 0.0);
    CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("velocity") && Catch::Contains("inf"));
    unchanged();
  }
  bad = ok;
  bad.angular_velocity = Vec3(0.0, std::numeric_limits<double>::quiet_NaN(), 0.0);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("angular velocity") && Catch::Contains("nan"));
  unchanged();
  bad = ok;
  bad.orientation = Quat(0.0, 0.0, 0.0, 0.0);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("unit quaternion"));
  unchanged();
  bad.orientation = Quat(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0, 0.0);
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("unit quaternion"));
  unchanged();
  bad = ok;
  bad.shape = Shape::plane(Vec3::UnitY(), 0.0);  // a movable plane
  CHECK_THROWS_WITH(world.add_body(bad), Catch::Contains("plane"));
  unchanged();
  CHECK_THROWS_WITH(Shape::plane(Vec3::Zero(), 0.0), Catch::Contains("normal"));

  // Rods: a NaN end point, an infinite length, a rod from a body to itself.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(world.add_distance({0, Vec3(nan, 0.0, 0.0), kWorldBody, Vec3::Zero(), 1.0}),
                    Catch::Contains("end points"));
  unchanged();
  CHECK_THROWS_WITH(world.add_distance({0, Vec3::Zero(), kWorldBody, Vec3(0.0, nan, 0.0), 1.0}),
                    Catch::Contains("end points"));
  unchanged();
  CHECK_THROWS_WITH(world.add_distance({0, Vec3::Zero(), kWorldBody, Vec3::Zero(),
                                        std::numeric_limits<double>::infinity()}),
                    Catch::Contains("length") && Catch::Contains("inf"));
  unchanged();
  CHECK_THROWS_WITH(world.add_distance({0, Vec3::Zero(), 0, Vec3::Zero(), 1.0}),
                    Catch::Contains("body_a and body_b are both 0"));
  unchanged();

  // The stress scene builders validate their own parameters.
  World empty;
  CHECK_THROWS_WITH(scenes::populate_mass_ratio(empty, 0.0), Catch::Contains("mass ratio"));
  CHECK_THROWS_WITH(scenes::populate_mass_ratio(empty, -10.0), Catch::Contains("-10"));
  CHECK(empty.bodies().empty());
}

TEST_CASE("a pile of bodies in one spot fails with the count instead of asking for gigabytes",
          "[stress][limits]") {
  for (const int count : {1000, 10000}) {
    INFO(count << " unit cubes at the origin");
    World world;
    for (int i = 0; i < count; ++i) {
      BodyDef cube;
      cube.shape = Shape::box(Vec3::Constant(0.5));
      cube.position = Vec3(0.0, 1e-6 * i, 0.0);
      world.add_body(cube);
    }
    const std::vector<Body> before = world.bodies();
    // 1000 cubes: 499,500 pairs, each up to 8 points (past kMaxContactPoints); 10000 cubes:
    // about 5e7 pairs (past kMaxCandidatePairs).
    CHECK_THROWS_AS(world.step(), std::length_error);
    CHECK_THROWS_WITH(world.step(), Catch::Contains(std::to_string(count) + " bodies"));
    for (std::size_t i = 0; i < before.size(); ++i) CHECK(world.bodies()[i].x == before[i].x);
  }
  // A crowded but reasonable pile still steps: 100 cubes in one spot.
  World world;
  for (int i = 0; i < 100; ++i) {
    BodyDef cube;
    cube.shape = Shape::box(Vec3::Constant(0.5));
    cube.position = Vec3(0.0, 1e-6 * i, 0.0);
    world.add_body(cube);
  }
  CHECK_NOTHROW(world.step());
  CHECK(world.counters().contacts > 0);
}

// ---- 11. The push methods beyond the paper's (engine/src/push/) ----

// Every push method of the table but the paper's two, which the sections above check with their
// own push work W.
namespace {
bool beyond_the_paper(const Choice& push) { return !push.in_paper; }

// Whether the bound is checked step by step for `push`, or over the run alone. avbd's penalty
// rows are springs whose stiffness and force are kept from step to step (Giles et al. 2025, the
// warm start of the penalties and multipliers), so a step can give back what earlier steps
// stored: measured at the scenes' 25 iterations, a step's excess of 0.045 J on chain_20 and
// 10.2 J on stack_dt_0.1 (tolerances 0.016 and 0.012 J), and on 6 of the first 20 random piles up
// to 113 J, while E(t) - E(0) - W(t) - R(t) never went above 0 in any of those runs.
bool bound_step_by_step(const Choice& push) { return push.name != "avbd"; }
}  // namespace

TEST_CASE("the push methods beyond the paper's keep the energy bound in the stiff scenes",
          "[stress][push_methods]") {
  // E(t) <= E(0) + W(t) + R(t) (top of this file), W the lift of the positions' push against
  // gravity x2 - x1 - v2 dt (EnergyTracker): each of these methods keeps its push out of the
  // stored momenta (the pseudo-velocities, the soft solve's positions, the position projection),
  // so only the lift can add energy. Cold and warm started (0.8), on the scenes where energy
  // would show first: the chain's whip, heavy on light, the stack at dt = 0.1 s, the ball in the
  // box, the heavy ball on the grid. xpbd moves positions in substeps and takes the velocities
  // from them; the bound holds for it as for the others (its pre-stabilisation is a push of
  // positions alone, counted in W). Every method of the push table but the paper's two (checked
  // above); avbd over the run alone (bound_step_by_step).
  for (const Choice& choice : parameter("push").choices) {
    if (!beyond_the_paper(choice)) continue;
    const std::string method(choice.name);
    for (const double warm : {0.0, 0.8}) {
      for (const char* name : {"chain_20", "mass_ratio_10", "stack_dt_0.1", "sphere_in_box",
                               "heavy_ball_grid"}) {
        INFO(method << ", warm start " << warm << ", scene " << name);
        scenes::Overrides o;
        o.set("push", choice.value);
        o.set("warm_start", warm);
        if ((method == "ngs" || method == "tgs") && warm > 0.0 &&
            std::string(name) == "stack_dt_0.1") {
          // Measured at 25 sweeps: a step excess of 0.049 J (tolerance 0.0104 J), at 100 sweeps
          // 0.005 J, at 400 0.0006 J: the residual of a velocity solve started from a stale
          // guess (each landing at dt = 0.1 s an impulse), which the position projection does
          // not take back. Checked where the solve converges enough for the bound to apply. tgs
          // alike (its relax is a velocity solve from the same guess): 0.32 J at 25 sweeps,
          // 0.0135 J at 100 (tolerance 0.011 J); checked at 400.
          o.set("iterations", method == "tgs" ? 400 : 100);
        }
        if (method == "soft") {
          // Box3D's relax continues from the soft solve's impulses and velocities; the push its
          // sweeps do not take out stays in the momenta. Measured at 25 sweeps, step excess: chain_20
          // 1.36 J, stack_dt_0.1 0.20 J, heavy_ball_grid 0.15 J (tolerances 0.016, 0.010, 0.11 J),
          // cold or warm. The bound is checked on the variant that relaxes from the substep's start
          // (soft_step.cpp).
          o.set("soft_relax", SoftRelax::restart);
        }
        const double seconds = std::min(5.0, scene(name).default_seconds);
        if (method == "xpbd" && std::string(name) == "chain_20") {
          // One sweep a substep along the 20 links leaves stretch (2.1 mm at 20 substeps) that the
          // next substep corrects, as a velocity: a step excess of 8.8 J at the default 20
          // substeps, 0.65 J at 30, 0.012 J at 40, -0.033 J at 60 (tolerance about 0.017 J). The
          // source's own step gives the same 8.8 J (the test "xpbd steps a chain as Mueller et
          // al.'s Algorithm 2 does", test_push_methods.cpp; docs/findings.md, "TGS and XPBD"):
          // at 20 substeps the rods store and give back energy as avbd's springs do, so the bound
          // holds over the run; step by step at 60, where the sweeps keep up with the chain.
          const CheckedRun source = run_checked(name, seconds, o);
          INFO(source.metrics.dump());
          check_run_energy_bound(source.energy);
          o.set("xpbd_substeps", 60);
        }
        const CheckedRun c = run_checked(name, seconds, o);
        INFO(c.metrics.dump());
        if (bound_step_by_step(choice)) {
          check_energy_bound(c.energy);
        } else {
          check_run_energy_bound(c.energy);
        }
      }
    }
  }
}

TEST_CASE("random piles keep the energy bound with the push methods beyond the paper's",
          "[stress][random][push_methods]") {
  // As the random pile test above (section 9), for every method of the push table but the
  // paper's two (avbd over the run alone: bound_step_by_step), over a tenth of its seeds; xpbd,
  // whose pre-stabilisation turns bodies started deep in each other, over all of them.
  int all_seeds = 200;
  if (const char* env = std::getenv("CPS_RANDOM_SEEDS")) all_seeds = std::atoi(env);
  const int seeds = std::max(1, all_seeds / 10);
  for (int seed = 0; seed < std::max(seeds, all_seeds); ++seed) {
    for (const Choice& choice : parameter("push").choices) {
      if (!beyond_the_paper(choice)) continue;
      if (seed >= seeds && std::string(choice.name) != "xpbd") continue;
      const auto push = static_cast<PushMode>(choice.value);
      WorldDef def = scenes::stack_world_def();
      def.push = push;
      def.soft_relax = SoftRelax::restart;  // as in the test above: Box3D's relax keeps push
      World world(def);
      scenes::populate_random(world, static_cast<std::uint64_t>(seed));
      scenes::EnergyTracker e;
      e.observe(world);
      for (int k = 0; k < 300 && !e.nonfinite(); ++k) {
        world.step();
        e.observe(world);
      }
      INFO("seed " << seed << " (push " << name_of(push) << ")");
      if (!bound_step_by_step(choice)) {
        check_run_energy_bound(e);
      } else if (!energy_bound_holds(e)) {
        check_energy_bound(e);
      }
    }
  }
  SUCCEED(seeds << " seeds, " << all_seeds << " for xpbd");
}
