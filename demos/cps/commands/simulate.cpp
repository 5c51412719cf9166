#include "commands/simulate.h"

#include "commands/solver_error.h"

#include "command.h"
#include "options/options.h"
#include "output/output.h"
#include "options/progress.h"
#include "energy_rise.h"
#include "state_hash.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

namespace cps::cli {
namespace {

nlohmann::json vec(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

TraceWriter::TraceWriter(std::filesystem::path path, bool force, nlohmann::json info)
    : path_(std::move(path)), info_(std::move(info)) {
  plan_ = plan_output({.folder = path_.parent_path(),
                       .files = {path_.filename().string()},
                       .command = "simulate",
                       .use = FolderUse::shared,
                       .scenes = {},
                       .option = "--trace",
                       .force = force});
  begin_output(plan_, info_);
  file_.emplace(path_);
  file_->write(kTraceHeader);
  file_->write("\n");
}

void TraceWriter::write(const World& world) {
  const long long step = static_cast<long long>(world.counters().steps);
  const double t = world.time();
  const auto& bodies = world.bodies();
  char row[512];
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    const Vec3 v = b.velocity();
    const Vec3 w = b.angular_velocity();
    const int n = std::snprintf(
        row, sizeof row,
        "%lld,%.9g,%zu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", step, t,
        i, b.x.x(), b.x.y(), b.x.z(), b.o.w(), b.o.x(), b.o.y(), b.o.z(), v.x(), v.y(), v.z(),
        w.x(), w.y(), w.z());
    file_->write(std::string_view(row, static_cast<std::size_t>(std::min<int>(n, sizeof row - 1))));
    ++rows_;
  }
}

long TraceWriter::finish() {
  file_->commit();
  end_output(plan_, info_);
  return rows_;
}

nlohmann::json simulate(const scenes::Scene& scene, scenes::Run& run, double seconds,
                        TraceWriter* trace) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  if (trace == nullptr) {
    run.advance_to(seconds);
  } else {
    trace->write(run.world);
    while (run.world.time() + 0.5 * run.world.def().dt < seconds) {  // as Run::advance_to
      run.step();
      trace->write(run.world);
    }
  }
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
          {"engine_version", engine_version()},
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
          {"state_hash", scenes::format_hash(scenes::state_hash(run.world))},
          {"bodies", bodies}};
}

namespace {

// The options of `cps simulate`.
struct SimulateOptions {
  std::string scene;
  std::optional<double> seconds;  // s; default: the scene's
  bool json = false;
  std::string trace;
  bool force = false;
  std::string expect_hash;
  double max_work = kDefaultMaxWork;  // body-iterations
  scenes::Overrides overrides;
  std::string solver_error;  // --solver-error FILE.csv
  std::string at;            // --at STEP,...
  std::optional<std::string> sweeps;  // --sweeps K,...
};

// Metrics that also report steps done to a Progress: the hook called after every step, so a long
// `cps simulate` shows progress without changing how it runs.
class ProgressMetrics final : public scenes::Metrics {
 public:
  ProgressMetrics(std::unique_ptr<scenes::Metrics> inner, Progress& progress)
      : inner_(std::move(inner)), progress_(progress) {}
  void observe(const World& world) override {
    inner_->observe(world);
    progress_.update(++steps_);
  }
  nlohmann::json report() const override { return inner_->report(); }

