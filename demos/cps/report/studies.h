#pragma once
// The report's studies as runs of its plan: each paper scene's solver error, its two references
// and its energy over time, and each row of the mass ratio table. A study is run alone (a task of
// the sweep, or `cps report --run ID`) into its CSV; the report is written from those CSVs, so
// that writing it, or merging the CSVs of runs spread over machines, steps no world.

#include "report/csv.h"
#include "report/mass_ratio.h"
#include "report/reference_report.h"

#include <optional>
#include <set>
#include <string>
#include <vector>

namespace cps::cli {

/// What a study computes (reference_report.h, mass_ratio.h).
enum class StudyKind { solver_error, references, energy, mass_ratio };

/// One study of a report's plan. The scene studies are a paper scene's (has_reference_sections);
/// a mass ratio study is one row of the mass ratio table (mass_ratio_rows).
struct StudySpec {
  StudyKind kind = StudyKind::solver_error;
  std::string scene;        ///< the paper scene's name; "" for a mass ratio study
  double mass_ratio = 0.0;  ///< the row's ratio (dimensionless, kMassRatios); mass ratio only
  SolverKind solver = SolverKind::pgs;  ///< the row's solver; mass ratio only
  PushMode push = PushMode::baumgarte;  ///< the row's push; mass ratio only
  /// The quick sweep's study: fewer solver-error samples, the quick horizon for the energy
  /// traces. Not in id(), as for RunSpec; recorded in its CSV.
  bool quick = false;

  /// "SCENE.solver_error", "SCENE.references", "SCENE.energy", or "mass_ratio.R.SOLVER.PUSH"
  /// ("mass_ratio.100.pgs.split-impulse"). No errors.
  std::string id() const;
  /// The CSV it is written to: the report's own name for a scene study (SCENE_solver_error.csv,
  /// SCENE_references.csv, SCENE_energy.csv), "mass_ratio_R_SOLVER_PUSH.csv" for a mass ratio row.
  std::string file_name() const;
  /// The study an id names, or std::nullopt when `id` is not a study's (it may be a run's).
  /// Throws UsageError naming the id when it has a study's form but names no study of this build
  /// (a scene without that study, a ratio, solver or push not in the mass ratio table).
  static std::optional<StudySpec> parse(const std::string& id);
};

/// The studies of the report of `scenes`: per paper scene its solver error, its references
/// (not for a scene judged by its own reference solution) and its energy, then every row of the
/// mass ratio table (mass_ratio_rows), each with `quick`. No errors.
std::vector<StudySpec> plan_studies(const std::vector<const scenes::Scene*>& scenes, bool quick);

/// Runs `spec` and returns its CSV: scene studies as sample_solver_error, scene_agreement and
/// energy_traces compute them (kSolverErrorSamplesQuick samples when quick, else
/// kSolverErrorSamples; kEnergyPoints points), a mass ratio row as run_pair_row. The columns:
/// study_table's. Throws UsageError for a scene this build does not know.
CsvTable run_study(const StudySpec& spec);

/// What a report draws of its studies, read back from their CSVs (add_study_table).
struct ReportStudies {
  std::map<std::string, SceneStudies> scenes;  ///< by scene name; a study missing leaves its part empty
  std::vector<PairRow> pairs;                  ///< the mass ratio rows present, in the table's order
  std::set<std::string> ids;                   ///< the study ids present
};

/// Adds the studies of `table` (a study CSV: run_study's, or the report's own SCENE_<part>.csv and
/// mass_ratio.csv) to `into`; `source` names its file in messages. Throws UsageError naming
/// the source, line, column and cell for a study id this build does not know, a count or a
/// number that is not one, a quick or held that is not 0 or 1; and a study id already in `into`
/// (each study may be merged once).
void add_study_table(const CsvTable& table, const std::string& source, ReportStudies& into);

/// The CSVs of a scene's studies as the report writes them (and run_study returns them): every
/// row starts with the columns study and quick. Solver error: samples, no_solve, then a row per
/// point (step, t_s, solve, rows, method, sweeps, lambda_error_relative, velocity_error_mps,
/// natural_map_N, refused); references: tolerance_m, horizon_s, checked_until_s, exact_solves,
/// exact_cpu_s, stopped, then a row per time (t_s, distance_m); energy: push, diverged_at_s, then
/// a row per recorded step (t_s, kinetic_J, potential_J, total_J, penetration_m, rod_error_m). A
/// study with no point still has one row, its point cells empty. Units in the column names;
/// numbers as number() writes them, "inf" for an infinite one.
CsvTable solver_error_table(const std::string& scene, const SceneStudies& studies);
CsvTable references_table(const std::string& scene, const SceneStudies& studies);
CsvTable energy_table(const std::string& scene, const SceneStudies& studies);

}  // namespace cps::cli
