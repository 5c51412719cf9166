#pragma once
// The energy watch of `cps simulate`, `cps render` and `cps figure`: whether a run's total
// mechanical energy rose above its start with nothing driving the scene, and the one-line warning
// that says so. docs/findings.md, "Energy that rises with nothing driving it", tells the story
// and the numbers; the definitions are here.
//
// Nothing drives any scene of cps: the engine has no kinematic or animated bodies (a static body
// has m^-1 = 0 and never moves) and the only external force is gravity, whose work is counted in
// the potential. So a rise of KE + PE above its start is energy the step made: the push kept in
// the velocities (Baumgarte, Sec. 5.3) or a solve that did not converge.

#include "scene.h"

#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cps::scenes {

/// The rise that warns, as a fraction (dimensionless) of the energy scale of EnergyRise: a run
/// whose KE + PE ever exceeds its start by more than this fraction of the scale gets the warning.
/// Typical 0.5. Chosen far above what the paper's scenes gain at their defaults where the push
/// does not throw bodies (stack, funnel, pendulum_grid 0, pendulum_wave 0.0015) and below what a
/// bouncing scene under the Baumgarte push gains (the Newton's cradle of the tests: 4.7 in 4 s,
/// 21 in 10 s; the intersecting stack: 12.6).
inline constexpr double kEnergyRiseWarnFraction = 0.5;

/// The mechanical energy of a world's movable bodies (J): kinetic_J = sum 1/2 m |v|^2 + 1/2 w . I w
/// (translational plus rotational), potential_J = -sum m g . x (gravity; datum x = 0, the origin:
/// for the default g = (0, -10, 0) the plane y = 0, the built-in scenes' ground). Static bodies
/// never move and are left out.
struct MechanicalEnergy {
  double kinetic_J = 0.0;
  double potential_J = 0.0;
  /// kinetic_J + potential_J (J).
  double total_J() const { return kinetic_J + potential_J; }
};

/// The energy of `world` as it is now (see MechanicalEnergy). No errors; a state that is not
/// finite gives values that are not finite.
MechanicalEnergy mechanical_energy(const World& world);

/// What the watch measured over a run; energies in J, times in s. E = KE + PE with the
/// potential PE = -sum m g . x of the movable bodies (datum x = 0), as FileSceneMetrics.
struct EnergyRise {
  double start_J = 0.0;  ///< E at the start (the world as it was when the watch began)
  /// The largest E - lift of any step (finite states only): the energy less what the positions'
  /// own corrections lifted so far (lift_J), so that a push that moves bodies out of an overlap
  /// without giving them velocity (split, split-impulse, ngs, soft) is not counted as a gain
  double max_J = 0.0;
  double max_time_s = 0.0;  ///< the world's time at that step (s)
  /// The first time E - lift passed start_J + kEnergyRiseWarnFraction scale_J (s; to 1e-3 of
  /// the bodies' size term), when it did: when the rise happened, where max_time_s may be a
  /// round-off peak of the plateau after it. NaN when it never passed.
  double warn_time_s = std::numeric_limits<double>::quiet_NaN();
  /// The potential energy the positions' own corrections added up to the last step (J, >= 0):
  /// the sum over steps and movable bodies of max(0, -m g . (x2 - x1 - v2 dt)), the lift of the
  /// part of each step's move that is not the stored velocity's (stress.h, W_split). 0 for the
  /// Baumgarte push, whose positions move with the stored momenta.
  double lift_J = 0.0;
  /// The energy scale the rise is measured against (J, >= 0): the larger of
  ///  - the start's energy above the bodies' lowest points: KE(0) + sum_i m_i |g| (h_i(0) - min_t
  ///    h_i(t)), h = height along -g; what the run could turn into motion without any gain,
  ///    independent of the datum (a cradle hanging at 100 m has the scale of one at 1 m), and
  ///  - the bodies' own size: sum_i m_i |g| r_i, r_i the radius of body i's bounding sphere (box:
  ///    |half extents|); the floor for bodies that start at rest and never fall, whose first
  ///    term is 0 (a resting box pushed up by its own size doubles the scale).
  double scale_J = 0.0;
  bool nonfinite = false;  ///< a state was not finite (the rise is measured up to it)
  /// A step of the run had constraint rows (contacts or rods); without any, no push acted and a
  /// rise is the integrator's own (the warning then says so instead of naming a push).
  bool constrained = false;

