#pragma once
// The result of one run of the sweep (RunResult): its settings and measures as named, typed
// fields, one per CSV column, and their CSV files (SCENE.csv, the --run files) written and read
// back by the same code.

#include "report/csv.h"
#include "report/plan.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cps::cli {

/// One run's row of the report's CSVs. Each field is the CSV column of its name (units as the
/// suffix: _s seconds, _m metres, _N newtons, _deg degrees, _rel a ratio; us_per_step
/// microseconds). A measure that is std::nullopt does not apply to the run (its column is left
/// out of a CSV where no row has it); one that is NaN applies but has no value (an empty cell).
/// Measures are kept at the CSV's precision (at_csv_precision). The settings' names are the
/// parameter table's choice names, kept as text so that a CSV of another build reads back.
struct RunResult {
  // The settings (RunSpec).
  std::string scene;
  std::string solver;          ///< "pgs", "jacobi"
  std::string push;            ///< a choice of the world parameter push: "baumgarte", ...
  std::string friction_model;  ///< "fixed", "coupled"
  int iterations = 0;          ///< solver iterations per solve
  int substeps = 0;            ///< steps per 1/60 s frame
  double warm_start = 0.0;     ///< warm start factor; 0 also where a CSV has no column
  std::optional<double> dt_s;       ///< the time step (s)
  std::optional<double> horizon_s;  ///< simulated time of the run (s)

  // What happened.
  bool diverged = false;                ///< the state blew up (see execute_run)
  std::optional<double> diverged_at_s;  ///< when (s); only for a diverged run
  /// Why it diverged (execute_run's words, text without commas: "not finite", "penetration
  /// 3.1 m past the largest body's size 2.4 m", ...); only for a diverged run of this build.
  std::optional<std::string> diverged_why;
  /// Physics CPU time per simulated second (s/s): the median over the timed repeats of the CPU
  /// time of the thread that stepped (report/timing.h), the repeats' first and third
  /// quartiles, and the least of them (the repeat that the machine disturbed least).
  std::optional<double> cpu_s_per_sim_s;
  std::optional<double> cpu_s_per_sim_s_q1;
  std::optional<double> cpu_s_per_sim_s_q3;
  std::optional<double> cpu_s_per_sim_s_min;
  std::optional<double> us_per_step;       ///< the median's CPU time per step (us)
  std::optional<int> timing_repeats;       ///< timed repeats the quartiles are taken over
  std::optional<int> runs_per_repeat;      ///< copies of the run stepped in one timed repeat
  std::optional<int> timing_threads;       ///< threads that stepped timed repeats at once (time_runs jobs)
  std::optional<double> trajectory_time_s;   ///< when positions are compared (s)
  std::optional<double> trajectory_error_m;  ///< RMS distance from the reference run (m)
  /// The substeps per 1/60 s frame of the trajectory error's reference (kReferenceSubsteps, or
  /// kQuickReferenceSubsteps in the quick sweep).
  std::optional<int> reference_substeps;
  /// The reference's distance from the same run at half its substeps (m).
  std::optional<double> reference_check_m;
  /// The order the reference's runs at a quarter, half and all of its substeps show
  /// (observed_order, dimensionless); none where it cannot be measured.
  std::optional<double> reference_order;
  /// The reference's own error (m) from that order: reference_check_m / (2^order - 1); none
  /// where the order is not positive (the distances do not shrink with dt).
  std::optional<double> reference_error_m;
  /// True where trajectory_error_m is under reference_error_m, or the reference has no error
  /// estimate: a difference the reference does not resolve (column under_reference_error, 0 or
  /// 1); only with a trajectory error.
  std::optional<bool> under_reference_error;
  std::optional<double> phase_error_deg;     ///< the metric max_phase_error_deg (deg)
  std::optional<double> residual_max_N;      ///< largest LCP residual of any row (N)
  std::optional<double> residual_rms_N;      ///< RMS LCP residual over every row (N)
  std::optional<double> penetration_max_m;   ///< deepest contact penetration (m)
  std::optional<double> penetration_rms_m;   ///< RMS contact penetration (m)
  std::optional<double> rod_error_max_m;     ///< largest rod length error (m)
  std::optional<double> rod_error_rms_m;     ///< RMS rod length error (m)
  std::optional<double> energy_drift_rel;    ///< the metric energy_drift_rel

  // The sweep the run belongs to (recorded so that --merge can tell what is missing).
  std::optional<std::string> sweep;  ///< the scene argument: a scene, "all" or "stress"
  std::optional<bool> quick;         ///< the quick sweep

