#pragma once
// `cps report`: error against run time. A report folder from the runs of a sweep: the CSVs, the
// work-precision diagrams (gnuplot), the mass ratio table and report.md.

#include "report/mass_ratio.h"
#include "report/reference_report.h"
#include "report/result.h"

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace cps::cli {

/// Writes DIR/SCENE.csv (one per scene present in `runs`, columns as results_table), the
/// work-precision diagrams DIR/SCENE_<measure>.png, .svg and .pdf (draw_diagram, their data and
/// scripts in DIR/plots), DIR/mass_ratio.csv (`pairs`, mass_ratio_table) and DIR/report.md
/// (report_markdown), and each paper scene's sections from its `studies` (write_reference_sections;
/// a scene missing from the map gets none). Steps no world. If `missing` (run ids, of `planned`) is not empty, report.md opens with
/// INCOMPLETE and names them, and every diagram's title says so. Throws std::runtime_error if a
/// file cannot be written or gnuplot fails (the message says to install gnuplot-nox when it is
/// missing; the CSVs are kept). `load` (ReportContent::load): the machine's load while the runs
/// were timed, a sentence for report.md, or "".
void write_report(const std::filesystem::path& dir, const std::vector<RunResult>& runs,
                  const std::map<std::string, SceneStudies>& studies,
                  const std::vector<PairRow>& pairs, const std::vector<std::string>& missing,
                  std::size_t planned, const std::string& load = "");

/// The files write_report may write into DIR for these scenes (plain names): report.md,
/// mass_ratio.csv, and per scene SCENE.csv and each measure's SCENE_<measure>.png, .svg and .pdf. Every
/// one is checked by the output rule (output.h) before a report's work begins.
std::vector<std::string> report_files(const std::vector<std::string>& scenes);

/// The files write_report may write into DIR/plots for these scenes: each measure's gnuplot data
/// SCENE_<measure>.dat and script SCENE_<measure>.gp.
std::vector<std::string> plot_files(const std::vector<std::string>& scenes);

}  // namespace cps::cli
