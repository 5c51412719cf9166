#pragma once
// The headline's choices, apart from how report.md prints them: the paper's run, the value a run
// is ranked by (smaller is better), the cheapest run with at most half the paper's value, and the
// runs the headline and the diagrams leave out (omissions).

#include "report/result.h"

#include <string>
#include <vector>

namespace cps::cli {

/// The run at the paper's settings among `runs` (RunResult::is_paper_setting; the last one if
/// several), or nullptr.
const RunResult* paper_run(const std::vector<const RunResult*>& runs);

/// The value of `measure` (a CSV column) that ranks run `r`, smaller being better: the value
/// itself, or +infinity for a run of the recovery time (metric.recovery_time_s) that never
/// recovered within its horizon (metric.recovered 0), so that it ranks after every run that did.
/// NaN where the run has no value (a diverged run's metrics, a measure it lacks).
double ranked_value(const RunResult& r, const std::string& measure);

/// True if ranked value v is at most half of e0 (the paper's run's): v <= e0 / 2; where e0 is
/// +infinity (the paper's run never recovered) any finite v. False for NaN.
bool at_most_half(double v, double e0);

/// True if ranked value v is at most e0: v <= e0; where e0 is +infinity, any finite v (reaching
/// "never" is no achievement). False for NaN.
bool reaches(double v, double e0);

/// True if the runs of `measure` can be compared with the paper's run `base`: for the trajectory
/// error only runs of base's push and friction model, which are measured against the same
/// reference run (kReferenceIterations, reference_substeps of that push and friction model);
/// every run for any other measure.
bool comparable(const RunResult& r, const RunResult& base, const std::string& measure);

/// The cheapest run (least cpu_s_per_sim_s) among `runs` that has a time, did not diverge, is
/// comparable with `base` and whose ranked value of `measure` is at_most_half of base's; for
/// the trajectory error only if half of base's value is above base's reference's own error
/// (reference_error_m; none: not resolved either), else the halving is not resolved. nullptr if none.
const RunResult* cheapest_halving(const std::vector<const RunResult*>& runs,
                                  const std::string& measure, const RunResult& base);

/// A run the headline leaves out, and why.
struct Omission {
  const RunResult* run = nullptr;
  /// "diverged at T s: WHY" (WHY: diverged_why, or "why not recorded" for a CSV of an older
  /// build), "no value of MEASURE" or "no time".
  std::string why;
};

/// The runs among `runs` that the headline of `measure` leaves out, in their order: every
/// diverged run, and every other run without a ranked value of `measure` or without a time.
/// A run that never recovered has a value (+infinity) and is not omitted.
std::vector<Omission> omissions(const std::vector<const RunResult*>& runs, const std::string& measure);

/// The time step of `r` as report.md prints it: "1/N s" where 1/dt_s is within 1e-5 of a whole
/// N, else its seconds ("0.002 s"); "?" where the run has no dt_s.
std::string dt_text(const RunResult& r);

}  // namespace cps::cli
