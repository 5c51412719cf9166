#pragma once
// The scene library: the paper's result scenes (Sec. 10), one file each, listed in one table.
// The `cps` command, the tests and the benchmarks all link it. It knows the engine, never GL.

#include "cps/world.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <string_view>
#include <type_traits>
#include <vector>

namespace cps::scenes {

/// Per-scene measurements, fed after every step and reported as JSON (the names of the keys
/// are part of the `cps simulate --json` interface; each carries its unit as a suffix).
class Metrics {
 public:
  virtual ~Metrics() = default;
  /// Called once after each World::step().
  virtual void observe(const World& world) = 0;
  /// The measurements so far.
  virtual nlohmann::json report() const = 0;
  /// Called once when the run is found diverged (divergence.h), its signs seen from since_s (s)
  /// on: an event of the run at or after since_s (a slide-off, a body leaving its place) is the
  /// divergence's, not the run's, and is dropped. Observing stops after this call.
  virtual void diverged_since(double since_s) { (void)since_s; }
};

/// Where the camera of a scene's pictures stands: eye and target (m), vertical field of view
/// (degrees). A scene without one is framed automatically.
struct CameraPreset {
  Vec3 eye = Vec3::Zero();
  Vec3 target = Vec3::Zero();
  double fov_y_deg = 45.0;
};

/// The window of simulated time over which `cps bench` times a scene's step: where the scene
/// does what it exists for (its contacts formed, its rods loaded), so that a step costs there
/// what it costs in use. The window is timed from a copy of the world taken at its start.
struct BenchTraits {
  /// Simulated time (s, >= 0) the world is advanced, untimed, before the window opens.
  double start_s = 1.0;
  /// Length of the window (s, > 0; typical 0.5 to 3).
  double seconds = 3.0;
  /// Why the window lies there, in one line (printed by `cps bench` and in its JSON).
  std::string_view reason = "from 1 s: the bodies have landed and rest on each other";
};

/// How `cps report` runs and judges a scene (see demos/cps/report.h). The defaults suit a scene
/// judged by its trajectory over its default duration.
struct ReportTraits {
  /// Simulated time every run of the report's sweep lasts (s, > 0); unset: the scene's
  /// default_seconds (see Scene::report_horizon_s).
  std::optional<double> horizon_s{};
  /// The horizon of the quick sweep (`cps report --quick`, s, > 0); unset: horizon_s. For a
  /// scene whose runs are long and whose step costs the same all along (the pendulum wave).
  std::optional<double> quick_horizon_s{};
  /// Why the horizon is what it is, in one line (report.md prints it with the horizon).
  std::string_view horizon_reason = "the scene's default duration";
  /// The CSV column of the report's headline measure: the error whose value at the paper's
  /// settings the headline quotes and tries to halve, smaller being better
  /// ("trajectory_error_m", "phase_error_deg", "rod_error_max_m", "metric.recovery_time_s", ...).
  std::string_view primary_measure = "trajectory_error_m";
  /// Why the headline measure is this one, in one line (report.md prints it under the
  /// headline): what it means and why smaller is better there.
  std::string_view headline_reason =
      "the default: the trajectory error at the trajectory time, not checked for chaos";
  /// True if the scene's metrics measure its error against a reference solution of their own
  /// (max_phase_error_deg: the pendulum wave's reduced-coordinate phases); the report then does
  /// not compute a trajectory error against a reference run.
  bool has_reference_solution = false;
  /// The time (s, in (0, horizon], a whole number of the scene's steps, 1/60 s for the paper's,
  /// so that every substep count steps onto it exactly) at which the trajectory error compares the bodies' positions
  /// with the reference run: chosen where the scene's contacts have acted but before chaos
  /// dominates (before runs that differ by round-off part by as much as the errors measured).
  /// Unset: 1 s, or the horizon if it is shorter (a default, not chosen for the scene). Not
  /// used when has_reference_solution is true.
  std::optional<double> trajectory_time_s;
  /// Why the trajectory time is what it is, in one line (report.md prints it with the time).
  std::string_view trajectory_reason =
      "not chosen for this scene: 1 s (the horizon if shorter), the first falls and landings";
};

/// A scene: its name (as typed on the command line), a one-line summary, its default duration
/// (s), its world parameters, how to add its bodies and how to measure it.
struct Scene {
  std::string_view name;
  std::string_view summary;
  double default_seconds = 10.0;
  std::function<WorldDef()> world_def;
  std::function<void(World& world)> populate;
  std::function<std::unique_ptr<Metrics>(const World& world)> make_metrics;
  /// Opacity of the scene's planes when drawn, in [0, 1]: below 1 for walls that bodies sit
  /// behind (the funnel).
  double plane_opacity = 1.0;
  std::optional<CameraPreset> camera;
  /// The --camera name its pictures take when none is given ("preset": the camera preset as it
  /// stands; "fit:frame" for a scene whose bodies fly far from where they start, so that its
  /// picture holds them close at rest and draws back while they fly). See cps::cli::scene_view.
  std::string_view default_camera = "preset";
  /// The window `cps bench` times.
  BenchTraits bench;
  /// How `cps report` runs and judges the scene.
  ReportTraits report;

