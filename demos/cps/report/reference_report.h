#pragma once
// The report's sections on solver error and time-step error apart, and on energy over time
// (references.h computes them): per paper scene three CSVs, three diagrams (gnuplot) and the
// paragraphs of report.md that read them.

#include <filesystem>
#include <string>
#include <vector>

namespace cps::cli {

/// The file names of a scene's reference sections: "solver_error", "references", "energy".
inline constexpr const char* kReferenceParts[] = {"solver_error", "references", "energy"};

/// Whether `scene` (a scene name) gets the reference sections: one of the paper's scenes.
bool has_reference_sections(const std::string& scene);

/// Computes and writes a paper scene's sections into DIR: SCENE_solver_error.csv and its diagram
/// (sample_solver_error at the paper's settings, kSolverErrorSamplesQuick samples when `quick`,
/// else kSolverErrorSamples), SCENE_references.csv and its diagram (scene_agreement; not for a
/// scene judged by its own reference solution), SCENE_energy.csv and its diagram
/// (energy_traces), each diagram as .png, .svg and .pdf with its data and script in DIR/plots
/// (SCENE_<part>.dat, .gp). `title_note` is appended to the diagrams' titles. Returns the
/// markdown of the sections, "" for a scene that has none (has_reference_sections). Throws
/// std::runtime_error if a file cannot be written or gnuplot fails.
std::string write_reference_sections(const std::filesystem::path& dir, const std::string& scene,
                                     bool quick, const std::string& title_note);

/// The files write_reference_sections may write into DIR for these scenes (SCENE_<part>.csv,
/// .png, .svg, .pdf), and into DIR/plots (SCENE_<part>.dat, .gp).
std::vector<std::string> reference_files(const std::vector<std::string>& scenes);
std::vector<std::string> reference_plot_files(const std::vector<std::string>& scenes);

}  // namespace cps::cli
