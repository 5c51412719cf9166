#pragma once
// `cps report`: error against run time. A sweep over solver settings per scene, each run's
// error measures and physics time, written as CSV, work-precision diagrams (gnuplot) and a
// Markdown report.

#include "scene.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace cps::cli {

/// One run of the sweep: a scene and the settings it runs with. iterations >= 1; substeps >= 1
/// steps per 1/60 s frame, so dt = 1 / (60 substeps) s.
struct RunSpec {
  std::string scene;
  SolverKind solver = SolverKind::pgs;
  PushMode push = PushMode::baumgarte;
  FrictionModel friction_model = FrictionModel::fixed;
  int iterations = 25;
  int substeps = 1;

  /// "scene.solver.push.friction.itN.ssM", e.g. "stack.pgs.baumgarte.fixed.it25.ss1".
  std::string id() const;
  /// The inverse of id(). Throws UsageError naming the id if it is malformed or the scene unknown.
  static RunSpec parse(const std::string& id);
};

/// One CSV row: column name (with its unit) -> value as text ("" where it does not apply).
using Row = std::map<std::string, std::string>;

/// The runs of the sweep for these scenes. Full: iterations 1, 2, 4, ..., 256 at 1 substep and
/// substeps 2, 4, 8, 16 at 25 iterations, for solver pgs and jacobi, push baumgarte and split,
/// friction model fixed and coupled where the scene has friction. Quick: iterations 1, 4, 16, 64
/// and substeps 4 (plus the paper's 25 / 1), friction model fixed only.
std::vector<RunSpec> plan_runs(const std::vector<const scenes::Scene*>& scenes, bool quick);

/// Runs one spec: the error run (residuals measured) and `repeats` timing runs of the physics
/// step alone; the wall time per simulated second is their median. Returns its CSV row.
Row execute_run(const RunSpec& spec, int repeats);

/// Writes DIR/SCENE.csv (one per scene present in rows, columns sorted with the settings first),
/// the work-precision diagrams DIR/SCENE_<measure>.png and .svg through gnuplot, and
/// DIR/report.md. Throws std::runtime_error if a file cannot be written or gnuplot fails
/// (the message says to install gnuplot-nox when it is missing; the CSVs are kept).
void write_report(const std::filesystem::path& dir, const std::vector<Row>& rows);

/// Reads every *.csv below the given folders (as written by write_report or `--run`).
/// Throws std::runtime_error naming a folder that does not exist or a malformed file.
std::vector<Row> read_rows(const std::vector<std::filesystem::path>& dirs);

/// Writes rows as one CSV file (header, then one line per row).
void write_csv(const std::filesystem::path& file, const std::vector<Row>& rows);

}  // namespace cps::cli