  /// A body thrown: faster than anything in the scene could make it without a gain (see
  /// EnergyRiseTracker). The total can miss it: a light body thrown out while a heavy one falls.
  struct Thrown {
    int body = -1;           ///< its index in World::bodies()
    double mass_kg = 0.0;    ///< kg
    double speed_mps = 0.0;  ///< m/s, its centre's speed then
    double limit_mps = 0.0;  ///< m/s, the speed it passed
    double time_s = 0.0;     ///< s, the first step it was past the limit
  };
  std::optional<Thrown> thrown;

  /// max_J - start_J (J, >= 0).
  double rise_J() const;
  /// rise_J() / scale_J (dimensionless); +inf for a rise from a scale of 0 (no motion and no
  /// gravity at the start), 0 when nothing rose.
  double fraction() const;
  /// fraction() > kEnergyRiseWarnFraction, or a body was thrown.
  bool warns() const;
};

/// Keeps the running maximum of E, the start, and each movable body's lowest height over a run.
/// observe() the world as built, then after every step. No errors; states that are not finite
/// are skipped (and set EnergyRise::nonfinite).
///
/// A body i is thrown when its centre's speed passes
///   sqrt(1 + kEnergyRiseWarnFraction) (1 + eps) (v0 + sqrt(2 |g| max(0, H - h_i)))
/// with v0 the fastest start speed of any movable body, H the highest point of any movable body
/// at the start (centre plus bounding radius, along -g), h_i the lowest height body i's centre
/// has reached and eps the largest restitution of a contact (the world's, or a body's own,
/// pair_restitution): the speed of a fall from the scene's top plus
/// the fastest start, doubled at most by a bounce (a contact that does not bounce gives a body at
/// most the speed of what hits it), with the total's margin on its kinetic energy. A lever (a
/// heavy body landing on the long arm of a see-saw) can pass it without a gain; no built-in
/// scene has one.
class EnergyRiseTracker {
 public:
  void observe(const World& world);
  /// The measurements so far (all 0 before the first observe()).
  EnergyRise result() const;

 private:
  bool started_ = false;
  EnergyRise rise_;
  double start_kinetic_J_ = 0.0;
  double g_ = 0.0;                  // |g| (m/s^2)
  std::vector<double> mass_;        // kg, by body index; 0 for static bodies
  std::vector<double> start_h_;     // m, height along -g at the start
  std::vector<double> lowest_h_;    // m, lowest height so far
  std::vector<Vec3> previous_x_;    // m, positions at the last observe()
  double previous_time_s_ = 0.0;    // s, the world's time then
  double size_J_ = 0.0;             // sum m |g| r (J)
  // New maxima of E - lift, each at least 1e-3 of size_J_ above the last kept (time s, J), for
  // warn_time_s once the scale is known.
  std::vector<std::pair<double, double>> peaks_;
  double start_speed_mps_ = 0.0;    // v0 (m/s)
  double top_h_ = -kInfinity;       // H (m)
};

/// Wraps run.metrics so that every step also feeds a tracker, which has already observed the
/// world as it is now; returns the tracker (read it after the run). The metrics report as before.
std::shared_ptr<const EnergyRiseTracker> watch_energy_rise(Run& run);

/// The warning for a run of scene `what` (the scene's name, with a variant's label if any) with
/// world parameters `def`: "" when the rise does not warn (EnergyRise::warns), else one line
/// without a newline, e.g.
///   "chain.json: the energy (kinetic + potential) rose 1870 % above its start (+93 J at
///    t = 9.7 s; 100 % = 5 J, ...) with nothing driving the scene, under --push baumgarte (...);
///    try --push split (...)"
/// naming the push method in use and the fix to try for it (docs/findings.md). No errors.
std::string energy_rise_warning(std::string_view what, const WorldDef& def, const EnergyRise& rise);

/// A warning of a run, for the command to print (whole, or its brief once per kind).
struct RunWarning {
  std::string kind;   ///< "divergence" or "energy_rise"
  std::string text;   ///< the whole warning (divergence_warning, energy_rise_warning), one line
  std::string brief;  ///< its first clause: what happened to which run, one short line
  std::string docs;   ///< the docs page and anchor that explain it
};

/// The run's warnings: its divergence (divergence_warning of run.divergence) and its energy rise
/// (energy_rise_warning of the tracker), naming it `scene`, or "scene (label)" with the first
/// line of a --compare variant's non-empty `label` ("push = baumgarte"); none when it neither
/// diverged nor gained energy. No errors.
std::vector<RunWarning> run_warnings(std::string_view scene, std::string_view label, const Run& run,
                                     const EnergyRiseTracker& tracker);

}  // namespace cps::scenes
