// `cps report push`: the push methods side by side (see report_push.h). Each method runs every
// case at the scene's own settings with only the world parameter push changed; the measures are
// defined once, in kLegend (written into push.md) and at the functions that compute them.
#include "report/report_push.h"

#include "output/atomic_file.h"
#include "options/options.h"
#include "output/output.h"
#include "options/progress.h"
#include "report/report.h"
#include "scene.h"
#include "stress/mass_ratio.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace cps::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// An overlap counts as resolved under this depth (m): 1 mm, a thousandth of the cubes' size.
constexpr double kResolvedOverlap = 1e-3;
// The intersecting stack's and sphere_in_box's runs (s): the intersecting stack's default
// duration, long enough for a method that brings the column to rest to have done so.
constexpr double kColumnSeconds = 4.0;
// The stack's run (s): 600 s, and 60 s in --quick.
constexpr double kStackSeconds = 600.0;
constexpr double kQuickStackSeconds = 60.0;
// In --quick the pendulum scenes run at most this long (s): the pendulum grid its whole 10 s,
// the pendulum wave 10 of its 62 s.
constexpr double kQuickPendulumSeconds = 10.0;
// Timed repeats of the intersecting stack's first window (the median counts), after one
// untimed repeat that warms the caches.
constexpr int kCostRepeats = 5;
// The mass ratio pairs run at the paper's solver and iteration count.
constexpr int kPairIterations = 25;
// The diagrams' floors: values under them are drawn on them (log axes cannot show 0).
constexpr double kOverlapFloor = 1e-6;  // m
constexpr double kSpeedFloor = 1e-4;    // m/s

// One push method: a choice of the world parameter push.
struct Method {
  std::string name;   // "baumgarte"
  std::string label;  // "baumgarte (push factor, Sec. 5.3)"
  int value = 0;      // the enum's value
};

