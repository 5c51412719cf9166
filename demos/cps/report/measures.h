#pragma once
// The error measures the report draws (a work-precision diagram each) and the scenes' headline
// measures: CSV column, labels, unit and round-off floor.

#include <string>

namespace cps::cli {

/// A measure of the work-precision diagrams: its CSV column (RunResult::value), what it is and
/// the y axis' label (both with the unit), the unit ("" for a ratio), and the round-off floor,
/// the value under which the measure shows double precision round-off rather than the method
/// (see kFloorNotes); with floor_per_weight the floor is relative: floor times the scene's
/// largest body weight m |g| (N).
struct Measure {
  const char* column;
  const char* label;
  const char* axis;
  const char* unit;
  double floor;
  bool floor_per_weight = false;
};

/// The measures drawn, in the order of report.md's diagrams.
inline constexpr Measure kMeasures[] = {
    {"trajectory_error_m", "RMS distance from the reference run at the trajectory time (m)",
     "trajectory error (m)", "m", 1e-10},
    {"phase_error_deg", "largest phase error against the reduced-coordinate reference (deg)",
     "phase error (deg)", "deg", 1e-8},
    {"residual_rms_N", "RMS LCP residual over every row of every solve (N)", "residual RMS (N)",
     "N", 1e-12, true},
    {"penetration_max_m", "deepest contact penetration over the run (m)", "penetration (m)", "m",
     1e-10},
    {"rod_error_max_m", "largest rod length error over the run (m)", "rod error (m)", "m", 1e-10},
    {"energy_drift_rel", "largest relative energy drift |E(t) / E(0) - 1|", "|E / E0 - 1|", "",
     1e-12},
    {"metric.recovery_time_s",
     "first time from which every overlap stays under 1 cm and every speed under 0.1 m/s for 0.5 s (s)",
     "recovery time (s)", "s", 1e-10},
    {"metric.max_speed_mps",
     "largest body speed at the end of the run (m/s; 0 is right only once the overlaps are "
     "resolved)", "speed (m/s)", "m/s", 1e-10},
};

/// Why the floors are where they are, for report.md.
inline constexpr const char* kFloorNotes =
    "values under a measure's round-off floor are drawn on the floor (dotted line) with their "
    "own mark: double precision carries 2.2e-16 of relative round-off per operation, so there "
    "they show round-off, not the method. Lengths (trajectory error, penetration, rod error): "
    "1e-10 m; positions metres from the origin carry about 1e-15 m per operation, and a run "
    "takes 1e3 to 1e5 steps of many operations each. LCP residual: 1e-12 of the scene's largest "
    "body weight m |g| (N); a solve exact to round-off leaves about 1e-16 of the forces solved "
    "for. Phase error: 1e-8 deg (2e-10 rad); the pendulum wave's phases grow to 630 rad over "
    "3720 steps, each adding about 1e-13 rad. Energy drift: 1e-12, energies summed over 50 "
    "bodies for 3720 steps. Speed: 1e-10 m/s. Recovery time: 1e-10 s.";

/// The round-off floor of measure `m` in the scene called `scene` (the measure's unit); for a
/// floor per weight, with the largest weight m |g| (N) among the scene's movable bodies (1 N
/// without gravity or for a scene this build does not know).
double floor_of(const Measure& m, const std::string& scene);

/// The CSV column of the headline measure of the scene called `scene` (its Scene::report); the
/// default one for a name no scene has (a CSV of an older build).
std::string primary_measure(const std::string& scene);

/// A human label of a CSV column: the diagram's label of a measure, else the column's name.
std::string label_of(const std::string& column);

}  // namespace cps::cli
