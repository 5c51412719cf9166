#include "report/run.h"

#include "options/options.h"
#include "report/references.h"
#include "report/tasks.h"
#include "report/timing.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

namespace cps::cli {
namespace {

// A measure at the CSV's precision (see RunResult).
double csv(double v) { return at_csv_precision(v); }

// Positions of the movable bodies (m) once `spec` has been stepped to time t (s), or nullopt if
// the run blew up on the way (see sane_state).
std::optional<std::vector<Vec3>> positions_at(const RunSpec& spec, double t) {
  scenes::Run run = scenes::make_run(spec.scene_def(), spec.overrides());
  run.world.step();  // at least one step, as every run
  while (scenes::short_of(run.world, t)) {
    if (!sane_state(run.world)) return std::nullopt;
    run.world.step();
  }
  if (!sane_state(run.world)) return std::nullopt;
  return scenes::movable_positions(run.world);
}

// The reference of a run at its scene's trajectory time: the positions (nullopt if the reference
// blew up); check_m (m), the RMS distance between the reference and the same run at half its
// substeps; and the order the three runs at 4, 8 and 16 substeps show and the reference's own
// error it gives (observed_order). Where contacts make the scene chaotic the distances do not
// shrink with dt, and trajectory errors below them mean nothing.
struct Reference {
  std::optional<std::vector<Vec3>> positions;
  double check_m = std::nan("");
  ObservedOrder observed;
};

// The reference of `spec` (its solver, iterations and substeps replaced); computed once per
// process and kept (threads that ask for another reference do not wait for this one).
const Reference& reference_of(const RunSpec& spec) {
  static OnceCache<Reference> cache;
  RunSpec ref = spec;
  ref.solver = SolverKind::pgs;
  ref.iterations = kReferenceIterations;
  ref.substeps = reference_substeps(spec.quick);
  ref.warm_start = 0.0;  // one reference for the cold and the warm runs: the paper's start
  // The quick sweep's runs have shorter horizons but the same trajectory time: one reference.
  return cache.get(ref.id(), [&] {
    const double t = trajectory_time_of(ref.scene_def(), spec.quick);
    Reference r;
    r.positions = positions_at(ref, t);
    RunSpec half = ref;
    half.substeps = ref.substeps / 2;
    const std::optional<std::vector<Vec3>> at_half = positions_at(half, t);
    RunSpec quarter = ref;
    quarter.substeps = ref.substeps / 4;
    const std::optional<std::vector<Vec3>> at_quarter = positions_at(quarter, t);
    if (r.positions && at_half) r.check_m = scenes::rms_distance(*r.positions, *at_half);
    if (at_quarter && at_half && r.positions) {
      r.observed = observed_order(scenes::rms_distance(*at_quarter, *at_half), r.check_m);
    }
    return r;
  });
}

// Largest and RMS of a measure over samples.
struct Spread {
  double max = 0.0;
  double sum_sq = 0.0;
  std::int64_t n = 0;
  void add(double v) {
    max = std::max(max, v);
    sum_sq += v * v;
    ++n;
  }
};

// The error run of a spec: the run itself (residuals, metrics) and what was measured after every
// step.
struct ErrorRun {
  scenes::Run run;
  Spread penetration;          // m, every contact of every step
  Spread rod_error;            // m, every rod of every step
  std::vector<Vec3> at_traj;   // positions at the trajectory time; empty if not reached
  std::optional<double> diverged_at;  // s
  std::string diverged_why;           // state_fault's words, or the bound passed
};

// Adds the contacts' penetrations and the rods' length errors of the world's last step.
void observe_errors(const World& world, ErrorRun& e) {
  for (const Manifold& m : world.manifolds()) {
    for (int i = 0; i < m.count; ++i) {
      e.penetration.add(std::max(0.0, m.contacts[static_cast<std::size_t>(i)].depth));
    }
  }
  for (const DistanceConstraint& d : world.distances()) {
    Vec3 a;
    Vec3 b;
    distance_endpoints(d, world.bodies(), a, b);
    e.rod_error.add(std::abs((b - a).norm() - d.length));
  }
}

// Steps the error run to `horizon` (s), measuring every step, and records the positions at
// t_traj (s). A run has diverged when its state is not finite or its penetration or rod error
// passes the size of the largest movable body (bodies then pass through each other, rods
// stretch past any shape in the scene): its numbers measure the blow-up, not the method's
// accuracy.
ErrorRun error_run(const scenes::Scene& scene, scenes::Overrides o, double horizon, double t_traj) {
  o.set("measure_residual", true);
  ErrorRun e{scenes::make_run(scene, o), {}, {}, {}, {}, {}};
  World& world = e.run.world;
  const double largest = scenes::largest_body_size(world);
  const double size_bound = largest > 0.0 ? largest : kInfinity;
  while (scenes::short_of(world, horizon)) {
    e.run.step();
    if (const std::string fault = state_fault(world); !fault.empty()) {
      e.diverged_at = world.time();
      e.diverged_why = fault;
      break;
    }
    observe_errors(world, e);
    if (e.at_traj.empty() && !scenes::short_of(world, t_traj)) e.at_traj = scenes::movable_positions(world);
    if (e.penetration.max > size_bound || e.rod_error.max > size_bound) {
      e.diverged_at = world.time();
      const bool pen = e.penetration.max > size_bound;
      e.diverged_why = std::string(pen ? "penetration " : "rod error ") +
                       number(pen ? e.penetration.max : e.rod_error.max) +
                       " m past the largest body's size " + number(size_bound) + " m";
      break;
    }
  }
  return e;
}

// A run that diverged before the trajectory time steps on to it (the physics alone) while its
// state stays finite: how far the blow-up has carried the bodies by then is its trajectory
// error. A step that refuses the blown-up state (too many contacts) ends it without one.
void step_on_to(ErrorRun& e, double t_traj) {
  try {
    World& world = e.run.world;
    while (sane_state(world) && scenes::short_of(world, t_traj)) world.step();
    if (sane_state(world)) e.at_traj = scenes::movable_positions(world);
  } catch (const std::exception&) {
    e.at_traj.clear();
  }
}

// The error run's measures into `r`: residuals, penetration (with collision), rod errors (with
// rods) and, if it did not diverge, the scene's metrics.
void record_errors(const ErrorRun& e, RunResult& r) {
  const World& world = e.run.world;
  r.diverged = e.diverged_at.has_value();
  if (e.diverged_at) r.diverged_at_s = csv(*e.diverged_at);
  if (e.diverged_at) r.diverged_why = e.diverged_why;
  const ResidualStats& res = world.residual();
  if (res.rows > 0) {  // no rows: no solve of A lambda = b was made (xpbd, avbd), so no residual
    r.residual_max_N = csv(res.max);
    r.residual_rms_N = csv(res.rms());
  }
  const auto rms = [](const Spread& s) {
    return std::sqrt(s.sum_sq / static_cast<double>(s.n ? s.n : 1));
  };
  if (world.def().collision) {
    r.penetration_max_m = csv(e.penetration.max);
    r.penetration_rms_m = csv(e.penetration.n ? rms(e.penetration) : 0.0);
  }
  if (!world.distances().empty()) {
    r.rod_error_max_m = csv(e.rod_error.max);
    r.rod_error_rms_m = csv(rms(e.rod_error));
  }
  if (r.diverged) return;
  // The numeric entries of the scene's metrics (booleans as 0/1, arrays and nulls left out).
  const nlohmann::json metrics = e.run.metrics->report();
  for (const auto& [key, value] : metrics.items()) {
    if (value.is_number()) r.metrics[key] = csv(value.get<double>());
    if (value.is_boolean()) r.metrics[key] = value.get<bool>() ? 1.0 : 0.0;
  }
  if (metrics.contains("max_phase_error_deg")) {
    r.phase_error_deg = csv(metrics["max_phase_error_deg"].get<double>());
  }
  if (metrics.contains("energy_drift_rel")) {
    r.energy_drift_rel = csv(metrics["energy_drift_rel"].get<double>());
  }
}

// Steps a fresh copy of the timed run to its end: steps and simulated time into `t`.
void step_copy(scenes::Run& run, TimedRun& t) {
  do {
    run.world.step();
  } while (scenes::short_of(run.world, t.until_s));
  t.steps = run.world.counters().steps;
  t.simulated_s = run.world.time();
}

// One repeat of `t`: its copies made (untimed), then stepped one after another under the
// thread's CPU clock. Returns the CPU seconds per copy. Before the copies are made, a block of
// a pseudo-random size (0 to 64 KiB in 16-byte steps, from a fixed seed) is allocated and held
// through the repeat: it moves where the worlds' buffers land on the heap, so that a repeat's
// memory layout (cache set conflicts, 4 KiB aliasing) varies from repeat to repeat instead of
// one layout holding for every repeat of a run in a process (Mytkowicz et al. 2009, "Producing
// wrong data without doing anything obviously wrong"). A guard, not a measured cure: see
// docs/benchmarks.md (Run time of cps report) for what it did and did not change here.
double time_repeat(TimedRun& t) {
  thread_local std::mt19937 layout(26);
  const std::vector<char> pad(16 * static_cast<std::size_t>(layout() % 4096), 1);
  std::vector<scenes::Run> copies;
  copies.reserve(static_cast<std::size_t>(t.copies));
  for (int k = 0; k < t.copies; ++k) copies.push_back(scenes::make_run(*t.scene, t.overrides));
  const double start = thread_cpu_seconds();
  for (scenes::Run& run : copies) step_copy(run, t);
  return (thread_cpu_seconds() - start) / static_cast<double>(t.copies);
}

// The most copies of a run in one repeat: a bound on the memory of the worlds made up front.
constexpr int kMaxCopies = 1000;

}  // namespace

std::string state_fault(const World& world) {
  for (const Body& b : world.bodies()) {
    if (!b.x.allFinite() || !b.p.allFinite() || !b.l.allFinite() || !b.o.coeffs().allFinite()) {
      return "not finite";
    }
    if (b.x.norm() > 1e6) return "a body past 1e6 m from the origin";
    if (b.velocity().norm() > 1e6) return "a body faster than 1e6 m/s";
  }
  return "";
}

bool sane_state(const World& world) { return state_fault(world).empty(); }

MeasuredRun measure_errors(const RunSpec& spec) {
  const scenes::Scene& scene = spec.scene_def();
  const double horizon = spec.horizon_s();
  const bool has_trajectory = !scene.report.has_reference_solution;
  const double t_traj = trajectory_time_of(scene, spec.quick);
  scenes::Overrides o = spec.overrides();
  RunResult r = result_of(spec);
  r.dt_s = csv(std::get<double>(*o.find("dt")));
  r.horizon_s = csv(horizon);

  const double cpu_start = thread_cpu_seconds();
  ErrorRun e = error_run(scene, o, horizon, t_traj);
  const double error_cpu_s = thread_cpu_seconds() - cpu_start;
  if (has_trajectory && e.diverged_at && e.at_traj.empty()) step_on_to(e, t_traj);
  record_errors(e, r);
  if (has_trajectory) {
    const Reference& ref = reference_of(spec);
    r.trajectory_time_s = csv(t_traj);
    r.reference_substeps = reference_substeps(spec.quick);
    r.reference_check_m = csv(ref.check_m);
    if (std::isfinite(ref.observed.order)) r.reference_order = csv(ref.observed.order);
    if (std::isfinite(ref.observed.error)) r.reference_error_m = csv(ref.observed.error);
    if (!e.at_traj.empty() && ref.positions) {
      r.trajectory_error_m = csv(scenes::rms_distance(e.at_traj, *ref.positions));
      // Not resolved where the reference's error is unknown (its runs do not converge).
      r.under_reference_error =
          !r.reference_error_m || *r.trajectory_error_m < *r.reference_error_m;
    }
  }
  const double until = e.diverged_at.value_or(horizon);
  const double work = run_work(e.run.world.bodies().size(), e.run.world.def(), until);
  o.set("measure_residual", false);
  return {std::move(r), TimedRun{&scene, std::move(o), until, work, 1, 0, 0.0, {}, error_cpu_s}};
}

void time_runs(const std::vector<TimedRun*>& runs, int repeats, double max_work, int jobs,
               const std::function<void(long long)>& progress) {
  long long done = 0;
  const auto report = [&](std::size_t) { progress(++done); };
  std::vector<std::function<void()>> warm_ups;
  for (TimedRun* t : runs) {
    warm_ups.push_back([t, repeats, max_work] {
      t->copies = 1;
      t->repeat_s.clear();
      const double warm_up = time_repeat(*t);  // untimed: discarded
      const double budget = t->work > 0.0 ? max_work / (t->work * repeats) : kMaxCopies;
      const double wanted = warm_up > 0.0 ? std::ceil(kMinRepeatSeconds / warm_up) : kMaxCopies;
      t->copies = static_cast<int>(std::clamp(std::min(wanted, std::floor(budget)), 1.0,
                                              static_cast<double>(kMaxCopies)));
    });
  }
  run_tasks(warm_ups, jobs, report);
  for (int round = 0; round < repeats; ++round) {
    std::vector<std::function<void()>> repeats_of_round;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      TimedRun* t = runs[round % 2 == 0 ? i : runs.size() - 1 - i];
      repeats_of_round.push_back([t] { t->repeat_s.push_back(time_repeat(*t)); });
    }
    run_tasks(repeats_of_round, jobs, report);
  }
}