std::vector<Method> methods() {
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

const scenes::Scene& scene_named(const char* name) {
  const scenes::Scene* s = scenes::find_scene(name);
  if (!s) throw std::logic_error(std::string("report push: no scene ") + name);
  return *s;
}

scenes::Overrides with_push(const Method& m) {
  scenes::Overrides o;
  o.set("push", ParameterValue(m.value));
  return o;
}

// Seconds (s) between two clock readings.
double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
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

// Largest speed |v| (m/s) of the centre of mass of any movable body.
double largest_speed(const World& world) {
  double v = 0.0;
  for (const Body& b : world.bodies()) {
    if (!b.is_static()) v = std::max(v, b.velocity().norm());
  }
  return v;
}

// Gravitational potential energy (J) of the movable bodies: sum of -m g . x.
double potential_energy(const World& world) {
  double e = 0.0;
  for (const Body& b : world.bodies()) {
    if (!b.is_static()) e -= b.mass * world.def().gravity.dot(b.x);
  }
  return e;
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

// One sample of a run's time series: time (s), largest overlap (m) of the state at that time,
// largest body speed (m/s).
struct Sample {
  double t = 0.0;
  double overlap_m = 0.0;
  double speed_mps = 0.0;
};

// A column pushed out of overlap (the intersecting stack, sphere_in_box): see run_column.
struct ColumnResult {
  double seconds = 0.0;
  double dt = 0.0;
  std::optional<double> diverged_at;  // s
  std::optional<double> resolved_at;  // s: overlaps under kResolvedOverlap from here to the end
  double max_overlap_m = 0.0;
  double peak_speed_mps = 0.0;
  double energy_injected_J = std::nan("");
  double height_error_m = std::nan("");
  std::vector<double> final_heights;  // m, movable bodies in body order
  std::vector<double> rest;           // m, the same bodies at rest (rest_heights)
  std::vector<Sample> series;         // every step's state, from t = 0
};

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
// A run whose state stops being sane (sane_state) ends there (diverged_at) with nothing
// resolved and no final heights.
ColumnResult run_column(const scenes::Scene& scene, const Method& m, double seconds) {
  scenes::Run run = make_run_or_usage_error(scene, with_push(m));
  const World& w = run.world;
  ColumnResult r;
  r.seconds = seconds;
  r.dt = w.def().dt;
  r.rest = rest_heights(w);
  double rest_pe = 0.0;
  {
    std::size_t k = 0;
    for (const Body& b : w.bodies()) {
      if (b.is_static()) continue;
      Vec3 x = b.x;
      x.y() = r.rest[k++];
      rest_pe -= b.mass * w.def().gravity.dot(x);
    }
  }
  double energy_max = scenes::kinetic_energy(w) + potential_energy(w);
  r.series.push_back({0.0, 0.0, largest_speed(w)});
  while (w.time() + 0.5 * r.dt < seconds) {
    run.step();
    r.series.back().overlap_m = manifold_overlap(w);  // the state the step started from
    if (!sane_state(w)) {
      r.diverged_at = w.time();
      break;
    }
    r.series.push_back({w.time(), 0.0, largest_speed(w)});
    r.peak_speed_mps = std::max(r.peak_speed_mps, r.series.back().speed_mps);
    energy_max = std::max(energy_max, scenes::kinetic_energy(w) + potential_energy(w));
  }
  if (!r.diverged_at) {
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
  for (const Sample& s : r.series) r.max_overlap_m = std::max(r.max_overlap_m, s.overlap_m);
  return r;
}

// Microseconds per step (wall clock around World::step only) of `scene` with push `m` over its
// bench window (Scene::bench: the intersecting stack's first 0.1 s, from t = 0): one untimed
// repeat, then the median of kCostRepeats repeats, each from the scene as built.
double window_us_per_step(const scenes::Scene& scene, const Method& m) {
  std::vector<double> us;
  for (int rep = 0; rep <= kCostRepeats; ++rep) {
    scenes::Run run = make_run_or_usage_error(scene, with_push(m));
    const double dt = run.world.def().dt;
    while (run.world.time() + 0.5 * dt < scene.bench.start_s) run.world.step();
    const double end = scene.bench.start_s + scene.bench.seconds;
    double wall = 0.0;
    int steps = 0;
    while (run.world.time() + 0.5 * dt < end) {
      const auto a = Clock::now();
      run.world.step();
      wall += seconds_between(a, Clock::now());
      ++steps;
    }
    if (rep > 0 && steps > 0) us.push_back(1e6 * wall / steps);
  }
  std::sort(us.begin(), us.end());
  return us.empty() ? std::nan("") : us[us.size() / 2];
}

// A scene run for its metrics (scene.h's Metrics::report) over `seconds` (s): the metrics, the
// time the state stopped being sane (if it did), and the wall clock (s) spent in World::step
// alone and the steps taken.
struct MetricsResult {
  nlohmann::json metrics;
  std::optional<double> diverged_at;  // s
  double step_wall_s = 0.0;
  long long steps = 0;
  double dt = 0.0;
};

MetricsResult run_metrics(const scenes::Scene& scene, const Method& m, double seconds) {
  scenes::Run run = make_run_or_usage_error(scene, with_push(m));
  MetricsResult r;
  r.dt = run.world.def().dt;
  while (run.world.time() + 0.5 * r.dt < seconds) {
    const auto a = Clock::now();
    run.world.step();
    r.step_wall_s += seconds_between(a, Clock::now());
    ++r.steps;
    run.metrics->observe(run.world);
    if (!sane_state(run.world)) {
      r.diverged_at = run.world.time();
      break;
    }
  }
  r.metrics = run.metrics->report();
  return r;
}

// A metric's number, or NaN where it is missing or not a number (null: never happened).
double metric(const nlohmann::json& metrics, const char* key) {
  return metrics.contains(key) && metrics[key].is_number() ? metrics[key].get<double>()
                                                             : std::nan("");
}

// The columns of push.csv, in order; each carries its unit as a suffix (_s, _m, _mps, _J,
// _rel: a ratio, us_per_step: microseconds); push, case and the mass ratios have none.
const std::vector<std::string> kColumns = {
    "push", "case", "seconds_s", "dt_s", "diverged_at_s", "overlap_under_1mm_from_s",
    "max_overlap_m", "peak_speed_mps", "energy_injected_J", "final_height_error_m",
    "final_heights_m", "rest_heights_m", "max_drift_m", "slide_off_time_s", "mass_ratios_held",
    "largest_mass_ratio_held", "max_rod_error_m", "max_rod_error_rel", "max_phase_error_deg",
    "us_per_step", "timed_from_s", "timed_for_s"};

// Cell texts for times that did not happen and ratios that did not hold.
constexpr const char* kNever = "never";
constexpr const char* kNone = "none";

std::string numbers(const std::vector<double>& values) {
  std::string s;
  for (const double v : values) s += (s.empty() ? "" : " ") + number(v);
  return s;
}

std::string csv_of(const std::vector<Row>& rows) {
  std::ostringstream out;
  for (std::size_t c = 0; c < kColumns.size(); ++c) out << (c ? "," : "") << kColumns[c];
  out << "\n";
  for (const Row& r : rows) {
    for (std::size_t c = 0; c < kColumns.size(); ++c) {
      const auto it = r.find(kColumns[c]);
      out << (c ? "," : "") << (it == r.end() ? "" : it->second);
    }
    out << "\n";
  }
  return out.str();
}

Row column_row(const Method& m, const char* name, const ColumnResult& c) {
  Row r;
  r["push"] = m.name;
  r["case"] = name;
  r["seconds_s"] = number(c.seconds);
  r["dt_s"] = number(c.dt);
  if (c.diverged_at) r["diverged_at_s"] = number(*c.diverged_at);
  r["overlap_under_1mm_from_s"] = c.resolved_at ? number(*c.resolved_at) : kNever;
  r["max_overlap_m"] = number(c.max_overlap_m);
  r["peak_speed_mps"] = number(c.peak_speed_mps);
  r["energy_injected_J"] = number(c.energy_injected_J);
  r["final_height_error_m"] = number(c.height_error_m);
  r["final_heights_m"] = numbers(c.final_heights);
  r["rest_heights_m"] = numbers(c.rest);
  return r;
}

// The cases of one method, in the order of push.md's columns.
struct MethodResults {
  Method method;
  ColumnResult intersecting;
  ColumnResult sphere;
  double intersecting_us = std::nan("");
  MetricsResult stack;
  double stack_seconds = 0.0;
  std::vector<double> held;  // the mass ratios that held
  MetricsResult grid;
  double grid_seconds = 0.0;
  MetricsResult wave;
  double wave_seconds = 0.0;
};

std::vector<Row> rows_of(const MethodResults& r, const scenes::Scene& intersecting) {
  std::vector<Row> rows;
  Row is = column_row(r.method, "intersecting_stack", r.intersecting);
  is["us_per_step"] = number(r.intersecting_us);
  is["timed_from_s"] = number(intersecting.bench.start_s);
  is["timed_for_s"] = number(intersecting.bench.seconds);
  rows.push_back(is);
  rows.push_back(column_row(r.method, "sphere_in_box", r.sphere));
  const auto metrics_row = [&](const char* name, const MetricsResult& m, double seconds) {
    Row row;
    row["push"] = r.method.name;
    row["case"] = name;
    row["seconds_s"] = number(seconds);
    row["dt_s"] = number(m.dt);
    if (m.diverged_at) row["diverged_at_s"] = number(*m.diverged_at);
    return row;
  };
  Row stack = metrics_row("stack", r.stack, r.stack_seconds);
  stack["max_drift_m"] = number(metric(r.stack.metrics, "max_drift_m"));
  const double slide = metric(r.stack.metrics, "slide_off_time_s");
  stack["slide_off_time_s"] = std::isnan(slide) ? kNever : number(slide);
  stack["us_per_step"] =
      number(r.stack.steps ? 1e6 * r.stack.step_wall_s / static_cast<double>(r.stack.steps) : std::nan(""));
  stack["timed_from_s"] = "0";
  stack["timed_for_s"] = number(static_cast<double>(r.stack.steps) * r.stack.dt);
  rows.push_back(stack);
  Row pair;
  pair["push"] = r.method.name;
  pair["case"] = "mass_ratio";
  pair["seconds_s"] = number(kPairSeconds);
  pair["dt_s"] = number(scenes::mass_ratio_world_def().dt);
  pair["mass_ratios_held"] = r.held.empty() ? kNone : numbers(r.held);
  pair["largest_mass_ratio_held"] = r.held.empty() ? kNone : number(r.held.back());
  rows.push_back(pair);
  Row grid = metrics_row("pendulum_grid", r.grid, r.grid_seconds);
  grid["max_rod_error_m"] = number(metric(r.grid.metrics, "max_rod_error_m"));
  rows.push_back(grid);
  Row wave = metrics_row("pendulum_wave", r.wave, r.wave_seconds);
  wave["max_rod_error_rel"] = number(metric(r.wave.metrics, "max_rod_error_rel"));
  wave["max_phase_error_deg"] = number(metric(r.wave.metrics, "max_phase_error_deg"));
  rows.push_back(wave);
  return rows;
}

// A cell of push.md: the CSV's text, "-" where it is empty (does not apply, not measured), and
// "diverged at T s" for the measures of a case that diverged.
std::string md_cell(const std::vector<Row>& rows, const std::string& push, const std::string& kase,
                    const std::string& column) {
  for (const Row& r : rows) {
    if (r.at("push") != push || r.at("case") != kase) continue;
    const auto div = r.find("diverged_at_s");
    if (div != r.end() && !div->second.empty()) return "diverged at " + div->second + " s";
    const auto it = r.find(column);
    return it == r.end() || it->second.empty() ? "-" : it->second;
  }
  return "-";
}

// The legend of push.md: what each column is, precisely.
std::string legend(bool quick, double stack_seconds, const scenes::Scene& is,
                   const scenes::Scene& grid, double grid_seconds,
                   const scenes::Scene& wave, double wave_seconds) {
  std::ostringstream md;
  md << "Every push method of this build (the choices of the world parameter push, `--push NAME`) "
        "runs the same cases, each at the scene's own settings with only push changed"
     << (quick ? "; **--quick**: the stack over " + number(stack_seconds) +
                     " s instead of 600 s, the pendulum wave over " + number(wave_seconds) +
                     " s instead of its " + number(wave.default_seconds) + " s"
               : std::string())
     << ". \"-\": the measure does not apply; \"never\": the time was not reached; "
        "\"diverged at T s\": the state stopped being finite or passed 1e6 m or 1e6 m/s at T, "
        "and the case's measures stop there.\n\n"
     << "- **IS** is the intersecting stack (Sec. 10.2: five cubes of half extent 1.2 m started "
        "0.4 m overlapping, the bottom one 1.2 m into the ground), **SiB** the stress scene "
        "sphere_in_box (a ball of radius 0.4 m started 0.7 m into a box of half extent 1 m "
        "resting on the ground), each run " << number(kColumnSeconds) << " s at 60 Hz.\n"
     << "- **< 1 mm from (s)**: the first time t from which the largest overlap stays under "
        "1 mm to the end of the run. The largest overlap of the state at time t is the deepest "
        "contact over World::manifolds() of the step that starts from it (the last state: the "
        "same narrow phase on every pair).\n"
     << "- **peak speed (m/s)**: the largest speed of any body's centre of mass over the run, "
        "after step 0.\n"
     << "- **energy injected (J)**: max over t of (KE + PE) minus the PE of the column at rest; KE "
        "translational and rotational, PE = -m g . x summed over the bodies. At rest: the bodies "
        "stacked on the ground in their order without overlap (IS: cube centres at 1.2, 3.6, "
        "6.0, 8.4, 10.8 m; SiB: box centre at 1.0 m, ball centre at 2.0 + 0.4 m), computed from "
        "the bodies' masses, shapes and gravity. Negative: the run never reached the resting "
        "state's energy.\n"
     << "- **height error (m)**: the largest |final height - resting height| of a body centre; "
        "push.csv has the heights (final_heights_m, rest_heights_m).\n"
     << "- **stack drift (m)**, **stack slides off (s)**: the stack scene (Sec. 10.1) over "
     << number(stack_seconds) << " s" << (quick ? " (--quick; 600 s without it)" : "")
     << ": its metrics max_drift_m (the largest horizontal distance of a cube centre from the "
        "column's axis) and slide_off_time_s (the first time a cube's centre is 0.5 m off the "
        "axis or it tilts past 10 degrees).\n"
     << "- **mass ratio held**: the largest mass ratio R of ";
  for (std::size_t i = 0; i < std::size(kMassRatios); ++i) {
    md << (i ? ", " : "") << number(kMassRatios[i]);
  }
  md << " (the report's mass ratio table: a cube of R kg resting on one of 1 kg on the ground) "
        "whose pair still holds after "
     << number(kPairSeconds) << " s with PGS at " << kPairIterations
     << " iterations (the light cube's centre within its half edge of the heavy cube's axis and "
        "the heavy cube within a quarter edge of its stacked height); \"none\": none held.\n"
     << "- **grid rod error (m)**: the pendulum grid's metric max_rod_error_m over "
     << number(grid_seconds) << " s (its default " << number(grid.default_seconds)
     << " s): the largest |rod length - its length| over the run. **wave rod error**, **wave phase error "
        "(deg)**: the pendulum wave's metrics max_rod_error_rel (the largest |rod length - "
        "its length| / its length over the run) and max_phase_error_deg (at the end of the run, "
        "the largest difference over its 50 pendulums between a ball's swing angle and that of "
        "the reduced-coordinate reference, wrapped to [-180, 180] deg), run "
     << number(wave_seconds) << " s"
     << (wave_seconds < wave.default_seconds
             ? " (--quick; its default is " + number(wave.default_seconds) + " s)"
             : std::string(" (its default)"))
     << ".\n"
     << "- **IS us/step**, **stack us/step**: microseconds per step, wall clock around "
        "World::step only (metrics and bookkeeping outside): IS over its first "
     << number(is.bench.seconds) << " s (the median of " << kCostRepeats
     << " runs after one untimed), the stack over its whole run. A measurement on this machine "
        "at the time of the run, not a property of the method.\n";
  return md.str();
}

// One diagram: a panel per case (IS, SiB), a line per method, value against time, log y with
// values under `floor` drawn on it. `column` 1: overlap, 2: speed (in the data file's order).
std::string diagram_script(const fs::path& data, const std::vector<Method>& ms, int column,
                           const std::string& title, const std::string& axis, double floor,
                           double y_max, double t_max, bool threshold) {
  static const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                         "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};
  std::ostringstream gp;
  gp << "set multiplot layout 1,2 title " << gp_text(title) << " font ',12'\n"
     << "set logscale y\nset format y '1e%T'\nset grid xtics ytics lc rgb '#d8d8d8'\n"
     << "set xrange [0:" << t_max << "]\nset yrange [" << floor / 2.0 << ":" << y_max * 3.0
     << "]\nset xlabel 'time (s)'\nset ylabel " << gp_text(axis)
     << "\nset key top right font ',8' opaque\nset tics font ',8'\n";
  if (threshold) {
    gp << "set arrow 1 from graph 0, first " << kResolvedOverlap << " to graph 1, first "
       << kResolvedOverlap << " nohead dt 2 lw 1.2 lc rgb 'gray30' back\n"
       << "set label 1 '1 mm' at graph 0.01, first " << kResolvedOverlap
       << " offset 1,0.6 font ',8' tc rgb 'gray30'\n";
  }
  const char* const panels[] = {"intersecting stack", "sphere in box"};
  for (int p = 0; p < 2; ++p) {
    gp << "set title " << gp_text(panels[p]) << " font ',10'\nplot ";
    for (std::size_t k = 0; k < ms.size(); ++k) {
      const std::size_t index = static_cast<std::size_t>(p) * ms.size() + k;
      gp << (k ? ", \\\n     " : "") << gp_text(data.string()) << " index " << index
         << " using 1:($" << column + 1 << " < " << floor << " ? " << floor << " : $"
         << column + 1 << ") with lines lw 1.6 lc rgb '"
         << kColours[k % (sizeof kColours / sizeof kColours[0])] << "' title "
         << gp_text(ms[k].name);
    }
    gp << "\n";
  }
  gp << "unset multiplot\n";
  return gp.str();
}

// Writes OUT/plots/STEM.dat and .gp, OUT/STEM.png and OUT/STEM.pdf (gnuplot's pdfcairo terminal:
// its text is text, for a paper), each through a temporary of this run.
void write_diagram(const fs::path& out, const std::string& stem, const std::string& data_text,
                   const std::string& body) {
  const fs::path data = out / "plots" / (stem + ".dat");
  const fs::path script = out / "plots" / (stem + ".gp");
  write_text_atomic(data, data_text);
  AtomicFile png(out / (stem + ".png"));
  AtomicFile pdf(out / (stem + ".pdf"));
  png.hand_over();
  pdf.hand_over();
  std::ostringstream gp;
  gp << "reset\nset terminal pngcairo size 1100,480 font ',10' noenhanced\n"
     << "set output '" << png.temporary().string() << "'\n"
     << body << "unset output\n";
  // The PDF at 100 pixels of the PNG per inch, so its 10 pt text sits as in the PNG.
  gp << "reset\nset terminal pdfcairo size 11in,4.8in font ',10' noenhanced\n"
     << "set output '" << pdf.temporary().string() << "'\n"
     << body << "unset output\n";
  write_text_atomic(script, gp.str());
  run_gnuplot(script);
  png.commit();
  pdf.commit();
}

}  // namespace

std::vector<std::string> push_report_files() {
  return {"push.csv", "push.md", "push_overlap.png", "push_overlap.pdf", "push_speed.png",
          "push_speed.pdf"};
}

std::vector<std::string> push_plot_files() {
  return {"push_overlap.dat", "push_overlap.gp", "push_speed.dat", "push_speed.gp"};
}

int run_push_report(const fs::path& out, bool quick, bool force, const nlohmann::json& info) {
  // Every target checked before any work.
  const OutputPlan main = plan_output(out, push_report_files(), force, FolderUse::shared);
  const OutputPlan plots = plan_output(out / "plots", push_plot_files(), force, FolderUse::shared);
  const scenes::Scene& is = scene_named("intersecting_stack");
  const scenes::Scene& sib = scene_named("sphere_in_box");
  const scenes::Scene& stack = scene_named("stack");
  const scenes::Scene& grid = scene_named("pendulum_grid");
  const scenes::Scene& wave = scene_named("pendulum_wave");
  const double stack_seconds = quick ? kQuickStackSeconds : kStackSeconds;
  const double grid_seconds =
      quick ? std::min(grid.default_seconds, kQuickPendulumSeconds) : grid.default_seconds;
  const double wave_seconds =
      quick ? std::min(wave.default_seconds, kQuickPendulumSeconds) : wave.default_seconds;

  const std::vector<Method> ms = methods();
  const auto started = Clock::now();
  std::vector<MethodResults> results;
  constexpr int kCases = 7;  // IS, SiB, IS cost, stack, mass ratios, grid, wave
  Progress progress(std::string("report push") + (quick ? " --quick" : ""),
                    static_cast<long long>(ms.size()) * kCases, "cases");
  long long done = 0;
  const auto tick = [&] { progress.update(++done); };
  for (const Method& m : ms) {
    MethodResults r;
    r.method = m;
    r.intersecting = run_column(is, m, kColumnSeconds);
    tick();
    r.sphere = run_column(sib, m, kColumnSeconds);
    tick();
    r.intersecting_us = window_us_per_step(is, m);
    tick();
    r.stack = run_metrics(stack, m, stack_seconds);
    r.stack_seconds = stack_seconds;
    tick();
    for (const double ratio : kMassRatios) {
      if (run_pair(ratio, SolverKind::pgs, static_cast<PushMode>(m.value), kPairIterations,
                   kPairSeconds).held) {
        r.held.push_back(ratio);
      }
    }
    tick();
    r.grid = run_metrics(grid, m, grid_seconds);
    r.grid_seconds = grid_seconds;
    tick();
    r.wave = run_metrics(wave, m, wave_seconds);
    r.wave_seconds = wave_seconds;
    tick();
    results.push_back(std::move(r));
  }
  progress.finish();
  const double elapsed = seconds_between(started, Clock::now());

  std::vector<Row> rows;
  for (const MethodResults& r : results) {
    for (Row& row : rows_of(r, is)) rows.push_back(std::move(row));
  }

  // push.md: the legend and one row per method.
  std::ostringstream md;
  md << "# Push methods side by side\n\n"
     << "Made by `cps report push" << (quick ? " --quick" : "") << "` (" << ms.size()
     << " methods, " << number(elapsed) << " s on this machine); every value in "
     << "[push.csv](push.csv).\n\n"
     << legend(quick, stack_seconds, is, grid, grid_seconds, wave, wave_seconds) << "\n"
     << "| method | IS < 1 mm from (s) | IS peak speed (m/s) | IS energy injected (J) | IS height "
        "error (m) | SiB < 1 mm from (s) | SiB peak speed (m/s) | SiB energy injected (J) | SiB "
        "height error (m) | stack drift (m) | stack slides off (s) | mass ratio held | grid rod "
        "error (m) | wave rod error (rel) | wave phase error (deg) | IS us/step | stack us/step "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Method& m : ms) {
    const auto c = [&](const char* kase, const char* column) {
      return md_cell(rows, m.name, kase, column);
    };
    md << "| " << m.label;
    for (const char* kase : {"intersecting_stack", "sphere_in_box"}) {
      for (const char* column : {"overlap_under_1mm_from_s", "peak_speed_mps",
                                 "energy_injected_J", "final_height_error_m"}) {
        md << " | " << c(kase, column);
      }
    }
    md << " | " << c("stack", "max_drift_m") << " | " << c("stack", "slide_off_time_s") << " | "
       << c("mass_ratio", "largest_mass_ratio_held") << " | "
       << c("pendulum_grid", "max_rod_error_m") << " | "
       << c("pendulum_wave", "max_rod_error_rel") << " | "
       << c("pendulum_wave", "max_phase_error_deg") << " | "
       << c("intersecting_stack", "us_per_step") << " | " << c("stack", "us_per_step") << " |\n";
  }
  md << "\n![largest overlap against time](push_overlap.png)\n\n"
     << "![largest body speed against time](push_speed.png)\n";

  // The diagrams' data: per case (IS, SiB) per method an index block "t overlap speed".
  std::ostringstream data;
  data << "# t (s), largest overlap (m), largest body speed (m/s); a block per case "
          "(intersecting_stack, sphere_in_box) and method (";
  for (std::size_t k = 0; k < ms.size(); ++k) data << (k ? ", " : "") << ms[k].name;
  data << ")\n";
  double overlap_max = kOverlapFloor, speed_max = kSpeedFloor, t_max = 0.0;
  for (const bool sphere : {false, true}) {
    for (const MethodResults& r : results) {
      const ColumnResult& c = sphere ? r.sphere : r.intersecting;
      for (const Sample& s : c.series) {
        data << s.t << " " << s.overlap_m << " " << s.speed_mps << "\n";
        overlap_max = std::max(overlap_max, s.overlap_m);
        speed_max = std::max(speed_max, s.speed_mps);
      }
      t_max = std::max(t_max, c.seconds);
      data << "\n\n";
    }
  }

  begin_output(main, info);
  begin_output(plots, info);
  write_text_atomic(out / "push.csv", csv_of(rows));
  write_text_atomic(out / "push.md", md.str());
  write_diagram(out, "push_overlap", data.str(),
                diagram_script(out / "plots" / "push_overlap.dat", ms, 1,
                               "largest overlap against time (values under " +
                                   number(kOverlapFloor) + " m drawn on the bottom edge)",
                               "largest overlap (m)", kOverlapFloor, overlap_max, t_max, true));
  write_diagram(out, "push_speed", data.str(),
                diagram_script(out / "plots" / "push_speed.dat", ms, 2,
                               "largest body speed against time (values under " +
                                   number(kSpeedFloor) + " m/s drawn on the bottom edge)",
                               "largest body speed (m/s)", kSpeedFloor, speed_max, t_max, false));
  end_output(plots, info);
  end_output(main, info);
  std::printf("%zu push methods in %.0f s: %s\n", ms.size(), elapsed,
              (out / "push.md").string().c_str());
  return 0;
}

}  // namespace cps::cli
