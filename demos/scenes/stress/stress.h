#pragma once
// The stress scenes (stability on stiff and extreme cases): the functions the scene
// table (stress_table.cpp) lists, and the measurements they share. The scenes probe what the
// paper's own five do not: large mass ratios, a heavy impact on a pendulum grid, a large time
// step, fast spin, deep overlap, a long chain, scaled units, degenerate geometry and random
// piles. Units are SI throughout; energies are in J with the potential -m g . x (datum x = 0, the
// ground plane y = 0 where a scene has one).

#include "scene.h"

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace cps::scenes {

/// Total mechanical energy (J) of the movable bodies: kinetic 1/2 (p.v + l.w) plus the
/// gravitational potential -m g . x (m g y for the scenes' g = (0, -10, 0) m/s^2, so the datum
/// is y = 0).
double total_energy(const World& world);

/// True if every body's x, o, p and l are finite.
bool all_finite(const World& world);

/// Energy bookkeeping of a run, fed after every step (and once before the first).
///
/// Derivation of the bound it keeps (the paper's Sec. 3.2 and Eq. 6.2.9). Over one step of semi-
/// implicit Euler with momenta advanced by the impulse dt (f + J^T lambda) and positions moved by
/// the new velocity v2, the energy E = KE + PE changes by exactly
///   dE = dt lambda . (J v2) - 1/2 |v2 - v1|^2_M  (+ the rotation term below),
/// f being the gravity force (its potential is linear in x). A converged solve gives
/// lambda_r (j_r . v2) = lambda_r t_r for every contact and rod row (complementarity; t = push +
/// bias is the row's target velocity), and lambda_r (j_r . v2) <= 0 for friction (0 when it
/// sticks, opposed to the slip at its limit). So the rows inject at most the push work
///   W_baumgarte = sum over steps of dt sum_r max(0, lambda_r t_r)            (J)
/// and everything else only dissipates. With the single frame push factor (Sec. 8.1) the stored
/// momenta come from a solve without the push (no energy in), and the push only moves positions
/// by dx_push = x2 - x1 - v2 dt, lifting the body against gravity by the work
///   W_split = sum over steps and bodies of max(0, -m g . dx_push)            (J).
/// push_work_J is the one that applies to the world's push mode. The rotation term: the integrator
/// keeps l and moves o by w = I^-1(o1) l; E is measured with I^-1(o2), so boxes whose inertia is
/// not isotropic change KE by 1/2 l . (I^-1(o2) - I^-1(o1)) l at constant l (the integrator's own
/// error; 0 for spheres and cubes). Its positive part is summed into rotation_drift_J.
/// Hence, up to the solver's unconverged residual, E(t) <= E(0) + push_work + rotation_drift.
class EnergyTracker {
 public:
  void observe(const World& world);

  double initial() const { return initial_.value_or(0.0); }
  double current() const { return current_; }
  double max() const { return max_; }
  /// max over the run of E(t) - E(0) (J), >= 0.
  double max_gain() const { return max_gain_; }
  /// Push work W (J) so far (see the class comment).
  double push_work() const { return push_work_; }
  /// Positive part of the rotation term so far (J).
  double rotation_drift() const { return rotation_drift_; }
  /// max over the run of E(t) - E(0) - W(t) - rotation_drift(t) (J): > 0 means energy came from
  /// somewhere the bound does not account for (unconverged PGS, or a bug).
  double max_unaccounted() const { return max_unaccounted_; }
  /// The same bound step by step: max over the steps of dE - dW - dR (J). Tighter than the
  /// cumulative one, since every step's dissipation -1/2 |v2 - v1|^2_M is not there to hide a
  /// gain in a later step; > 0 only by the solver's unconverged residual (or a bug).
  double max_step_excess() const { return max_step_excess_; }
  /// True once any body's state was not finite.
  bool nonfinite() const { return nonfinite_; }

  /// Keys initial_energy_J, max_energy_J, energy_J, max_energy_gain_J, push_work_J,
  /// rotation_drift_J, max_unaccounted_energy_J, nan.
  void add_to(nlohmann::json& j) const;

 private:
  struct State {
    Vec3 x;
    Quat o;
  };
  std::optional<double> initial_;
  double current_ = 0.0;
  double max_ = -kInfinity;
  double max_gain_ = 0.0;
  double push_work_ = 0.0;
  double rotation_drift_ = 0.0;
  double max_unaccounted_ = -kInfinity;
  double max_step_excess_ = -kInfinity;
  bool nonfinite_ = false;
  std::vector<State> previous_;
};

/// Metrics with only the energy bookkeeping (EnergyTracker keys) and max_penetration_m (deepest
/// contact over the run, m) and final_penetration_m (deepest overlap at the end, m).
class EnergyMetrics : public Metrics {
 public:
  void observe(const World& world) override;
  nlohmann::json report() const override;

 protected:
  const World* world_ = nullptr;
  EnergyTracker energy_;
  double max_penetration_ = 0.0;
};

/// The hard cases' measurements (survival, penetration, energy injected, rod stretch,
/// whether the scene holds), fed with the world as built and after every step. Every movable
/// body has a resting place: where its centre lies when the scene stands as it is meant to (m;
/// the position as built for a scene built at rest, the stacked column for one whose bodies fall
/// or are pushed into place). A body has left its place when its centre is farther than
/// `leave_m` (m, > 0) from it. Keys of add_to (units as suffixes):
/// - leave_distance_m: leave_m.
/// - arrival_s: the first observed time (s) from which every movable body stays within leave_m
///   of its resting place for kHoldS; 0 for a scene built at rest that stays so; null if that
///   never happened.
/// - survival_s: after the arrival, the first observed time (s) from which a body stays farther
///   than leave_m from its resting place for kHoldS (a body that sags out for a moment and comes
///   back has not left); if none, the time observed so far (the run's duration), and at most the
///   time the run diverged from (Metrics::diverged_since); 0 if the bodies never arrived.
/// - final_displacement_m: the largest distance of a movable body from its resting place at the
///   last observation (m).
/// - max_penetration_m: the deepest contact of any step (deepest_contact, m).
/// - energy_injected_J: max over the observations of E(t) - E_ref (J, >= 0), E = KE + PE
///   (total_energy) and E_ref the larger of E(0) and the energy of the bodies at rest in their
///   resting places, so that the lift a scene started in overlap needs to come to rest is not
///   counted: a scene at rest that gains energy has had it made by the step.
/// - max_rod_stretch_m: the largest |distance - length| of any rod at any observation (m; 0
///   without rods).
/// - mass_ratio: the largest movable mass over the smallest (dimensionless).
/// - holds: every state was finite, the run did not diverge, the bodies arrived and did not
///   leave, and at the last observation every movable body is within leave_m of its resting
///   place; so "holds" and a survival shorter than the run never come together.
/// - nan: a state was not finite (the measures stop there).
class HardCaseWatch {
 public:
  /// resting_places: one per body of the world it will observe, by index (static bodies' entries
  /// are not used); leave_m: > 0 (m). Throws std::invalid_argument for leave_m <= 0 or not finite.
  HardCaseWatch(std::vector<Vec3> resting_places, double leave_m);
  void observe(const World& world);
  void add_to(nlohmann::json& j) const;
  /// True as add_to's "holds" says.
  bool holds() const;
  /// The run diverged from since_s (s; Metrics::diverged_since): it holds no more, and it
  /// survived at most until then.
  void diverged_since(double since_s);

  /// s: how long the bodies must stay in place to arrive, or out of it to have left. Typical
  /// 0.5 s: a rope sagging to its rest length under a heavy load leaves and comes back within it.
  static constexpr double kHoldS = 0.5;

 private:
  std::vector<Vec3> rest_;
  double leave_m_;
  double rest_energy_J_ = 0.0;
  std::optional<double> start_energy_J_;
  std::optional<double> arrival_s_;
  std::optional<double> left_s_;
  std::optional<double> in_place_since_;  // s, the start of the current time in place
  std::optional<double> out_since_;       // s, the start of the current time out of place
  std::optional<double> diverged_s_;      // s, Metrics::diverged_since's
  double observed_s_ = 0.0;
  double final_displacement_m_ = 0.0;
  double max_penetration_m_ = 0.0;
  double max_energy_J_ = -kInfinity;
  double max_rod_stretch_m_ = 0.0;
  double mass_ratio_ = 1.0;
  bool nonfinite_ = false;
};

/// Metrics of a hard case: HardCaseWatch's keys only.
class HardCaseMetrics final : public Metrics {
 public:
  HardCaseMetrics(std::vector<Vec3> resting_places, double leave_m)
      : watch_(std::move(resting_places), leave_m) {}
  void observe(const World& world) override { watch_.observe(world); }
  void diverged_since(double since_s) override { watch_.diverged_since(since_s); }
  nlohmann::json report() const override;

 private:
  HardCaseWatch watch_;
};

/// Every body's position as built (m), by index: the resting places of a scene built at rest.
std::vector<Vec3> resting_places_as_built(const World& world);

/// The resting places of a column (m), by body index: each movable body, in index order, rests
/// on the one before (the first on the ground plane y = 0) at its horizontal position as built,
/// so body k's centre is at the height of the half heights (box half extent y, sphere radius) of
/// the movable bodies before it, doubled, plus its own. Static bodies keep their positions.
/// For the stack (Sec. 10.1), the intersecting stack (Sec. 10.2), stack_N and sphere_in_box;
/// the bodies are assumed unrotated as built.
std::vector<Vec3> resting_places_stacked(const World& world);

// ---- The scenes, by file. Each populate adds its bodies to an empty world. ----

// mass_ratio.cpp (see mass_ratio.h for the parametrised functions)
WorldDef mass_ratio_world_def();
void populate_mass_ratio_10(World& world);
void populate_mass_ratio_100(World& world);
void populate_mass_ratio_1000(World& world);
std::unique_ptr<Metrics> make_mass_ratio_metrics(const World& world);

// heavy_ball_grid.cpp
void populate_heavy_ball_grid(World& world);
std::unique_ptr<Metrics> make_heavy_ball_grid_metrics(const World& world);

// large_dt.cpp: the stack and the pendulum wave at dt = 0.1 s
WorldDef stack_dt_01_world_def();
WorldDef pendulum_wave_dt_01_world_def();
std::unique_ptr<Metrics> make_large_dt_metrics(const World& world);

// spin.cpp: a free box spinning about a non-principal axis
WorldDef spin_world_def();
void populate_spin_100(World& world);
void populate_spin_1000(World& world);
std::unique_ptr<Metrics> make_spin_metrics(const World& world);

// sphere_in_box.cpp
WorldDef sphere_in_box_world_def();
void populate_sphere_in_box(World& world);
std::unique_ptr<Metrics> make_sphere_in_box_metrics(const World& world);

// chain.cpp
WorldDef chain_world_def();
void populate_chain_20(World& world);
std::unique_ptr<Metrics> make_chain_metrics(const World& world);

// scale.cpp: the stack in scaled units
/// The stack's world at length scale s (> 0, dimensionless): dt = (1/60 s) sqrt(s), everything
/// else as stack_world_def(). x -> s x, t -> sqrt(s) t, m -> s^3 m leaves the equations of
/// motion, the push factor beta d / dt and the friction limit mu m g invariant with g fixed.
WorldDef scaled_stack_world_def(double s);
/// The stack (ground, 5 cubes) with lengths times s and masses times s^3.
void populate_scaled_stack(World& world, double s);
WorldDef scale_001_world_def();
WorldDef scale_100_world_def();
void populate_scale_001(World& world);
void populate_scale_100(World& world);
std::unique_ptr<Metrics> make_scale_001_metrics(const World& world);
std::unique_ptr<Metrics> make_scale_100_metrics(const World& world);

// degenerate.cpp
WorldDef degenerate_world_def();
void populate_coincident_spheres(World& world);
void populate_parallel_edges(World& world);
void populate_edge_balance(World& world);
void populate_touching_boxes(World& world);
std::unique_ptr<Metrics> make_degenerate_metrics(const World& world);

// hard_cases.cpp: the hard cases (heavy on light, a heavy rope, long runs)
/// heavy_on_light: the static ground plane y = 0 and kHeavyOnLightCubes cubes of one density,
/// edges kHeavyOnLightSmallestEdgeM x 2^k (k = 0 at the bottom), stacked touching, at rest.
WorldDef heavy_on_light_world_def();
void populate_heavy_on_light(World& world);
std::unique_ptr<Metrics> make_heavy_on_light_metrics(const World& world);
/// heavy_rope: the static ground plane y = 0, kHeavyRopeLinks small balls hanging straight down
/// on rods from a fixed point 7 m up, a cube of kHeavyRopeBlockRatio x a link's mass hanging from
/// the last by the middle of its top face, its bottom 1.15 m above the ground; at rest.
WorldDef heavy_rope_world_def();
void populate_heavy_rope(World& world);
/// heavy_rope with the block `ratio` times a link's mass (finite, > 0; dimensionless), the rest as
/// populate_heavy_rope (which is this at kHeavyRopeBlockRatio). Throws std::invalid_argument for a
/// bad ratio.
void populate_heavy_rope_ratio(World& world, double ratio);
std::unique_ptr<Metrics> make_heavy_rope_metrics(const World& world);
/// stack_20_long: stack_20 (scaled.cpp) for kLongRunSteps steps.
void populate_stack_20_long(World& world);
std::unique_ptr<Metrics> make_stack_20_long_metrics(const World& world);
/// pyramid_20_rows_long: pyramid_210 (scaled.cpp: 20 rows of unit boxes) for kLongRunSteps steps.
void populate_pyramid_20_rows_long(World& world);
std::unique_ptr<Metrics> make_pyramid_20_rows_long_metrics(const World& world);

inline constexpr int kHeavyOnLightCubes = 6;
inline constexpr double kHeavyOnLightSmallestEdgeM = 0.1;   ///< m: the bottom cube's edge
inline constexpr double kHeavyOnLightDensity = 1000.0;      ///< kg/m^3 (water): 1 kg to 32768 kg
inline constexpr int kHeavyRopeLinks = 20;
inline constexpr double kHeavyRopeLinkMassKg = 0.1;          ///< kg
inline constexpr double kHeavyRopeLinkRadiusM = 0.05;        ///< m
inline constexpr double kHeavyRopeRodLengthM = 0.25;         ///< m, every rod
inline constexpr double kHeavyRopeBlockRatio = 1800.0;       ///< block mass / link mass (AVBD's HeavyRope)
inline constexpr double kHeavyRopeBlockHalfM = 0.3;          ///< m, the block's half edge
/// Steps of the long runs; their default duration is this times dt = 1/60 s.
inline constexpr int kLongRunSteps = 10000;

// random.cpp
/// Adds a random pile from `seed`: a static ground plane y = 0, then 4 to 12 bodies, each a box
/// (edges 0.05 to 5 m, log-uniform per axis) or a sphere (diameter 0.05 to 5 m, log-uniform),
/// mass 0.01 to 1000 kg (log-uniform), centre uniform in [-4, 4] x [0, 8] x [-4, 4] m (bodies may
/// overlap each other and the ground), uniformly random orientation, velocity of uniformly random
/// direction and speed uniform in [0, 50] m/s, no spin. Deterministic: std::mt19937_64 with the
/// sampling written out (no std distributions), so a seed gives the same scene on every standard
/// library. Never throws for any seed.
void populate_random(World& world, std::uint64_t seed);
void populate_random_seed_1(World& world);
std::unique_ptr<Metrics> make_random_metrics(const World& world);

}  // namespace cps::scenes
