#pragma once
// `cps report push`: every push method (every choice of the world parameter push, in the
// table's order: cps::parameter("push").choices) on the same cases, each at the scene's own
// settings with only push changed: the intersecting stack and sphere_in_box (overlaps resolved,
// energy injected, final heights), the stack's drift, the mass ratios that hold, the pendulums'
// rod and phase errors, the cost per step, and the hard cases (survival, penetration,
// energy injected, rod stretch, mass ratio held, with a tuned avbd row on the heavy ones;
// push/cases.h). Writes push.csv, push.md and two diagrams.

#include "report/csv.h"
#include "report/push/cases.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace cps::cli {

/// The scene argument of `cps report` that runs the push methods side by side instead of a
/// sweep.
inline constexpr const char* kPushReport = "push";

/// The files `cps report push` writes into its output folder (plain names): push.csv, push.md,
/// push_overlap.png (the largest overlap against time) and push_speed.png (the largest body
/// speed against time), each also as a PDF of the same name (.pdf, gnuplot's pdfcairo: vector
/// lines and text), and score.csv (the mass ratio scorecard, scorecard.h).
std::vector<std::string> push_report_files();

/// The files it writes into OUT/plots: the gnuplot data and script of each diagram
/// (push_overlap.dat, .gp, push_speed.dat, .gp).
std::vector<std::string> push_plot_files();

/// push.csv of these results: a row per method and case (intersecting_stack, sphere_in_box,
/// stack, mass_ratio, pendulum_grid, pendulum_wave, then the hard cases by scene name: plan.hard),
/// and a row per tuned variant (variant: the parameter set besides push, "" elsewhere); columns
/// with their unit as a suffix (_s, _m, _mps, _J, _rel, _deg; us_per_step: microseconds;
/// iterations: a count); "never" for a time not reached (survival_s: no body left its place),
/// "none" where no mass ratio held, "" where a column does not apply to the case.
CsvTable push_table(const PushPlan& plan, const std::vector<MethodResults>& results);

/// Runs every push method on the cases (plan_push_report; quick: the stack over 60 s instead of
/// 600 s, the pendulum wave over 10 s instead of its 62 s, the 10,000-step hard cases over
/// kQuickLongRunSteps steps) and writes push_report_files()
/// into `out` and push_plot_files() into out/plots, both shared folders (output.h), with `info`
/// (run_info) in their run.json. Every target is checked before any work: throws UsageError
/// (exit 2) naming a foreign file it would replace (without `force`) or an unusable folder.
/// Throws std::runtime_error if a file cannot be written or gnuplot fails (the CSV and the
/// table are written first and kept). Returns the exit code, 0.
int run_push_report(const std::filesystem::path& out, bool quick, bool force,
                    const nlohmann::json& info);

}  // namespace cps::cli
