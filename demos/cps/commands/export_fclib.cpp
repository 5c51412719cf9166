// `cps export --fclib` (see export_fclib.h).
#include "commands/export_fclib.h"
#include "options/diagnostics.h"

#include "commands/solver_error.h"
#include "commands/system_rows.h"
#include "options/options.h"
#include "options/progress.h"
#include "output/output.h"

#include "cps/step_system.h"

#ifdef CPS_HAVE_FCLIB
#include "exact_lcp.h"
#include "fclib_problem.h"
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace cps::cli {

#ifdef CPS_HAVE_FCLIB
namespace {

const char* terms_name(TargetTerms t) {
  switch (t) {
    case TargetTerms::push_and_bias: return "push and bias";
    case TargetTerms::bias_only: return "bias only (the second solve of Sec. 8.1)";
    case TargetTerms::push_from_rest: return "push from rest (split impulse's pseudo-velocities)";
  }
  return "?";
}

// The text FCLIB keeps beside the problem of step `s` of `scene`.
analysis::FclibText problem_text(const std::string& scene, const StepSystem& s,
                                 const analysis::FclibLocal& p, const nlohmann::json& parameters) {
  char head[512];
  std::snprintf(head, sizeof head,
                "cps export %s: scene %s, step %lld (0 is the first; t = %.9g s at its start), "
                "solve %d of the step (targets: %s), dt = %.17g s, solver %s with %d sweeps, "
                "friction %s; %d contacts (%lld rows), %zu rods. Units: W, V, R in "
                "1/kg, q and s in m/s, r and l impulses in N s, u in m/s. Parameters: ",
                engine_version(), scene.c_str(), static_cast<long long>(s.step),
                static_cast<double>(s.step) * s.dt, s.solve, terms_name(s.terms), s.dt,
                std::string(name_of(s.solver)).c_str(), s.iterations,
                s.friction == FrictionModel::fixed ? "fixed (a box of +-mu m g.n per tangent row)"
                                                   : "coupled (a box of +-mu lambda_n per tangent row)",
                p.contacts(),
                static_cast<long long>(p.W.rows()), p.rod_rows.size());
  return {"cps " + scene + " step " + std::to_string(s.step), head + parameters.dump(),
          analysis::fclib_mapping_text()};
}

// The rows of s beside its FCLIB file, so that cps's own box problem can be solved again from
// the file: per cps row, its FCLIB place (r[i]: the i-th local row; l[k]: the k-th rod row; -:
// none), bounds, coefficient, contact row, b, and the engine's and an exact lambda (N). The
// exact one is the least-norm exact solution (demos/analysis/exact_lcp.h), or with coupled
// friction the one found; `exact_note` says why the column is empty when the exact solve
// refused.
std::string rows_csv(const StepSystem& s, const analysis::FclibLocal& p, std::string& exact_note) {
  std::vector<std::string> place(static_cast<std::size_t>(s.rows()), "-");
  for (std::size_t i = 0; i < p.local_rows.size(); ++i) {
    if (p.local_rows[i] >= 0) place[static_cast<std::size_t>(p.local_rows[i])] = "r[" + std::to_string(i) + "]";
  }
  for (std::size_t k = 0; k < p.rod_rows.size(); ++k) {
    place[static_cast<std::size_t>(p.rod_rows[k])] = "l[" + std::to_string(k) + "]";
  }
  Eigen::VectorXd exact;
  try {
    const analysis::ExactSolution solution = analysis::solve_exact(s);
    exact = s.friction == FrictionModel::fixed
                ? solution.distance(s, Eigen::VectorXd::Zero(s.rows())).nearest
                : solution.lambda;
  } catch (const std::exception& e) {
    exact_note = e.what();
  }
  return system_rows_header("fclib") + "\n" + system_rows(s, "", place, exact);
}

}  // namespace
#endif

int run_fclib_export(const FclibExportOptions& o, int argc, char** argv) {
  if (o.scene == "all" || o.scene == "stress") {
    throw UsageError("export takes one scene, not '" + o.scene + "'");
  }
  const std::filesystem::path path(o.path);
  if (path.extension() != ".hdf5" || path.stem().empty() || path.stem() == ".") {
    throw UsageError("--fclib " + o.path + ": give a file name ending in .hdf5 (an FCLIB file)");
  }
  const scenes::Scene* scene = select_scenes(o.scene).front();
  const std::string scene_name(scene->name);
  scenes::Run run = make_run_or_usage_error(*scene, o.overrides);
  const double seconds = o.seconds.value_or(scene->default_seconds);
  const double dt = run.world.def().dt;
  check_steps(o.scene, seconds, dt);
  check_work(o.scene, run.world.bodies().size(), run.world.def(), seconds, o.max_work,
             lower_run_options(run.world.def()));
  const std::vector<std::int64_t> steps = parse_steps(o.at, std::llround(seconds / dt), "--at");
  if (steps.size() > static_cast<std::size_t>(kMaxFclibSteps)) {
    throw UsageError("--at: " + std::to_string(steps.size()) + " steps, more than the " +
                     std::to_string(kMaxFclibSteps) + " files one --fclib export writes");
  }
  // One step: the file itself; several: STEM-stepN.hdf5 beside it.
  std::map<std::int64_t, std::string> names;
  for (const std::int64_t step : steps) {
    names[step] = steps.size() == 1 ? path.filename().string()
                                    : path.stem().string() + "-step" + std::to_string(step) + ".hdf5";
  }
  // Beside each, STEM-rows.csv: cps's rows, bounds and lambda (rows_csv).
  const auto rows_name = [](const std::string& name) {
    return std::filesystem::path(name).stem().string() + "-rows.csv";
  };
  std::vector<std::string> files;
  std::map<std::string, std::string> sources;
  for (const auto& [step, name] : names) {
    files.push_back(name);
    files.push_back(rows_name(name));
    sources[name] = scene_source(scene->name);
    sources[rows_name(name)] = scene_source(scene->name);
  }
#ifndef CPS_HAVE_FCLIB
  // The options are checked as in a build with FCLIB, so that their errors read the same.
  (void)argc;
  (void)argv;
  throw UsageError("--fclib " + o.path + ": FCLIB was left out of this build (libfclib-dev was "
                   "not found when cps was configured; scripts/deps.sh installs it)");
#else
  // FCLIB's library is opened (dlopen) before the run and before any output: without it the
  // export fails (exit 1) having written nothing.
  try {
    analysis::load_fclib();
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("--fclib " + o.path + ": " + e.what() + "; nothing written");
  }
  const nlohmann::json parameters = parameters_json(run.world.def());
  const nlohmann::json info = run_info("export", argc, argv,
                                       {{"scene", scene->name},
                                        {"seconds", seconds},
                                        {"fclib", o.path},
                                        {"at", steps},
                                        {"overrides", overrides_json(o.overrides)},
                                        {"parameters", parameters}});
  const OutputPlan output = plan_output({.folder = path.parent_path(),
                                         .files = files,
                                         .command = "export",
                                         .use = FolderUse::shared,
                                         .scenes = sources,
                                         .option = "--fclib",
                                         .force = o.force});

  // The first solve of each chosen step, up to the last of them.
  std::map<std::int64_t, StepSystem> captured;
  run.world.set_solve_observer([&](const StepSystem& s) { captured.emplace(s.step, s); },
                               [&](std::int64_t step, int solve, Eigen::Index) {
                                 return solve == 0 && names.count(step) != 0;
                               });
  const std::int64_t last = steps.back();
  Progress progress("export " + o.scene, static_cast<long long>(last + 1), "steps", 2.0);
  while (run.world.counters().steps <= last) {
    run.step();
    progress.update(static_cast<long long>(run.world.counters().steps));
  }
  progress.finish();
  run.world.set_solve_observer({});

  // Every problem mapped before any file is written.
  std::map<std::int64_t, analysis::FclibLocal> problems;
  for (const std::int64_t step : steps) {
    const auto it = captured.find(step);
    if (it == captured.end()) {
      const StepCounters& counted = run.world.counters();
      if (counted.solves == 0 && counted.rows > 0) {
        throw std::runtime_error("--fclib: push " + std::string(name_of(run.world.def().push)) +
                                 " sweeps its own rows and solves no A lambda = b, so its steps "
                                 "have no FCLIB problem; nothing written");
      }
      throw std::runtime_error("--fclib: step " + std::to_string(step) + " of " + scene_name +
                               " had no solve (no contact and no rod then); nothing written");
    }
    try {
      problems.emplace(step, analysis::fclib_local_problem(it->second));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error("--fclib: step " + std::to_string(step) + " of " + scene_name +
                               ": " + e.what() + "; nothing written");
    }
  }
  begin_output(output, info);
  for (const auto& [step, problem] : problems) {
    const std::filesystem::path target = path.parent_path() / names[step];
    // fclib creates the file itself (and adds to an HDF5 file already there): the run's empty
    // temporary is removed, fclib writes that name, and commit() renames it onto the target.
    AtomicFile file(target);
    file.hand_over();
    std::filesystem::remove(file.temporary());
    try {
      analysis::write_fclib_local(problem, problem_text(scene_name, captured.at(step), problem, parameters),
                                  file.temporary());
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("--fclib " + target.string() + ": nothing written (" + e.what() + ")");
    }
    const std::uintmax_t bytes = file.commit();
    notes() << "export " << scene_name << ": step " << step << ", " << problem.contacts()
              << " contacts and " << problem.rod_rows.size() << " rods (W " << problem.W.rows()
              << " x " << problem.W.cols() << ", " << problem.W.nonZeros() << " entries), "
              << bytes << " bytes in " << target.string() << "\n";
    std::string exact_note;
    const std::filesystem::path rows = path.parent_path() / rows_name(names[step]);
    write_text_atomic(rows, rows_csv(captured.at(step), problem, exact_note));
    notes() << "export " << scene_name << ": step " << step << ", its rows, bounds and lambda in "
              << rows.string()
              << (exact_note.empty() ? std::string() : " (no exact lambda: " + exact_note + ")")
              << "\n";
  }
  end_output(output, info);
  return 0;
#endif
}

}  // namespace cps::cli