 private:
  std::unique_ptr<scenes::Metrics> inner_;
  Progress& progress_;
  long long steps_ = 0;
};

int run_simulate(const SimulateOptions& o, int argc, char** argv) {
  const std::vector<const scenes::Scene*> chosen = select_scenes(o.scene);
  if (o.scene == "all" || o.scene == "stress") {
    throw UsageError("simulate takes one scene, not '" + o.scene + "'");
  }
  const scenes::Scene* scene = chosen.front();
  std::optional<std::uint64_t> expected_hash;
  if (!o.expect_hash.empty()) {
    expected_hash = scenes::parse_hash(o.expect_hash);
    if (!expected_hash) {
      throw UsageError("--expect-hash " + o.expect_hash +
                       ": give the 16 hex digits of a state_hash, as simulate --json "
                       "prints it (e.g. 0123456789abcdef)");
    }
  }
  scenes::Run r = make_run_or_usage_error(*scene, o.overrides);
  const double seconds = o.seconds.value_or(scene->default_seconds);
  check_steps(o.scene, seconds, r.world.def().dt);
  check_work(o.scene, r.world.bodies().size(), r.world.def(), seconds, o.max_work,
             lower_run_options(r.world.def()));
  if (o.solver_error.empty() && (!o.at.empty() || o.sweeps)) {
    throw UsageError(std::string(o.at.empty() ? "--sweeps" : "--at") +
                     " needs --solver-error FILE.csv (the file the errors go to)");
  }
  std::optional<SolverErrorPlan> solver_error;
  if (!o.solver_error.empty()) {
    if (!o.trace.empty() && std::filesystem::path(o.trace).lexically_normal() ==
                                std::filesystem::path(o.solver_error).lexically_normal()) {
      throw UsageError("--solver-error " + o.solver_error +
                       " is also the --trace file: give two different files");
    }
    solver_error = plan_solver_error(o.solver_error, o.at,
                                     o.sweeps.value_or(std::string(kDefaultSweeps)),
                                     std::llround(seconds / r.world.def().dt));
  }
  std::optional<TraceWriter> trace;
  if (!o.trace.empty()) {
    trace.emplace(o.trace, o.force,
                  run_info("simulate", argc, argv,
                           {{"scene", scene->name},
                            {"seconds", seconds},
                            {"trace", o.trace},
                            {"overrides", overrides_json(o.overrides)},
                            {"parameters", parameters_json(r.world.def())}}));
  }
  std::optional<SolverErrorWriter> errors;
  if (solver_error) {
    errors.emplace(std::move(*solver_error), o.force,
                   run_info("simulate", argc, argv,
                            {{"scene", scene->name},
                             {"seconds", seconds},
                             {"solver_error", o.solver_error},
                             {"overrides", overrides_json(o.overrides)},
                             {"parameters", parameters_json(r.world.def())}}));
    errors->observe(r.world);
  }
  // Steps on stderr, only once the run has taken 2 s (short runs and --json stay clean).
  Progress progress("simulate " + o.scene, std::llround(seconds / r.world.def().dt), "steps", 2.0);
  r.metrics = std::make_unique<ProgressMetrics>(std::move(r.metrics), progress);
  const auto energy = scenes::watch_energy_rise(r);  // the warning below; changes no output
  const nlohmann::json summary = simulate(*scene, r, seconds, trace ? &*trace : nullptr);
  progress.finish();
  scenes::print_energy_rise_warning(scene->name, "", r.world.def(), *energy);
  if (trace) {
    const long rows = trace->finish();
    std::cerr << "trace: " << rows << " rows (" << r.world.bodies().size()
              << " bodies per step) in " << o.trace << "\n";
  }
  if (errors) {
    const long rows = errors->finish();
    std::cerr << "solver-error: " << rows << " rows in " << o.solver_error << "\n";
  }
  if (o.json) {
    std::cout << summary.dump(2) << "\n";
  } else {
    std::cout << scene->name << ": " << summary["steps"] << " steps, " << summary["simulated_s"]
              << " s simulated in " << summary["wall_s"] << " s (" << summary["us_per_step"]
              << " us/step)\nmetrics: " << summary["metrics"].dump()
              << "\nstate hash: " << std::string(summary["state_hash"]) << "\n";
  }
  if (expected_hash) {
    const std::string got = summary["state_hash"];
    if (got != scenes::format_hash(*expected_hash)) {
      std::cerr << "cps: state hash " << got << " differs from the expected "
                << scenes::format_hash(*expected_hash) << " (--expect-hash): the run ended in "
                << "another state\n";
      return 1;
    }
  }
  return 0;
}

}  // namespace

Command add_simulate(CLI::App& app, int argc, char** argv) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* sub = app.add_subcommand("simulate", "run a scene headless and report metrics");
  sub->add_option("scene", o->scene, "scene name (see 'cps list') or the path of a scene file (.json)")->required();
  add_seed_option(*sub, o->scene);
  add_seconds_option(*sub, o->seconds, "at most 1e7 steps (--seconds / --dt) a run");
  sub->add_flag("--json", o->json, "print one JSON object (keys carry their unit: _s, _m, ...)");
  sub->add_option("--trace", o->trace,
                  "write every body's state per step to this CSV: step, t (s), body index, "
                  "position (m), orientation quaternion w x y z, velocity (m/s), angular "
                  "velocity (rad/s); one row per body per step, step 0 = as built; missing "
                  "folders are created, and the folder's run.json lists the files cps wrote there")
      ->check(kNotEmpty);
  sub->add_flag("--force", o->force,
                "let --trace or --solver-error replace a file of that name that no earlier cps run wrote (its "
                "folder's run.json lists the files cps wrote there; those are replaced without "
                "it); any other file is never touched");
  sub->add_option("--expect-hash", o->expect_hash,
                  "the state_hash (16 hex digits) the run must end with: if the run ends in "
                  "another state, print both hashes and exit 1 (a CI check that the physics "
                  "did not change)")
      ->check(kNotEmpty);
  sub->add_option("--solver-error", o->solver_error,
                  "write, for the steps of --at, each solve's error against its exact solution "
                  "(Siconos' Lemke method, polished) to this CSV: step, t (s), solve, rows, "
                  "method (exact, engine, pgs, jacobi), sweeps, then |lambda - lambda*| (N, to "
                  "the nearest exact solution), relative, impulse error (N s), velocity error "
                  "(m/s), Signorini force (N), velocity (m/s) and complementarity (W), friction "
                  "violation (N), natural-map residual (N); pgs and jacobi start from 0. Missing "
                  "folders are created; --force as for --trace")
      ->check(kNotEmpty);
  sub->add_option("--at", o->at,
                  "with --solver-error: the steps whose solves are measured, comma-separated "
                  "step indices in [0, steps - 1] (0 is the first step; default: the last)")
      ->check(kNotEmpty);
  sub->add_option("--sweeps", o->sweeps,
                  "with --solver-error: the sweep counts of pgs and jacobi, comma-separated "
                  "integers in [0, " + std::to_string(kMaxSolverErrorSweeps) + "] (default " +
                  std::string(kDefaultSweeps) + ")")
      ->check(kNotEmpty);
  add_max_work_option(*sub, o->max_work);
  add_world_options(*sub, o->overrides);
  return {sub, [o, argc, argv] { return run_simulate(*o, argc, argv); }};
}

}  // namespace cps::cli
