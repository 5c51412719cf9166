#include "report/push/cases.h"

#include "options/options.h"
#include "report/csv.h"
#include "report/mass_ratio.h"
#include "report/run.h"
#include "report/timing.h"
#include "divergence.h"
#include "scene_file.h"

#include <algorithm>
#include <stdexcept>

namespace cps::cli {
namespace {


const scenes::Scene* scene_named(const char* name) {
  const scenes::Scene* s = scenes::find_scene(name);
  if (!s) throw std::logic_error(std::string("report push: no scene ") + name);
  return s;
}

scenes::Overrides with_push(const Method& m) {
  scenes::Overrides o;
  o.set("push", ParameterValue(m.value));
  return o;
}

// Largest contact depth (m, >= 0) over the world's manifolds: those of its last step, made by
// its collide stage from the positions at the start of that step.
double manifold_overlap(const World& world) {
  double d = 0.0;
  for (const Manifold& m : world.manifolds()) {
    for (int i = 0; i < m.count; ++i) d = std::max(d, m.contacts[static_cast<std::size_t>(i)].depth);
  }
  return d;
}

// The resting state of a column: the movable bodies, taken in the order of their heights as
// built, stacked on the ground plane one on the next without overlap: each centre at the top of
// the one below plus its own half height (a box's extent along y, a ball's radius). Returns the
// resting centre height (m) of each movable body, in body order. The intersecting stack gives
// 1.2, 3.6, 6.0, 8.4, 10.8 m (cubes of half extent 1.2 m); sphere_in_box 1.0 m (the box of half
// extent 1 m) and 2.0 + 0.4 m (the ball of radius 0.4 m on it). Throws std::logic_error if the
// world has no ground plane (normal +y).
std::vector<double> rest_heights(const World& world) {
  std::optional<double> ground;
  std::vector<int> movable;
  for (int i = 0; i < static_cast<int>(world.bodies().size()); ++i) {
    const Body& b = world.body(i);
    if (!b.is_static()) {
      movable.push_back(i);
    } else if (b.shape.kind == ShapeKind::plane && b.shape.normal.isApprox(Vec3::UnitY())) {
      ground = std::max(ground.value_or(-kInfinity), b.x.y() + b.shape.offset);
    }
  }
  if (!ground) throw std::logic_error("report push: the scene has no ground plane");
  std::vector<int> by_height = movable;
  std::stable_sort(by_height.begin(), by_height.end(),
                   [&](int a, int b) { return world.body(a).x.y() < world.body(b).x.y(); });
  std::vector<double> rest(world.bodies().size(), 0.0);
  double top = *ground;
  for (const int i : by_height) {
    const Body& b = world.body(i);
    double half = b.shape.radius;
    if (b.shape.kind == ShapeKind::box) {
      const Mat3 r = b.rotation();
      half = std::abs(r(1, 0)) * b.shape.half_extents.x() + std::abs(r(1, 1)) * b.shape.half_extents.y() +
             std::abs(r(1, 2)) * b.shape.half_extents.z();
    }
    rest[static_cast<std::size_t>(i)] = top + half;
    top += 2.0 * half;
  }
  std::vector<double> heights;
  for (const int i : movable) heights.push_back(rest[static_cast<std::size_t>(i)]);
  return heights;
}

// The potential energy (J) of the movable bodies of `w` at their resting heights `rest` (m, in
// body order).
double rest_potential_energy(const World& w, const std::vector<double>& rest) {
  double pe = 0.0;
  std::size_t k = 0;
  for (const Body& b : w.bodies()) {
    if (b.is_static()) continue;
    Vec3 x = b.x;
    x.y() = rest[k++];
    pe -= b.mass * w.def().gravity.dot(x);
  }
  return pe;
}

// The measures of a column that did not diverge, from its last state and its series: the final
// heights and their largest error, when the overlaps were resolved for good, the energy injected
// above the resting column's (J; energy_max: the largest KE + PE over the run).
void finish_column(const World& w, double energy_max, double rest_pe, ColumnResult& r) {
  r.series.back().overlap_m = scenes::max_penetration_now(w);
  r.energy_injected_J = energy_max - rest_pe;
  for (const Body& b : w.bodies()) {
    if (!b.is_static()) r.final_heights.push_back(b.x.y());
  }
  r.height_error_m = 0.0;
  for (std::size_t k = 0; k < r.final_heights.size(); ++k) {
    r.height_error_m = std::max(r.height_error_m, std::abs(r.final_heights[k] - r.rest[k]));
  }
  for (const Sample& s : r.series) {
    if (s.overlap_m >= kResolvedOverlap) {
      r.resolved_at.reset();
    } else if (!r.resolved_at) {
      r.resolved_at = s.t;
    }
  }
}

// When `run` diverged, as every run's watch finds it (divergence.h: a state not finite, or a
// contact past a body's size for kDivergedSteps steps; its time the first step that showed it),
// or when its state left sane_state's bounds (1e6 m, 1e6 m/s); nullopt while neither.
std::optional<double> diverged_at_of(const scenes::Run& run) {
  if (run.divergence && run.divergence->found()) return run.divergence->found()->at_s;
  if (!sane_state(run.world)) return run.world.time();
  return std::nullopt;
}

// Runs `scene` with push `m` for `seconds` (s) and measures, from the state after every step:
//  - the largest overlap (m): at the state of time t - dt the largest contact depth over
//    World::manifolds() after the step to t (its collide stage saw that state), and at the
//    last state the same narrow phase run on every pair (scenes::max_penetration_now);
//    resolved_at is the first time t from which it stays under kResolvedOverlap to the end;
//  - peak_speed_mps: the largest speed of any movable body's centre of mass over the states
//    after step 0 (the state as built is at rest);
//  - energy_injected_J: the largest kinetic plus potential energy (KE translational and
//    rotational, PE = -m g . x) over every state from t = 0, minus the potential energy of the
//    column at rest (rest_heights, from the bodies' masses, shapes and the world's gravity);
//  - the final heights of the movable bodies' centres and height_error_m, the largest
//    |final - rest| among them.
// A run that diverges (diverged_at_of) ends there (diverged_at) with nothing resolved and no
// final heights.
ColumnResult run_column(const scenes::Scene& scene, const Method& m, double seconds) {
  scenes::Run run = make_run_or_usage_error(scene, with_push(m));
  const World& w = run.world;
  ColumnResult r;
  r.seconds = seconds;
  r.dt = w.def().dt;
  r.rest = rest_heights(w);
  const double rest_pe = rest_potential_energy(w, r.rest);
  double energy_max = scenes::kinetic_energy(w) + scenes::potential_energy(w);
  r.series.push_back({0.0, 0.0, largest_speed(w)});
  while (scenes::short_of(w, seconds)) {
    run.step();
    r.series.back().overlap_m = manifold_overlap(w);  // the state the step started from
    if (const std::optional<double> at = diverged_at_of(run)) {
      r.diverged_at = at;
      break;
    }
    r.series.push_back({w.time(), 0.0, largest_speed(w)});
    r.peak_speed_mps = std::max(r.peak_speed_mps, r.series.back().speed_mps);
    energy_max = std::max(energy_max, scenes::kinetic_energy(w) + scenes::potential_energy(w));
  }
  if (!r.diverged_at) finish_column(w, energy_max, rest_pe, r);
  for (const Sample& s : r.series) r.max_overlap_m = std::max(r.max_overlap_m, s.overlap_m);
  return r;
}

// Microseconds per step (CPU time of this thread around World::step only) of `scene` with push `m` over its
// bench window (Scene::bench: the intersecting stack's first 0.1 s, from t = 0): one untimed
// repeat, then the median of kCostRepeats repeats, each from the scene as built.
double window_us_per_step(const scenes::Scene& scene, const Method& m) {
  std::vector<double> us;
  for (int rep = 0; rep <= kCostRepeats; ++rep) {
    scenes::Run run = make_run_or_usage_error(scene, with_push(m));
    while (scenes::short_of(run.world, scene.bench.start_s)) run.world.step();
    const double end = scene.bench.start_s + scene.bench.seconds;
    double cpu = 0.0;
    int steps = 0;
    while (scenes::short_of(run.world, end)) {
      const double a = thread_cpu_seconds();
      run.world.step();
      cpu += thread_cpu_seconds() - a;
      ++steps;
    }
    if (rep > 0 && steps > 0) us.push_back(1e6 * cpu / steps);
  }
  std::sort(us.begin(), us.end());
  return us.empty() ? std::nan("") : us[us.size() / 2];
}

// Steps `run` to `seconds` (s), its metrics observing every step, and stops early where it
// diverges (diverged_at_of); adds the CPU time of this thread in World::step (s) to step_cpu_s
// and the steps to `steps`. Returns when it diverged (s), if it did.
std::optional<double> step_observed(scenes::Run& run, double seconds, double& step_cpu_s,
                                    long long& steps) {
  while (scenes::short_of(run.world, seconds)) {
    const double start = thread_cpu_seconds();
    run.world.step();
    step_cpu_s += thread_cpu_seconds() - start;
    ++steps;
    run.metrics->observe(run.world);
    if (const std::optional<double> at = diverged_at_of(run)) return at;
  }
  return std::nullopt;
}

MetricsResult run_metrics(const scenes::Scene& scene, const Method& m, double seconds) {
  scenes::Run run = make_run_or_usage_error(scene, with_push(m));
  MetricsResult r;
  r.dt = run.world.def().dt;
  r.seconds = seconds;
  r.diverged_at = step_observed(run, seconds, r.step_cpu_s, r.steps);
  r.metrics = run.metrics->report();
  return r;
}

// The hard cases in push.md's order, each with its duration (s) in the full and the quick plan:
// the heavy ones over their default (10 s), the long runs over their 10,000 steps or, quick,
// kQuickLongRunSteps steps of their dt.
std::vector<HardCase> hard_cases(bool quick) {
  std::vector<HardCase> list;
  for (const char* name : {"heavy_on_light", "heavy_rope"}) {
    const scenes::Scene* s = scene_named(name);
    list.push_back({s, s->default_seconds, true});
  }
  for (const char* name : {"stack_20_long", "pyramid_20_rows_long"}) {
    const scenes::Scene* s = scene_named(name);
    const double dt = s->world_def().dt;
    list.push_back({s, quick ? kQuickLongRunSteps * dt : s->default_seconds, false});
  }
  return list;
}

}  // namespace

bool HardResult::held_throughout() const {
  if (diverged_at || !metrics.value("holds", false)) return false;
  return metric(metrics, "survival_s") >= seconds - 0.5 * dt;
}

HardResult run_hard_case(const scenes::Scene& scene, const Method& m, double seconds,
                         std::optional<double> k_start) {
  scenes::Overrides o = with_push(m);
  if (k_start) o.set("avbd_k_start", ParameterValue(*k_start));
  scenes::Run run = make_run_or_usage_error(scene, o);
  HardResult r;
  r.scene = std::string(scene.name);
  if (k_start) r.variant = "avbd_k_start=" + number(*k_start);
  r.seconds = seconds;
  r.dt = run.world.def().dt;
  r.iterations = run.world.def().iterations;
  r.has_rods = !run.world.distances().empty();
  r.diverged_at = step_observed(run, seconds, r.step_cpu_s, r.steps);
  r.metrics = run.metrics->report();
  return r;
}

std::optional<Method> push_method_named(const std::string& name) {
  for (const Method& m : push_methods()) {
    if (m.name == name) return m;
  }
  return std::nullopt;
}

double largest_speed(const World& world) {
  double v = 0.0;
  for (const Body& b : world.bodies()) {
    if (!b.is_static()) v = std::max(v, b.velocity().norm());
  }
  return v;
}

std::vector<Method> push_methods() {
  std::vector<Method> list;
  for (const Choice& c : parameter("push").choices) {
    std::string label(c.name);
    const std::string title(c.title), source(c.source);
    if (!title.empty() || !source.empty()) {
      label += " (" + title + (!title.empty() && !source.empty() ? ", " : "") + source + ")";
    }
    list.push_back({std::string(c.name), label, c.value});
  }
  return list;
}

PushPlan plan_push_report(bool quick) {
  PushPlan p;
  p.quick = quick;
  p.methods = push_methods();
  p.intersecting = scene_named("intersecting_stack");
  p.sphere = scene_named("sphere_in_box");
  p.stack = scene_named("stack");
  p.grid = scene_named("pendulum_grid");
  p.wave = scene_named("pendulum_wave");
  p.stack_seconds = quick ? kQuickStackSeconds : kStackSeconds;
  p.grid_seconds = quick ? std::min(p.grid->default_seconds, kQuickPendulumSeconds) : p.grid->default_seconds;
  p.wave_seconds = quick ? std::min(p.wave->default_seconds, kQuickPendulumSeconds) : p.wave->default_seconds;
  p.hard = hard_cases(quick);
  return p;
}

MethodResults run_method(const PushPlan& plan, const Method& m, const std::function<void()>& tick) {
  MethodResults r;
  r.method = m;
  r.intersecting = run_column(*plan.intersecting, m, kColumnSeconds);
  tick();
  r.sphere = run_column(*plan.sphere, m, kColumnSeconds);
  tick();
  r.intersecting_us = window_us_per_step(*plan.intersecting, m);
  tick();
  r.stack = run_metrics(*plan.stack, m, plan.stack_seconds);
  tick();
  for (const double ratio : kMassRatios) {
    if (run_pair(ratio, SolverKind::pgs, static_cast<PushMode>(m.value), kPairIterations, kPairSeconds).held) {
      r.held.push_back(ratio);
    }
  }
  tick();
  r.grid = run_metrics(*plan.grid, m, plan.grid_seconds);
  tick();
  r.wave = run_metrics(*plan.wave, m, plan.wave_seconds);
  tick();
  for (const HardCase& h : plan.hard) {
    r.hard.push_back(run_hard_case(*h.scene, m, h.seconds));
    tick();
  }
  if (m.name == kTunedMethod) {
    for (const HardCase& h : plan.hard) {
      if (!h.tuned_avbd) continue;
      r.hard.push_back(run_hard_case(*h.scene, m, h.seconds, kTunedAvbdKStart));
      tick();
    }
  }
  return r;
}

int push_case_count(const PushPlan& plan, const Method& m) {
  int n = 7 + static_cast<int>(plan.hard.size());
  if (m.name == kTunedMethod) {
    n += static_cast<int>(std::count_if(plan.hard.begin(), plan.hard.end(),
                                        [](const HardCase& h) { return h.tuned_avbd; }));
  }
  return n;
}

double metric(const nlohmann::json& metrics, const char* key) {
  return metrics.contains(key) && metrics[key].is_number() ? metrics[key].get<double>()
                                                             : std::nan("");
}

}  // namespace cps::cli
