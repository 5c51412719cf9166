#pragma once
// The commands of `cps`, one file each in commands/ (list, simulate, scene, parameters, report,
// bench, and with the renderer render, figure, export and diff). Each owns its options: its add_*
// function registers a subcommand on the application with its options and returns how to run
// it; main.cpp parses the command line and runs the command chosen.

#include "options/cli_fwd.h"

#include <functional>

namespace cps::cli {

/// Runs the cps command line argv[0, argc) (argv[0] the program's name, argv[1] the command) as
/// the `cps` executable does: parses it, runs the command, prints its output and messages, and
/// returns the exit status: 0, 1 (a failure), 2 (a usage error) or 3 (a warning under
/// --warnings-as-errors). The diagnostics (--quiet, the warnings printed) start anew each call.
/// No exception escapes (cli_main.cpp).
int run_command(int argc, char** argv);

/// A registered command: its CLI11 subcommand, and what runs it once the command line is parsed
/// (the options it reads live as long as `run`).
struct Command {
  /// The subcommand, owned by the application; true (operator bool) once chosen by the parse.
  CLI::App* sub = nullptr;
  /// Runs the command and returns its exit code (0 on success). Throws UsageError for a bad
  /// value on the command line (exit 2), other exceptions for failures (exit 1).
  std::function<int()> run;
};

/// `cps list`: prints the paper's and the stress scenes with their default duration (s) and
/// summary.
Command add_list(CLI::App& app);

/// `cps simulate SCENE`: runs one scene headless and prints its metrics (--json: one JSON
/// object), optionally a per-step trace CSV; --expect-hash makes it exit 1 if the run ends in
/// another state. argc and argv are recorded in the run.json of the trace's folder.
Command add_simulate(CLI::App& app, int argc, char** argv);

/// `cps report [SCENE]`: the error against run time sweep, written as CSV, plots and report.md
/// into --out (also --list-runs, --run ID and --merge to spread it over machines). argc and
/// argv (the whole command line) are recorded in the folder's run.json.
Command add_report(CLI::App& app, int argc, char** argv);

/// `cps scene NAME`: writes a scene as a scene file (JSON) to stdout or --out FILE (the output
/// rule: never a foreign file without --force, atomically). argc and argv are recorded in the
/// folder's run.json.
Command add_scene(CLI::App& app, int argc, char** argv);

/// `cps parameters`: the world parameter table as Markdown, JSON, the scene schema's world
/// section or tab-separated rows (--format).
Command add_parameters(CLI::App& app);

/// `cps bench`: microseconds per physics step, cost growth with body count and, with the
/// renderer, milliseconds per rendered frame, as Markdown on stdout.
Command add_bench(CLI::App& app);

#ifdef CPS_HAVE_RENDERER
/// `cps render SCENE|all`: PNG frame sequences (optionally side by side per --compare variant,
/// and assembled into a video). argc and argv are recorded in each folder's run.json.
Command add_render(CLI::App& app, int argc, char** argv);

/// `cps figure SCENE|paper`: one labelled PNG, PDF or SVG per figure, a panel per time and variant, with a
/// JSON sidecar that records argc and argv.
Command add_figure(CLI::App& app, int argc, char** argv);

/// `cps export SCENE --out FILE.glb`: a run as a glTF 2.0 binary (meshes, materials in the
/// renderer's colours, rods as cylinders, one animation sampled at --fps, the scene's camera);
/// or `--fclib FILE.hdf5 --at STEPS`: those steps' solves as FCLIB problems (export_fclib.h).
/// argc and argv are recorded in the folder's run.json.
Command add_export(CLI::App& app, int argc, char** argv);

/// `cps diff REFERENCE FRAMES`: two PNG files or two frame folders compared with a tolerance (per frame the
/// largest and mean channel difference and the pixels past a threshold), a diff picture for each
/// frame past it; exit 0 within, 1 past, 2 for usage errors. argc and argv go to run.json.
Command add_diff(CLI::App& app, int argc, char** argv);
#endif

}  // namespace cps::cli
