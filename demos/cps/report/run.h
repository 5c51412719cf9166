#pragma once
// Executing one run of the sweep: the error run (residuals, penetration, rod error, metrics,
// trajectory error against a reference run) and the timing runs of the physics step alone.

#include "report/plan.h"
#include "report/result.h"

namespace cps::cli {

/// The reference of the trajectory error: PGS with this many iterations and substeps per 1/60 s
/// frame, and the run's own push and friction model, cold.
inline constexpr int kReferenceIterations = 256;
inline constexpr int kReferenceSubsteps = 16;

/// Runs one spec: the error run (residuals measured) and `repeats` (>= 1) timing runs of the
/// physics step alone; the wall time per simulated second is their median (timing_repeats: how
/// many; one if the error run took over 2 s; a diverged run is timed until it diverged,
/// diverged_at_s). The trajectory error (m) is the RMS distance of the movable bodies from a
/// reference run (kReferenceIterations, kReferenceSubsteps) at the scene's
/// Scene::report_trajectory_time_s(); reference_check_m (m) is the reference's distance from
/// the same run at half its substeps, an estimate of its own error. Returns the result without
/// the sweep (RunResult::sweep, quick), which the caller adds. Throws UsageError for an unknown
/// scene or a bad parameter.
RunResult execute_run(const RunSpec& spec, int repeats);

/// False once the state is not finite, or a body is further than 1e6 m away or faster than
/// 1e6 m/s: the run has blown up and goes no further.
bool sane_state(const World& world);

}  // namespace cps::cli
