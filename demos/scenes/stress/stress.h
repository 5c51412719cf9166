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