void record_timing(const TimedRun& t, int jobs, RunResult& r) {
  if (t.repeat_s.empty() || !(t.simulated_s > 0.0)) return;
  const Quartiles q = quartiles(t.repeat_s);
  r.cpu_s_per_sim_s = csv(q.median / t.simulated_s);
  r.cpu_s_per_sim_s_q1 = csv(q.q1 / t.simulated_s);
  r.cpu_s_per_sim_s_q3 = csv(q.q3 / t.simulated_s);
  r.cpu_s_per_sim_s_min = csv(*std::min_element(t.repeat_s.begin(), t.repeat_s.end()) / t.simulated_s);
  r.us_per_step = csv(1e6 * q.median / static_cast<double>(std::max<std::int64_t>(t.steps, 1)));
  r.timing_repeats = static_cast<int>(t.repeat_s.size());
  r.runs_per_repeat = t.copies;
  r.timing_threads = jobs;
  r.machine = this_machine();
  r.build = this_build();
}

RunResult execute_run(const RunSpec& spec, int repeats, double max_work) {
  MeasuredRun m = measure_errors(spec);
  time_runs({&m.timing}, repeats, max_work, 1, [](long long) {});
  record_timing(m.timing, 1, m.result);
  return m.result;
}

}  // namespace cps::cli
