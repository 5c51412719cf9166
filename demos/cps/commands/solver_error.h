#pragma once
// `cps simulate --solver-error FILE.csv`: the systems of chosen steps captured
// (World::set_solve_observer, cps/step_system.h), solved exactly (demos/analysis/exact_lcp.h),
// and the engine's PGS and Jacobi sweeps (Sec. 7; and coloured PGS in the captured order when the
// run uses it) at chosen counts judged against the exact
// solution (demos/analysis/criteria.h), one CSV row per step, solve, method and sweep count.

#include "output/output.h"

#include "cps/step_system.h"
#include "cps/world.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cps::cli {

/// The sweep counts written when --sweeps is not given.
inline constexpr std::string_view kDefaultSweeps = "1,2,5,10,25,100,1000";
/// The most sweeps --sweeps accepts (count): 10^6 sweeps of a 150-row system take about 2 s.
inline constexpr int kMaxSolverErrorSweeps = 1'000'000;

/// What --solver-error asks for: the file, the steps (indices as World::counters().steps before
/// the step: 0 is the first step; sorted, unique) and the sweep counts (sorted, unique).
struct SolverErrorPlan {
  std::filesystem::path path;
  std::vector<std::int64_t> steps;
  std::vector<int> sweeps;
};

/// The steps of `at` (comma-separated step indices in [0, total_steps - 1]; "" gives the run's
/// last step, total_steps - 1), sorted and unique; `option` names the option that holds the
/// list in messages ("--at"). Throws UsageError (exit 2) naming the value and the range for an
/// item that is not such an integer (an empty item, a sign, a fraction), and when the run takes
/// no step.
std::vector<std::int64_t> parse_steps(const std::string& at, std::int64_t total_steps,
                                      const std::string& option);

/// Reads the options into a plan. `at`: comma-separated step indices ("": the run's last step,
/// total_steps - 1); `sweeps`: comma-separated counts. Throws UsageError (exit 2) naming the value and
/// what is allowed: a step outside [0, total_steps - 1], a sweep count that is not an integer in
/// [0, kMaxSolverErrorSweeps], an empty list.
SolverErrorPlan plan_solver_error(const std::string& path, const std::string& at,
                                  const std::string& sweeps, std::int64_t total_steps);

/// The first line of the CSV: the columns with their units (criteria.h for the criteria).
std::string solver_error_header();

/// The file of the solves' rows beside the CSV at `path`: STEM-rows.csv in its folder
/// ("out/se.csv" gives "out/se-rows.csv"): per captured solve and row, step, solve, then
/// system_rows (bounds, b, A_jj, the engine's lambda and the least-norm exact lambda, or with
/// coupled friction the exact solution found).
std::filesystem::path solver_error_rows_path(const std::filesystem::path& path);

/// Captures the planned steps' systems from a world and writes the CSV under the output rule
/// (output.h: the file's folder is a shared output folder; the file is written atomically).
class SolverErrorWriter {
 public:
  /// Checks the path and the rows file beside it (plan_output with option "--solver-error":
  /// UsageError if one exists and no earlier cps run wrote it, or wrote it for another scene than
  /// `scene` (a scene_source), unless `force`; a folder of that name; a folder that cannot be
  /// written), creates the folder and records the run in its run.json (begin_output with `info`).
  SolverErrorWriter(SolverErrorPlan plan, const std::string& scene, bool force, nlohmann::json info);
  SolverErrorWriter(const SolverErrorWriter&) = delete;
  SolverErrorWriter& operator=(const SolverErrorWriter&) = delete;

  /// Sets world's solve observer to keep the systems of the planned steps. The writer must
  /// outlive the steps.
  void observe(World& world);
  /// Solves each captured system exactly and writes one row per step, solve, method (exact,
  /// engine, pgs, jacobi, coloured-pgs for a run under it) and sweep count, and the solves' rows
  /// (solver_error_rows_path), then lists both files in run.json. Returns the rows
  /// written. A planned step with no solve (no contact or rod) is named on stderr. Throws
  /// std::runtime_error when an exact solve fails (naming the step) or the file cannot be
  /// written.
  long finish();

 private:
  SolverErrorPlan plan_;
  OutputPlan output_;
  nlohmann::json info_;
  std::vector<StepSystem> systems_;
};

}  // namespace cps::cli
