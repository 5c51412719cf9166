#pragma once
// `cps export SCENE --fclib FILE.hdf5 --at STEPS`: the first solve of each chosen step captured
// (World::set_solve_observer, cps/step_system.h) and written as a local frictional contact
// problem of FCLIB (demos/analysis/fclib_problem.h for the mapping; docs/exact_reference.md),
// one file per step, under the output rule (output.h).

#include "scene.h"

#include <optional>
#include <string>

namespace cps::cli {

/// The most steps one --fclib export writes (one file each).
inline constexpr int kMaxFclibSteps = 1000;

/// What `cps export --fclib` was asked for.
struct FclibExportOptions {
  std::string scene;
  std::optional<double> seconds;  ///< s; default: the scene's (the run --at's steps lie in)
  std::string at;                 ///< comma-separated step indices; "": the run's last step
  std::string path;               ///< --fclib FILE.hdf5
  bool force = false;
  double max_work = 0.0;  ///< body-iterations
  scenes::Overrides overrides;
};

/// Runs the export: checks the options, the steps and the files (one step: FILE.hdf5; several:
/// STEM-stepN.hdf5 beside it, N the step) before any step, runs the scene up to the last chosen
/// step, maps each captured solve, then writes every file (a temporary beside it, renamed) and
/// lists them in the folder's run.json (argc, argv). Returns 0. Throws UsageError (exit 2) for
/// a bad option (a name not ending in .hdf5, a step outside the run, more than kMaxFclibSteps
/// steps, a foreign file without --force, FCLIB left out of this build), std::runtime_error
/// naming the step when a chosen step had no solve or no contact, or naming FCLIB's library
/// when it cannot be opened (analysis::load_fclib; checked before the run). Nothing is then
/// written.
int run_fclib_export(const FclibExportOptions& o, int argc, char** argv);

}  // namespace cps::cli
