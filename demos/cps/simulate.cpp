#include "simulate.h"

#include <chrono>

namespace cps::cli {
namespace {

nlohmann::json vec(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

nlohmann::json parameters_json(const WorldDef& def) {
  return {{"gravity_mps2", vec(def.gravity)},
          {"dt_s", def.dt},
          {"iterations", def.iterations},
          {"beta", def.beta},
          {"friction", def.friction},
          {"restitution", def.restitution},
          {"restitution_threshold_mps", def.restitution_threshold},
          {"push", def.push == PushMode::split ? "split" : "baumgarte"},
          {"solver", def.solver == SolverKind::jacobi ? "jacobi" : "pgs"},
          {"friction_model", def.friction_model == FrictionModel::coupled ? "coupled" : "fixed"},
          {"rotation", def.rotation == RotationUpdate::exact ? "exact" : "linear"},
          {"assembly", def.assembly == Assembly::matrix_free ? "matrix-free" : "explicit"},
          {"contact_margin_m", def.contact_margin},
          {"collision", def.collision},
          {"contact_caching", false}};
}

nlohmann::json simulate(const scenes::Scene& scene, scenes::Run& run, double seconds) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  run.advance_to(seconds);
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();

  const StepCounters& c = run.world.counters();
  nlohmann::json bodies = nlohmann::json::array();
  for (const Body& b : run.world.bodies()) {
    if (b.is_static()) continue;
    bodies.push_back({{"position", vec(b.x)},
                      {"orientation", {b.o.w(), b.o.x(), b.o.y(), b.o.z()}},
                      {"velocity", vec(b.velocity())},
                      {"angular_velocity", vec(b.angular_velocity())}});
  }
  return {{"scene", scene.name},
          {"parameters", parameters_json(run.world.def())},
          {"steps", c.steps},
          {"simulated_s", run.world.time()},
          {"wall_s", wall},
          {"us_per_step", c.steps > 0 ? 1e6 * wall / static_cast<double>(c.steps) : 0.0},
          {"metrics", run.metrics->report()},
          {"counters",
           {{"pairs_tested", c.pairs_tested},
            {"contacts", c.contacts},
            {"rows", c.rows},
            {"solves", c.solves}}},
          {"bodies", bodies}};
}

}  // namespace cps::cli
