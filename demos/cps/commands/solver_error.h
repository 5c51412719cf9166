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

/// The most rows a captured system may have for --solver-error (count; pyramid_50 has 975): its
/// exact solve is a dense LCP of up to about twice as many variables (exact_lcp.h), whose Lemke
/// pivots take time and memory that grow as the cube and the square of that (docs/commands.md
/// gives the times). A larger system is refused (exit 2) when the run reaches it, before it is
/// written out or handed to Siconos.
inline constexpr Eigen::Index kMaxExactRows = 1000;

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
  /// written). Writes nothing: finish() creates the folder and the files.
  SolverErrorWriter(SolverErrorPlan plan, const std::string& scene, bool force, nlohmann::json info);
  SolverErrorWriter(const SolverErrorWriter&) = delete;
  SolverErrorWriter& operator=(const SolverErrorWriter&) = delete;

  /// Sets world's solve observer to keep the systems of the planned steps (only theirs are
  /// written out). The writer must outlive the steps. A planned system is refused, by a
  /// UsageError thrown out of World::step before it is written out, when it has more than
  /// kMaxExactRows rows, or when its re-solves (rows x the sum of the --sweeps counts, for each
  /// sweeping method) bring the re-solves' work past `work_left` (row-sweeps, counted as the
  /// run's body-iterations: what --max-work leaves after the run itself).
  void observe(World& world, double work_left);
  /// Solves each captured system exactly and writes one row per step, solve, method (exact,
  /// engine, pgs, jacobi, coloured-pgs for a run under it) and sweep count, and the solves' rows
  /// (solver_error_rows_path): creates the folder, records the run in its run.json
  /// (begin_output with the constructor's `info`), writes both files and lists them there. Returns the rows
  /// written. A planned step with no solve (no contact or rod) is named on stderr. Throws
  /// std::runtime_error when an exact solve fails (naming the step) or the file cannot be
  /// written.
  long finish();

 private:
  SolverErrorPlan plan_;
  OutputPlan output_;
  nlohmann::json info_;
  std::vector<StepSystem> systems_;
  double sweep_work_ = 0.0;  // row-sweeps of the re-solves of the systems kept so far
};

}  // namespace cps::cli
