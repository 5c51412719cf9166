#pragma once
// report.md: what the numbers are, the headline per scene, each scene's section (its warm
// starting table, diagrams and runs) and the mass ratio table.

#include "report/csv.h"
#include "report/measures.h"
#include "report/result.h"

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace cps::cli {

/// What report.md is made of.
struct ReportContent {
  /// The scenes, in the order of their first run.
  std::vector<std::string> scenes;
  /// The runs of each scene, by scene, in the order given.
  std::map<std::string, std::vector<const RunResult*>> runs;
  /// The diagrams drawn for each scene (draw_diagram), by scene, in kMeasures' order.
  std::map<std::string, std::vector<const Measure*>> diagrams;
  /// Markdown placed after each scene's diagrams, by scene (write_reference_sections), or none.
  std::map<std::string, std::string> scene_sections;
  /// The mass ratio table as written to mass_ratio.csv (mass_ratio_table).
  CsvTable pairs;
  /// The ids of the planned runs that are missing (--merge), of `planned` in all.
  std::vector<std::string> missing;
  std::size_t planned = 0;
  /// How many runs the report holds.
  std::size_t run_count = 0;
  /// What the machine's load was while the runs were timed (a sentence), or "" (a merge).
  std::string load;
  /// Per paper scene, its solver error's medians (solver_error_medians): method -> sweeps ->
  /// median relative force error on the paper run's sampled steps.
  std::map<std::string, std::map<std::string, std::map<int, double>>> solver_error;
};

/// The text of report.md. If `missing` is not empty it opens with INCOMPLETE and names the first
/// 20 of them. The headline (per scene its measure, smaller being better, at the paper's settings
/// and the run's dt, and the cheapest run with at most half of it: report/headline.h; then why
/// each scene's measure is the one it is, ReportTraits::headline_reason) is followed by the
/// omissions' summary (per scene the runs diverged, by cause, and those without a value or
/// time). Each scene's section opens with the table "Warm starting: what PGS needs to reach
/// the paper's error" (per warm start factor, 0 included: the fewest iterations at PGS,
/// Baumgarte, fixed friction, 1 substep whose primary measure is at most the paper's run's,
/// that run's time, its ratio to the paper run's, and the iterations saved, 25 minus the
/// count), then its diagrams (SCENE_<measure>.png), a table of its runs (with whether a
/// trajectory error is under its reference's own error) and its omissions (headline.h:
/// omissions) with their settings, dt, when and why.
std::string report_markdown(const ReportContent& content);

}  // namespace cps::cli