  /// The horizon of `cps report`'s runs (s): report.horizon_s or default_seconds; in the quick
  /// sweep report.quick_horizon_s where set.
  double report_horizon_s(bool quick = false) const {
    if (quick && report.quick_horizon_s) return *report.quick_horizon_s;
    return report.horizon_s.value_or(default_seconds);
  }
  /// The time of `cps report`'s trajectory error (s): report.trajectory_time_s, or 1 s, or the
  /// horizon if that is shorter.
  double report_trajectory_time_s() const {
    return report.trajectory_time_s.value_or(std::min(1.0, report_horizon_s()));
  }
};

/// The paper's result scenes (Sec. 10), in the order `cps list` prints them ("all" on the
/// command line).
std::span<const Scene> paper_scenes();

/// The stress scenes (stiff and extreme cases), listed apart ("stress" on the command line).
/// Defined in scenes/stress/stress_table.cpp.
std::span<const Scene> stress_scenes();

/// Paper scenes, then stress scenes.
std::span<const Scene> all_scenes();

/// The scene called `name`, or nullptr. Besides the tables: the example scene files by name
/// (assets/scenes, embedded: "dominoes"); random_SEED, the random scene (populate_random) with
/// that seed (a decimal integer in [0, 2^64 - 1]; random_1 is "random"); scaled scenes for
/// benchmarks, made on demand from a family name and a size: stack_N (N cubes, 1..40),
/// pyramid_N (a pyramid of about N boxes, 1..20000), funnel_N (N balls, 1..20000),
/// pendulum_wave_N (N pendulums, 1..20000), pendulum_grid_N (an N x N grid, 1..100); and a name
/// ending in ".json", a scene file loaded from that path (scene_file.h; the scene is called by
/// the path as given, its outputs by output_name). The returned pointer stays valid for the
/// whole program. Throws SceneFileError (scene_file.h, a std::invalid_argument) for a scene file
/// that cannot be read or is not valid.
const Scene* find_scene(std::string_view name);

/// The name of a scene's output files and folders (`cps render`'s OUT/NAME/ and its video, a
/// figure's default file, the report's files): its name, except for a scene file loaded from a
/// path, whose outputs are named by scene_file_output_name (scene_file.h), never by the path as
/// typed. No errors.
std::string_view output_name(const Scene& scene);

/// The candidate nearest to `word` by edit distance (cps::nearest_name, parameters.h).
using ::cps::nearest_name;

/// The random scene with this seed, named random_SEED (see find_scene); kept for the program's
/// life.
const Scene* random_scene(std::uint64_t seed);

/// The scaled scene families, with the size range each takes ("stack_N 1..40", ...).
std::span<const std::string_view> scaled_families();

/// Builds a scaled scene (see find_scene). Throws std::invalid_argument naming the size and
/// the allowed range, or an unknown family.
Scene scaled_scene(std::string_view family, int n);

/// Values that replace a scene's own world parameters, by parameter of the table in
/// cps/parameters.h (units as there), in the order they were set.
struct Overrides {
  std::vector<std::pair<const Parameter*, ParameterValue>> values;

  /// Sets the parameter (WorldDef member name, flag or JSON key) to v, replacing an earlier
  /// value of it. Throws std::invalid_argument for an unknown name or a value the table refuses.
  Overrides& set(std::string_view name, const ParameterValue& v);
  Overrides& set(const Parameter& p, const ParameterValue& v);
  /// The same for a method, by its enum (PushMode::split, SolverKind::jacobi, ...).
  template <class Enum>
    requires std::is_enum_v<Enum>
  Overrides& set(std::string_view name, Enum v) {
    return set(name, ParameterValue(static_cast<int>(v)));
  }
  /// The value set for the parameter, or nullptr.
  const ParameterValue* find(std::string_view name) const;
};

/// The scene's WorldDef with the overrides applied. Not validated here: World's constructor does.
WorldDef world_def_with(const Scene& scene, const Overrides& overrides);

/// The stepping rule of every run to a time: true while `world` is more than half a step (dt, s)
/// short of t (s), so that a run of t seconds takes round(t / dt) steps whatever the round-off
/// in World::time(). Run::advance_to and every loop that steps to a time use it.
inline bool short_of(const World& world, double t) {
  return world.time() + 0.5 * world.def().dt < t;
}

class DivergenceWatch;  // divergence.h

/// A world built from a scene, with its metrics, ready to step.
struct Run {
  World world;
  std::unique_ptr<Metrics> metrics;
  /// Whether and when the run diverged (divergence.h), fed through `metrics` (make_run wraps
  /// them); read it, not the metrics' report, once the run may have moved (a report can read
  /// the world a scene's metrics saw last).
  std::shared_ptr<const DivergenceWatch> divergence{};

