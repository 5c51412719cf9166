#pragma once
// The cases of `cps report push`, run for one push method at a time: each at the scene's own
// settings with only the world parameter push changed. The measures are defined here, at the
// functions that compute them, and in push.md's legend (push/report.cpp).

#include "scene.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cps::cli {

/// An overlap counts as resolved under this depth (m): 1 mm, a thousandth of the cubes' size.
inline constexpr double kResolvedOverlap = 1e-3;
/// The intersecting stack's and sphere_in_box's runs (s): the intersecting stack's default
/// duration, long enough for a method that brings the column to rest to have done so.
inline constexpr double kColumnSeconds = 4.0;
/// The stack's run (s): 600 s, and 60 s in --quick.
inline constexpr double kStackSeconds = 600.0;
inline constexpr double kQuickStackSeconds = 60.0;
/// In --quick the pendulum scenes run at most this long (s): the pendulum grid its whole 10 s,
/// the pendulum wave 10 of its 62 s.
inline constexpr double kQuickPendulumSeconds = 10.0;
/// Timed repeats of the intersecting stack's first window (the median counts), after one
/// untimed repeat that warms the caches.
inline constexpr int kCostRepeats = 5;
/// The mass ratio pairs run at the paper's solver and iteration count.
inline constexpr int kPairIterations = 25;
/// In --quick the 10,000-step hard cases (stack_20_long, pyramid_20_rows_long) run this many
/// steps (count): 600, 10 s at their dt = 1/60 s, past stack_20's landing at about 1.5 s.
inline constexpr int kQuickLongRunSteps = 600;
/// The tuned variant of avbd on the heavy cases (heavy_on_light, heavy_rope): its penalties start
/// at this stiffness (N/m, the parameter avbd_k_start; its default is 1 N/m). A row holds a body
/// of mass M once its penalty is near M / dt^2: 6.5e5 N/m for heavy_rope's 180 kg block.
inline constexpr double kTunedAvbdKStart = 1e6;
/// The push method that runs the tuned variant.
inline constexpr const char* kTunedMethod = "avbd";

/// One push method: a choice of the world parameter push.
struct Method {
  std::string name;   ///< "baumgarte"
  std::string label;  ///< "baumgarte (push factor, Sec. 5.3)": the name, title and source
  int value = 0;      ///< the PushMode value
};

/// Every push method of this build, in the table's order (cps::parameter("push").choices).
std::vector<Method> push_methods();

/// A hard case (stress scenes with HardCaseMetrics) in the report: its scene, how
/// long it runs (s) and whether avbd also runs it with its penalties from kTunedAvbdKStart.
struct HardCase {
  const scenes::Scene* scene = nullptr;
  double seconds = 0.0;
  bool tuned_avbd = false;
};

/// What `cps report push` runs: the methods, the scenes of its cases and how long each runs (s;
/// quick: the stack over kQuickStackSeconds, the pendulums at most kQuickPendulumSeconds, the
/// 10,000-step hard cases kQuickLongRunSteps steps).
struct PushPlan {
  bool quick = false;
  std::vector<Method> methods;
  const scenes::Scene* intersecting = nullptr;  ///< intersecting_stack (Sec. 10.2)
  const scenes::Scene* sphere = nullptr;        ///< sphere_in_box (stress)
  const scenes::Scene* stack = nullptr;         ///< stack (Sec. 10.1)
  const scenes::Scene* grid = nullptr;          ///< pendulum_grid
  const scenes::Scene* wave = nullptr;          ///< pendulum_wave
  double stack_seconds = 0.0;
  double grid_seconds = 0.0;
  double wave_seconds = 0.0;
  /// heavy_on_light and heavy_rope (tuned_avbd, their default 10 s), stack_20_long and
  /// pyramid_20_rows_long (10,000 steps; quick: kQuickLongRunSteps).
  std::vector<HardCase> hard;
};

/// The plan of the full run, or with `quick` the quick one. Throws std::logic_error if this
/// build lacks one of the scenes.
PushPlan plan_push_report(bool quick);

/// One sample of a run's time series: time (s), largest overlap (m) of the state at that time,
/// largest body speed (m/s).
struct Sample {
  double t = 0.0;
  double overlap_m = 0.0;
  double speed_mps = 0.0;
};

