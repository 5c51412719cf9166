#pragma once
// Executing one run of the sweep: the error run (residuals, penetration, rod error, metrics,
// trajectory error against a reference run) and the timed repeats of the physics step alone
// (report/timing.h: CPU time of the thread, quartiles).

#include "report/plan.h"
#include "report/result.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace cps::cli {

/// The reference of the trajectory error: PGS with this many iterations and substeps per 1/60 s
/// frame, and the run's own push and friction model, cold.
inline constexpr int kReferenceIterations = 256;
inline constexpr int kReferenceSubsteps = 16;
/// The reference's substeps in the quick sweep (count per 1/60 s frame): twice the quick sweep's
/// finest run (4 substeps), at half the full reference's cost.
inline constexpr int kQuickReferenceSubsteps = 8;
/// The reference's substeps for a run of the full sweep or of the quick one.
constexpr int reference_substeps(bool quick) { return quick ? kQuickReferenceSubsteps : kReferenceSubsteps; }

/// The timing of one run, carried out apart from its error run so that a sweep can interleave
/// the repeats of all its runs (time_runs): the physics step alone (residuals off, metrics not
/// fed) from the run's start to `until_s` (s), each repeat on a fresh world. One repeat steps the
/// run `copies` times over (kMinRepeatSeconds); `repeat_s` holds each timed repeat's CPU time of
/// the calling thread (s) per copy.
struct TimedRun {
  const scenes::Scene* scene = nullptr;
  scenes::Overrides overrides;
  double until_s = 0.0;              ///< simulated time the run is timed to (s)
  double work = 0.0;                 ///< body-iterations of one copy (run_work)
  int copies = 1;                    ///< copies of the run in one repeat (>= 1)
  std::int64_t steps = 0;            ///< steps of one copy
  double simulated_s = 0.0;          ///< simulated time of one copy (s)
  std::vector<double> repeat_s;      ///< per timed repeat: CPU seconds per copy
  /// CPU seconds (thread clock) of the error run's steps: a little more than one copy costs
  /// (the error run also measures residuals), for estimating the timing's duration.
  double error_run_cpu_s = 0.0;
};

/// A run's error run done: its result (settings and errors, no time yet) and its timing to do.
struct MeasuredRun {
  RunResult result;
  TimedRun timing;
};

/// The error run of `spec` (residuals measured) and its trajectory error: the RMS distance (m)
/// of the movable bodies from a reference run (kReferenceIterations, kReferenceSubsteps) at the
/// scene's trajectory_time_of (references.h: within the references' horizon); reference_check_m
/// (m) is the reference's distance from the same run at half its substeps, an estimate of its own
/// error, and under_reference_error says whether the trajectory error is under it. A diverged
/// run says why in diverged_why (state_fault's words, or the penetration or rod error past the
/// largest movable body's size). The timing is set up to
/// the horizon, or to the time the run diverged (diverged_at_s): a diverged run is timed until
/// then, what the method cost until it failed. The result has no sweep (RunResult::sweep, quick),
/// which the caller adds. Throws UsageError for an unknown scene or a bad parameter.
MeasuredRun measure_errors(const RunSpec& spec);

/// Times `runs` (each TimedRun of measure_errors) with `repeats` (>= 1) timed repeats each, by the
/// CPU time of the thread that steps the repeat (thread_cpu_seconds), on `jobs` threads (>= 1;
/// 1: the calling thread alone). First one untimed warm-up repeat of each run, which also sets
/// its copies: enough for a repeat to last kMinRepeatSeconds, at most as many as keep repeats x
/// copies x work within `max_work` (body-iterations; at least 1). Then `repeats` rounds, each
/// timing one repeat of every run, in plan order and backwards in every other round, a round
/// ending before the next begins: the repeats of the runs a report compares are spread over the
/// same stretch of time, so that a change of the machine's load or clock speed falls on all of
/// them alike. With several jobs, repeats of different runs step at once on different threads:
/// each is charged its own thread's CPU time, but they share the machine's caches and memory.
/// `progress` is called after each repeat (one call at a time) with the repeats done so far, of
/// runs.size() x (repeats + 1).
void time_runs(const std::vector<TimedRun*>& runs, int repeats, double max_work, int jobs,
               const std::function<void(long long)>& progress);

/// The run's time from its repeats (at least one; else nothing is set): cpu_s_per_sim_s and its
/// quartiles cpu_s_per_sim_s_q1, _q3 and least cpu_s_per_sim_s_min (CPU seconds per simulated
/// second), us_per_step (the median per step, us), timing_repeats, runs_per_repeat and
/// timing_threads (`jobs` of time_runs, >= 1), and the machine and build (this_machine,
/// this_build).
void record_timing(const TimedRun& t, int jobs, RunResult& r);

/// One run alone: measure_errors, time_runs of it alone and record_timing.
RunResult execute_run(const RunSpec& spec, int repeats, double max_work);

/// Why the state has blown up, or "" while it has not: "not finite", "a body past 1e6 m from
/// the origin", "a body faster than 1e6 m/s" (text without commas, for diverged_why).
std::string state_fault(const World& world);

/// False once the state is not finite, or a body is further than 1e6 m away or faster than
/// 1e6 m/s (state_fault): the run has blown up and goes no further.
bool sane_state(const World& world);

}  // namespace cps::cli
