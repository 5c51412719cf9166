#pragma once
// The sweep's work-precision diagrams: one measure against physics time, log-log, a panel per
// solver, push and friction model, drawn by gnuplot.

#include "report/measures.h"
#include "report/result.h"

#include <filesystem>
#include <string>
#include <vector>

namespace cps::cli {

/// Draws the diagram of measure `m` over `runs` (the runs of the scene called `scene`) as
/// DIR/SCENE_<measure>.png, .svg and .pdf (SCENE: file_stem; the PDF through gnuplot's pdfcairo
/// terminal, its text as text), with its data and script in DIR/plots (SCENE_<measure>.dat,
/// .gp). Panels per solver, push and friction model (pgs left, jacobi right) on shared axes; in
/// each the iteration line (1 substep), the warm-started iteration lines, the substep line (25
/// iterations), the paper's settings ringed, diverged runs on the top edge (at their time until
/// they diverged), runs that never recovered (ranked_value infinite: headline.h) on the top edge
/// with their own mark, values under the measure's round-off floor (floor_of) drawn on it, and
/// for the trajectory error the reference's own error and, ringed with their own mark, the runs
/// under it (under_reference_error). The key names the dt of the runs at 1 substep. `title_note` is appended to the title. Returns
/// false, writing nothing, if no run that finished has a value of the measure. Throws
/// std::runtime_error if a file cannot be written or gnuplot fails.
bool draw_diagram(const std::filesystem::path& dir, const std::string& scene, const Measure& m,
                  const std::vector<const RunResult*>& runs, const std::string& title_note);

}  // namespace cps::cli
