#pragma once
// The report's sections on solver error and time-step error apart, and on energy over time
// (references.h computes them): per paper scene the studies, computed before anything is
// written, then three CSVs, three diagrams (gnuplot) and the paragraphs of report.md that read
// them.

#include "report/references.h"

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace cps::cli {

/// The file names of a scene's reference sections: "solver_error", "references", "energy".
inline constexpr const char* kReferenceParts[] = {"solver_error", "references", "energy"};

/// Whether `scene` (a scene name) gets the reference sections: one of the paper's scenes.
bool has_reference_sections(const std::string& scene);

/// What a paper scene's sections show, computed apart from writing them (studies.h: each part
/// is a study of the report's plan, read back from its CSV). A part not present is not drawn.
struct SceneStudies {
  bool quick = false;  ///< the quick sweep's studies (fewer samples, the quick horizon)
  int samples = 0;  ///< steps sampled for the solver error (count); 0: that part not present
  std::vector<SolverErrorPoint> solver_error;  ///< sample_solver_error at the paper's settings
  int no_solve = 0;  ///< sampled steps without a solve (count)
  /// scene_agreement; none for a scene judged by its own reference solution, or not present.
  std::optional<ReferenceAgreement> agreement;
  std::vector<EnergyTrace> energy;  ///< energy_traces, kEnergyPoints recorded steps at most
};

/// The most recorded steps of an energy trace (count).
inline constexpr int kEnergyPoints = 1500;

/// The median relative force error of each line of the solver error (method "pgs" or "jacobi" ->
/// sweeps -> median over the sampled solves of |lambda - lambda*| / |lambda*|, dimensionless;
/// overflowed sweeps count as +inf, refused solves not at all). lambda = 0 has the relative
/// error 1 exactly (|lambda*| is the least-norm solution, the nearest to 0), so a median above 1
/// means the sweeps end further from the solutions than they began: they diverge.
std::map<std::string, std::map<int, double>> solver_error_medians(const SceneStudies& studies);

/// Writes a paper scene's sections from its `studies` into DIR: SCENE_solver_error.csv,
/// SCENE_references.csv (not for a scene judged by its own reference solution) and
/// SCENE_energy.csv (studies.h's tables), each with its diagram as .png, .svg and .pdf and their
/// data and scripts in DIR/plots (SCENE_<part>.dat, .gp); a part not present in `studies` is
/// left out. Steps no world. `title_note` is appended to the diagrams'
/// titles. Returns the markdown of the sections, "" for a scene that has none
/// (has_reference_sections). Throws std::runtime_error if a file cannot be written or gnuplot
/// fails.
std::string write_reference_sections(const std::filesystem::path& dir, const std::string& scene,
                                     const SceneStudies& studies, const std::string& title_note);

/// The files write_reference_sections may write into DIR for these scenes (SCENE_<part>.csv,
/// .png, .svg, .pdf), and into DIR/plots (SCENE_<part>.dat, .gp).
std::vector<std::string> reference_files(const std::vector<std::string>& scenes);
std::vector<std::string> reference_plot_files(const std::vector<std::string>& scenes);

}  // namespace cps::cli