  // What the time was measured on (report/timing.h; text without commas).
  std::optional<std::string> machine;  ///< CPU model and logical CPUs (this_machine)
  std::optional<std::string> build;    ///< compiler, build type and flags (this_build)

  /// The scene's numeric metrics (columns "metric.NAME", by NAME; booleans as 0 and 1).
  std::map<std::string, double> metrics;
  /// Columns this build does not know (a CSV of another build), by name, as text.
  std::map<std::string, std::string> other;

  /// The run's id (RunSpec::id of its settings).
  std::string id() const;
  /// "solver push friction_model", e.g. "pgs baumgarte fixed".
  std::string variant() const;
  /// The settings its push reads (push_reads of `push`; all of them for a push this build does
  /// not know, a merged CSV's): a label leaves the others out, as they change nothing.
  PushReads reads() const;
  /// True at the paper's settings: PGS, Baumgarte push, fixed friction, kPaperIterations
  /// iterations, 1 substep, cold start.
  bool is_paper_setting() const;
  /// The number in column `column` (a measure: "trajectory_error_m", "metric.max_speed_mps",
  /// "cpu_s_per_sim_s", ...); NaN where the run has none.
  double value(std::string_view column) const;
  /// The text of column `column` as the CSV writes it; std::nullopt where the run has no such
  /// column (see RunResult).
  std::optional<std::string> cell(std::string_view column) const;
};

/// A result with `spec`'s settings and nothing measured.
RunResult result_of(const RunSpec& spec);

/// The results as one CSV table: the columns any result has, the settings first, then the
/// measures, the sweep, and the metrics and other columns sorted by name; cells as
/// RunResult::cell ("" where a result has no such column).
CsvTable results_table(const std::vector<RunResult>& results);

/// The results in a CSV table (as results_table writes them): empty cells are columns the run
/// does not have. Throws UsageError naming `source` (a file) if the first column is not "scene"
/// or a setting (solver, push, friction_model, iterations, substeps, diverged) is missing, and
/// naming it, the line (CsvTable::lines), the column and the cell for a count that is not one, a
/// cell that reads as a number that is not finite ("nan", "inf", "1e999"; in any column), a
/// number column (a measure, "metric.*", warm_start) that is not all a number, or a diverged,
/// quick or under_reference_error that is not 0 or 1.
std::vector<RunResult> results_of(const CsvTable& table, const std::string& source);

/// Writes results_table(results) to `file` atomically. Throws std::runtime_error "cannot write
/// FILE: REASON" on failure.
void write_results(const std::filesystem::path& file, const std::vector<RunResult>& results);

/// The memory a merge is taken to need per cell of the CSVs it reads (bytes): the table's
/// string, the result's field and the report's copies. Measured: about 100 bytes per cell
/// merging 20,000 rows of 27 columns (55 MB over the 23 MB of a merge of 2 rows).
inline constexpr std::uintmax_t kMergeBytesPerCell = 256;

/// The most memory a merge may be estimated to need (bytes): 256 MiB, about 1 million cells,
/// four times the largest sweep's CSVs (stress: 7,200 runs of about 40 columns).
inline constexpr std::uintmax_t kMergeMemoryLimit = std::uintmax_t{256} << 20;

/// What the CSVs below a merge's folders hold: the runs, and the study tables (header starting
/// with "study": studies.h) with the file each was read from.
struct ReportCsvs {
  std::vector<RunResult> runs;
  std::vector<std::pair<std::string, CsvTable>> studies;
};

/// Reads every *.csv below the given folders (as written by write_report or `--run`), in path
/// order, except an older build's mass_ratio.csv and reference sections, which hold neither
/// runs nor studies: the runs (results_of), and the study tables as they are, to be read by
/// add_study_table. Before parsing any, counts their bytes,
/// rows and cells (rows x header columns) and throws UsageError naming those counts, the
/// estimate (bytes + cells x kMergeBytesPerCell) and the limit if the estimate passes
/// kMergeMemoryLimit. Throws UsageError naming a folder that does not exist; a file found below
/// two given folders (naming both); a file that is not a report CSV (results_of); a cell that is
/// not finite ("nan", "inf"), not a number where one is due, or not 0 or 1 in diverged, quick
/// or under_reference_error (naming the file, line, column and cell); and a run id found twice
/// (naming the id and both files and lines).
ReportCsvs read_results(const std::vector<std::filesystem::path>& dirs);

}  // namespace cps::cli