/// A column pushed out of overlap (the intersecting stack, sphere_in_box): see run_column.
struct ColumnResult {
  double seconds = 0.0;               ///< simulated (s)
  double dt = 0.0;                    ///< the scene's time step (s)
  std::optional<double> diverged_at;  ///< s
  std::optional<double> resolved_at;  ///< s: overlaps under kResolvedOverlap from here to the end
  double max_overlap_m = 0.0;
  double peak_speed_mps = 0.0;
  double energy_injected_J = std::nan("");
  double height_error_m = std::nan("");
  std::vector<double> final_heights;  ///< m, movable bodies in body order
  std::vector<double> rest;           ///< m, the same bodies at rest (rest_heights)
  std::vector<Sample> series;         ///< every step's state, from t = 0
};

/// A scene run for its metrics (scene.h's Metrics::report) over `seconds` (s): the metrics, the
/// time the state stopped being sane (if it did), and the CPU time of the stepping thread (s)
/// spent in World::step alone and the steps taken.
struct MetricsResult {
  nlohmann::json metrics;
  std::optional<double> diverged_at;  ///< s
  double step_cpu_s = 0.0;  ///< CPU time of this thread in World::step alone (s)
  long long steps = 0;
  double dt = 0.0;   ///< the scene's time step (s)
  double seconds = 0.0;  ///< how long it was to run (s)
};

/// A hard case run for its HardCaseMetrics (stress.h) with one push method, at the scene's own
/// settings or (variant) with one parameter more set.
struct HardResult {
  std::string scene;      ///< "heavy_on_light"
  std::string variant;    ///< "" at the scene's settings; "avbd_k_start=1e+06" for the tuned row
  nlohmann::json metrics; ///< HardCaseMetrics::report(): survival_s, max_penetration_m, ...
  std::optional<double> diverged_at;  ///< s: the state stopped being sane (sane_state)
  double seconds = 0.0;   ///< how long it was to run (s)
  double dt = 0.0;        ///< the scene's time step (s)
  int iterations = 0;     ///< the solver's sweeps per solve (the scene's 25)
  bool has_rods = false;  ///< the scene has distance constraints (heavy_rope)
  double step_cpu_s = 0.0;  ///< CPU time of this thread in World::step alone (s)
  long long steps = 0;
  /// True when no body left its place in the whole run: it did not diverge, metrics' holds
  /// (arrived, in place at the end) and survival_s reached the run's end.
  bool held_throughout() const;
};

/// The cases of one method, in the order of push.md's columns.
struct MethodResults {
  Method method;
  ColumnResult intersecting;
  ColumnResult sphere;
  double intersecting_us = std::nan("");  ///< us per step over the intersecting stack's window
  MetricsResult stack;
  std::vector<double> held;  ///< the mass ratios (kMassRatios) whose pair held, ascending
  MetricsResult grid;
  MetricsResult wave;
  /// A row per plan.hard case at the scene's settings, in plan order; for avbd then a tuned row
  /// (variant) per case with tuned_avbd.
  std::vector<HardResult> hard;
};

/// Runs every case of `plan` for method `m`, calling `tick` after each of its
/// push_case_count(plan, m) cases (IS, SiB, IS cost, stack, mass ratios, grid, wave, then the
/// hard cases' rows). Throws UsageError for a bad parameter, std::logic_error for a column
/// scene without a ground plane.
MethodResults run_method(const PushPlan& plan, const Method& m, const std::function<void()>& tick);

/// The number of cases run_method runs (and ticks) for `m`: 7 of the paper's and stress scenes,
/// a row per hard case, and for avbd a tuned row per case with tuned_avbd.
int push_case_count(const PushPlan& plan, const Method& m);

/// Runs `scene` with push `m` (and, if `k_start` is given, avbd_k_start at that, N/m) for
/// `seconds` (s), feeding its metrics (which must be HardCaseMetrics: a hard case) after every
/// step, stopping if the state stops being sane. Steps are timed by the CPU time of this thread
/// (thread_cpu_seconds), World::step alone. Throws UsageError for a bad parameter.
HardResult run_hard_case(const scenes::Scene& scene, const Method& m, double seconds,
                         std::optional<double> k_start = std::nullopt);

/// The method called `name` among push_methods(), or nullopt.
std::optional<Method> push_method_named(const std::string& name);

/// The largest speed |v| (m/s) of the centre of mass of any movable body of `world`. No errors.
double largest_speed(const World& world);

/// A metric's number, or NaN where it is missing or not a number (null: never happened).
double metric(const nlohmann::json& metrics, const char* key);

}  // namespace cps::cli