  /// Steps once and feeds the metrics.
  void step() {
    world.step();
    metrics->observe(world);
  }
  /// Steps until world.time() reaches t (s), within half a step.
  void advance_to(double t) {
    while (short_of(world, t)) step();
  }
};

/// Builds a scene's world. Throws std::invalid_argument if the parameters are invalid.
Run make_run(const Scene& scene, const Overrides& overrides = {});

/// Deepest penetration (m) among the contacts of the world's last step; 0 if none
/// (World::deepest_contact).
double deepest_contact(const World& world);

/// Kinetic energy of all bodies (J), translational plus rotational.
double kinetic_energy(const World& world);

/// The full size (m) of the largest movable body: a box's longest edge, a ball's diameter; 0 if
/// the world has no movable body.
double largest_body_size(const World& world);

/// Positions x (m) of the movable bodies, in body order: one Vec3 each.
std::vector<Vec3> movable_positions(const World& world);

/// RMS distance (m) between two lists of the same bodies' positions (the first min(|a|, |b|) of
/// each, paired in order); 0 if either is empty.
double rms_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

/// Largest |distance - length| (m) over the world's distance constraints now; 0 if none.
double max_rod_error(const World& world);

/// Deepest overlap (m) over every pair of bodies, from the geometry as it is now (runs the
/// narrow phase on all pairs; independent of the last step's contacts).
double max_penetration_now(const World& world);

/// Adds the static ground plane y = 0 (solid below, normal +y) and returns its body index.
int add_ground(World& world);

/// A ball joint: point local_a of body_a and point local_b of body_b (body frames, m) held
/// together, made of three rods (Sec. 5.2 rows) from the point on body_b to the three feet
/// local_a + arm s_i e_i on body_a (e_i body_a's axes, s_i = signs(i) = +-1, so that the feet can
/// lie inside body_a; arm in m, typically the body's half width). At the joint's solution the
/// three rows are a ball joint's: J along body_a's three axes, torque arms to the joint point;
/// away from it they differ by second order in error / arm. The two bodies get no contacts with
/// each other (DistanceConstraint::collide false). Either body may be static, not both. Throws
/// std::invalid_argument (World::add_distance's errors, or arm not in (0, 1e6] m, or a sign not
/// +-1). Returns the three rods' indices.
std::array<int, 3> add_ball_joint(World& world, int body_a, const Vec3& local_a, int body_b,
                                  const Vec3& local_b, double arm, const Vec3& signs = Vec3::Ones());

/// Adds the static ground plane y = 0 and the paper's column of five cubes (edge 2.4 m, mass
/// 1.2 kg) with centres (0, bottom + spacing i, 0), i = 0..4 (m). Shared by the stack (Sec. 10.1)
/// and the intersecting stack (Sec. 10.2).
void add_ground_and_cube_column(World& world, double bottom, double spacing, int count = 5);

/// A metrics object of type M built from `args`, having observed the world as built.
template <class M, class... Args>
std::unique_ptr<Metrics> observed(const World& world, Args&&... args) {
  auto m = std::make_unique<M>(std::forward<Args>(args)...);
  m->observe(world);
  return m;
}

// The scenes (one file each).
WorldDef stack_world_def();
void populate_stack(World& world);
std::unique_ptr<Metrics> make_stack_metrics(const World& world);

WorldDef intersecting_stack_world_def();
void populate_intersecting_stack(World& world);
std::unique_ptr<Metrics> make_intersecting_stack_metrics(const World& world);

WorldDef funnel_world_def();
/// The funnel's four static planes through the origin, normals (+-1, 1, 0)/sqrt 2 and
/// (0, 1, +-1)/sqrt 2: the free side is y > |x| and y > |z|.
void add_funnel_walls(World& world);
void populate_funnel(World& world);
std::unique_ptr<Metrics> make_funnel_metrics(const World& world);

WorldDef pendulum_grid_world_def();
void populate_pendulum_grid(World& world);
std::unique_ptr<Metrics> make_pendulum_grid_metrics(const World& world);

WorldDef pendulum_wave_world_def();
void populate_pendulum_wave(World& world);
/// `count` pendulums (>= 1) in rows of 50 along x, rows 0.3 m apart along z, each row the
/// scene's 50 periods. count = 50 is the paper's scene.
void add_pendulum_wave_rows(World& world, int count);
std::unique_ptr<Metrics> make_pendulum_wave_metrics(const World& world);

}  // namespace cps::scenes
