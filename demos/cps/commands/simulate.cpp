#include "commands/simulate.h"

#include "commands/solver_error.h"

#include "command.h"
#include "options/options.h"
#include "output/output.h"
#include "options/progress.h"
#include "energy_rise.h"
#include "options/diagnostics.h"
#include "state_hash.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

namespace cps::cli {
namespace {

nlohmann::json vec(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

long long energy_rows(long long steps, long long every) {
  return steps / every + 1 + (steps % every != 0 ? 1 : 0);
}

SimulateFiles::SimulateFiles(std::vector<SimulateTarget> targets, const std::string& scene, bool force)
    : targets_(std::move(targets)) {
  namespace fs = std::filesystem;
  const auto request = [&](const fs::path& folder, std::vector<std::string> files,
                           const std::string& option) {
    std::map<std::string, std::string> scenes;
    for (const std::string& f : files) scenes[f] = scene;
    return plan_output({.folder = folder,
                        .files = std::move(files),
                        .command = "simulate",
                        .use = FolderUse::shared,
                        .scenes = std::move(scenes),
                        .option = option,
                        .force = force});
  };
  // Each target alone first, so that a refusal names its own option.
  for (const SimulateTarget& t : targets_) {
    request(t.path.parent_path(), {t.path.filename().string()}, t.option);
  }
  // Then one plan per folder (the same folder by any path), with every target it receives.
  std::vector<fs::path> folders;                // absolute, normal
  std::vector<std::vector<std::size_t>> group;  // the targets of each folder
  for (std::size_t i = 0; i < targets_.size(); ++i) {
    const fs::path folder = targets_[i].path.parent_path();
    std::error_code ec;
    fs::path key = fs::weakly_canonical(fs::absolute(folder.empty() ? fs::path(".") : folder), ec);
    if (ec) key = fs::absolute(folder.empty() ? fs::path(".") : folder).lexically_normal();
    std::size_t k = 0;
    while (k < folders.size() && folders[k] != key) ++k;
    if (k == folders.size()) {
      folders.push_back(key);
      group.emplace_back();
    }
    for (const std::size_t j : group[k]) {
      if (targets_[j].path.filename() == targets_[i].path.filename()) {
        throw UsageError(targets_[i].option + " " + targets_[i].path.string() + ": the same file as " +
                         targets_[j].option + " " + targets_[j].path.string() +
                         "; give each option its own file");
      }
    }
    group[k].push_back(i);
  }
  for (const std::vector<std::size_t>& g : group) {
    std::vector<std::string> names;
    std::string options;
    for (const std::size_t i : g) {
      names.push_back(targets_[i].path.filename().string());
      options += (options.empty() ? "" : " or ") + targets_[i].option;
    }
    plans_.push_back(request(targets_[g.front()].path.parent_path(), names, options));
  }
}

void SimulateFiles::begin(const nlohmann::json& info) {
  info_ = info;
  for (const OutputPlan& plan : plans_) begin_output(plan, info_);
  for (const SimulateTarget& t : targets_) files_.push_back(std::make_unique<AtomicFile>(t.path));
}

void SimulateFiles::finish() {
  for (const std::unique_ptr<AtomicFile>& f : files_) f->commit();
  for (const OutputPlan& plan : plans_) end_output(plan, info_);
}

TraceWriter::TraceWriter(AtomicFile& file) : file_(&file) {
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

EnergyWriter::EnergyWriter(AtomicFile& file, long long every) : file_(&file), every_(every) {
  file_->write(kEnergyHeader);
  file_->write("\n");
}

void EnergyWriter::write(const World& world) {
  if (static_cast<long long>(world.counters().steps) % every_ == 0) row(world);
}

void EnergyWriter::write_last(const World& world) {
  if (static_cast<long long>(world.counters().steps) != last_step_) row(world);
}

void EnergyWriter::row(const World& world) {
  last_step_ = static_cast<long long>(world.counters().steps);
  const scenes::MechanicalEnergy e = scenes::mechanical_energy(world);
  char text[320];
  const int n = std::snprintf(text, sizeof text, "%lld,%.9g,%.12g,%.12g,%.12g,%.9g,%.9g\n",
                              last_step_, world.time(), e.kinetic_J, e.potential_J, e.total_J(),
                              scenes::deepest_contact(world), scenes::max_rod_error(world));
  file_->write(std::string_view(text, static_cast<std::size_t>(std::min<int>(n, sizeof text - 1))));
  ++rows_;
}

nlohmann::json simulate(const scenes::Scene& scene, scenes::Run& run, double seconds,
                        TraceWriter* trace, EnergyWriter* energy) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  if (trace == nullptr && energy == nullptr) {
    run.advance_to(seconds);
  } else {
    const auto write = [&] {
      if (trace != nullptr) trace->write(run.world);
      if (energy != nullptr) energy->write(run.world);
    };
    write();
    while (scenes::short_of(run.world, seconds)) {
      run.step();
      write();
    }
    if (energy != nullptr) energy->write_last(run.world);
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
  std::string energy;
  std::optional<long long> energy_every;  // steps; default 1
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
    for (const auto& [other, option] : {std::pair{o.trace, "--trace"}, std::pair{o.energy, "--energy"}}) {
      if (!other.empty() && std::filesystem::path(other).lexically_normal() ==
                                std::filesystem::path(o.solver_error).lexically_normal()) {
        throw UsageError("--solver-error " + o.solver_error + " is also the " + option +
                         " file: give each option its own file");
      }
    }
    solver_error = plan_solver_error(o.solver_error, o.at,
                                     o.sweeps.value_or(std::string(kDefaultSweeps)),
                                     std::llround(seconds / r.world.def().dt));
  }
  if (o.energy_every && o.energy.empty()) {
    throw UsageError("--energy-every " + std::to_string(*o.energy_every) +
                     ": it sets the rows of the --energy file; give --energy FILE too");
  }
  const long long every = o.energy_every.value_or(1);
  const long long steps = std::llround(seconds / r.world.def().dt);
  if (!o.energy.empty() && energy_rows(steps, every) > kMaxEnergyRows) {
    long long fits = std::max(every, steps / (kMaxEnergyRows - 1));
    while (energy_rows(steps, fits) > kMaxEnergyRows) ++fits;
    throw UsageError("--energy " + o.energy + ": " + std::to_string(steps) + " steps at one row every " +
                     std::to_string(every) + " would write " +
                     std::to_string(energy_rows(steps, every)) + " rows, more than the " +
                     std::to_string(kMaxEnergyRows) + " an energy file may have; give --energy-every " +
                     std::to_string(fits) + " or more, or fewer --seconds");
  }
  const long long bodies = static_cast<long long>(r.world.bodies().size());
  if (!o.trace.empty() && static_cast<double>(steps + 1) * static_cast<double>(bodies) > kMaxTraceRows) {
    const long long fits = std::max(0LL, kMaxTraceRows / std::max(1LL, bodies) - 1);
    throw UsageError("--trace " + o.trace + ": " + std::to_string(steps + 1) + " steps (step 0 and " +
                     std::to_string(steps) + " more) of " + std::to_string(bodies) +
                     " bodies would write more than the " + std::to_string(kMaxTraceRows) +
                     " rows a trace may have; give --seconds " +
                     shortest_decimal(static_cast<double>(fits) * r.world.def().dt) + " or less (" +
                     std::to_string(fits) + " steps), or --energy FILE for one row a step");
  }
  // The budget covers the trace too: a row is one body's state written, one body-iteration.
  const double trace_work = o.trace.empty() ? 0.0 : static_cast<double>(steps + 1) * static_cast<double>(bodies);
  const double work = run_work(r.world.bodies().size(), r.world.def(), seconds);
  if (work + trace_work > o.max_work) {
    throw UsageError("--trace " + o.trace + ": the run's " + count_text(work) + " body-iterations and the trace's " +
                     count_text(trace_work) + " rows (one body-iteration each) pass the budget of " +
                     count_text(o.max_work) + " body-iterations a run may take (--max-work); give a "
                     "larger --max-work, or fewer --seconds");
  }
  // Every file is checked before any is written: the trace's and energy's folders and the solver
  // error's are planned; the first two are begun before the run, the last when it is written.
  const std::string source = scene_source(scene->name);
  std::vector<SimulateTarget> targets;
  if (!o.trace.empty()) targets.push_back({o.trace, "--trace"});
  if (!o.energy.empty()) targets.push_back({o.energy, "--energy"});
  std::optional<SimulateFiles> files;
  std::optional<TraceWriter> trace;
  std::optional<EnergyWriter> energy_csv;
  if (!targets.empty()) files.emplace(targets, source, o.force);
  std::optional<SolverErrorWriter> errors;
  if (solver_error) {
    errors.emplace(std::move(*solver_error), source, o.force,
                   run_info("simulate", argc, argv,
                            {{"scene", scene->name},
                             {"seconds", seconds},
                             {"solver_error", o.solver_error},
                             {"overrides", overrides_json(o.overrides)},
                             {"parameters", parameters_json(r.world.def())}}));
    errors->observe(r.world, o.max_work - work - trace_work);
  }
  if (files) {
    nlohmann::json info = {{"scene", scene->name},
                           {"seconds", seconds},
                           {"overrides", overrides_json(o.overrides)},
                           {"parameters", parameters_json(r.world.def())}};
    if (!o.trace.empty()) info["trace"] = o.trace;
    if (!o.energy.empty()) {
      info["energy"] = o.energy;
      info["energy_every"] = every;
    }
    files->begin(run_info("simulate", argc, argv, info));
    std::size_t i = 0;
    if (!o.trace.empty()) trace.emplace(files->file(i++));
    if (!o.energy.empty()) energy_csv.emplace(files->file(i++), every);
  }
  // Steps on stderr, only once the run has taken 2 s (short runs and --json stay clean).
  Progress progress("simulate " + o.scene, std::llround(seconds / r.world.def().dt), "steps", 2.0);
  r.metrics = std::make_unique<ProgressMetrics>(std::move(r.metrics), progress);
  const auto energy = scenes::watch_energy_rise(r);  // the warning below; changes no output
  const nlohmann::json summary = simulate(*scene, r, seconds, trace ? &*trace : nullptr,
                                          energy_csv ? &*energy_csv : nullptr);
  progress.finish();
  for (const scenes::RunWarning& w : scenes::run_warnings(scene->name, "", r, *energy)) {
    warn(w.kind, w.text, w.brief, w.docs);
  }
  if (files) files->finish();
  if (trace) {
    note("trace: " + std::to_string(trace->rows()) + " rows (" +
         std::to_string(r.world.bodies().size()) + " bodies per step) in " + o.trace);
  }
  if (energy_csv) {
    note("energy: " + std::to_string(energy_csv->rows()) + " rows (one every " +
         std::to_string(every) + (every == 1 ? " step" : " steps") + ", and the last) in " + o.energy);
  }
  if (errors) {
    const long rows = errors->finish();
    note("solver-error: " + std::to_string(rows) + " rows in " + o.solver_error +
         "; the solves' rows, bounds and exact lambda in " +
         solver_error_rows_path(o.solver_error).string());
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
  sub->add_option("--energy", o->energy,
                  "write the energy over time to this CSV: step, t (s), kinetic energy "
                  "(translational + rotational), potential energy of gravity (datum: the origin, "
                  "y = 0 for the default gravity) and their total (J), the deepest contact "
                  "penetration of the step and the largest rod error (m); one row per step (or "
                  "per --energy-every steps), step 0 = as built, at most 1e6 rows; missing "
                  "folders are created, and the folder's run.json lists the files cps wrote there")
      ->check(kNotEmpty);
  sub->add_option_function<std::string>(
         "--energy-every",
         [o](const std::string& text) { o->energy_every = std::stoll(text); },
         "write a row of --energy every N steps (an integer in [1, 1e7]; default 1), and the "
         "last step")
      ->type_name("N")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            long long v = 0;
            const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
            if (text.empty() || ec != std::errc() || end != text.data() + text.size() || v < 1 ||
                static_cast<double>(v) > kMaxSteps) {
              return text + ": not allowed; give a decimal integer in [1, 10000000] (steps)";
            }
            return {};
          },
          ""));
  sub->add_flag("--force", o->force,
                "let --trace, --energy or --solver-error replace a file of that name that no "
                "earlier cps run wrote (its "
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
                  "method (exact, engine, pgs, jacobi, and coloured-pgs under --solver "
                  "coloured-pgs), sweeps, then |lambda - lambda*| (N, to "
                  "the nearest exact solution), relative, impulse error (N s), velocity error "
                  "(m/s), Signorini force (N), velocity (m/s) and complementarity (W), friction "
                  "violation (N), natural-map residual (N); the sweeps start from 0. Missing "
                  "folders are created; --force as for --trace")
      ->check(kNotEmpty);
  sub->add_option("--at", o->at,
                  "with --solver-error: the steps whose solves are measured, comma-separated "
                  "step indices in [0, steps - 1] (0 is the first step; default: the last)")
      ->check(kNotEmpty);
  sub->add_option("--sweeps", o->sweeps,
                  "with --solver-error: the sweep counts of the re-solves, comma-separated "
                  "integers in [0, " + std::to_string(kMaxSolverErrorSweeps) + "] (default " +
                  std::string(kDefaultSweeps) + ")")
      ->check(kNotEmpty);
  add_max_work_option(*sub, o->max_work);
  add_world_options(*sub, o->overrides);
  add_diagnostic_flags(*sub);
  return {sub, [o, argc, argv] { return run_simulate(*o, argc, argv); }};
}

}  // namespace cps::cli
