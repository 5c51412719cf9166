#pragma once
// `cps report`: error against run time. A sweep over solver settings per scene, each run's
// error measures and physics time, written as CSV, work-precision diagrams (gnuplot) and a
// Markdown report.

#include "scene.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace cps::cli {

/// One run of the sweep: a scene and the settings it runs with. iterations >= 1; substeps >= 1
/// steps per 1/60 s frame, so dt = 1 / (60 substeps) s; warm_start is the warm start factor
/// (dimensionless, in [0, 1]; the world parameter warm_start, Sec. 6.2.3): 0, the default, is
/// the paper's cold start from lambda = 0, typical warm values 0.8 and 1.
struct RunSpec {
  std::string scene;
  SolverKind solver = SolverKind::pgs;
  PushMode push = PushMode::baumgarte;
  FrictionModel friction_model = FrictionModel::fixed;
  int iterations = 25;
  int substeps = 1;
  double warm_start = 0.0;

  /// "scene.solver.push.friction.itN.ssM", e.g. "stack.pgs.baumgarte.fixed.it25.ss1", with
  /// ".wsF" after it only when warm_start is not 0 (F its shortest decimal form that reads back
  /// exactly: "stack.pgs.baumgarte.fixed.it4.ss1.ws0.8", ".ws1"), so that the ids of cold runs
  /// are those of builds before warm starting.
  std::string id() const;
  /// The inverse of id(); ".ws0" is taken as a cold run too. Throws UsageError naming the id if
  /// it is malformed, the scene unknown, a count out of range or the warm start factor not a
  /// number in [0, 1].
  static RunSpec parse(const std::string& id);
};

/// One CSV row: column name (with its unit) -> value as text ("" where it does not apply).
using Row = std::map<std::string, std::string>;

/// True if `push` (a choice of the world parameter push) is one of the paper's push methods: its
/// source names a section of the paper ("Sec. 5.3": baumgarte, "Sec. 8.1": split).
bool is_paper_push(const Choice& push);

/// The runs of the sweep for these scenes. Full: iterations 1, 2, 4, 8, 16, 25, 32, 64, 128, 256
/// at 1 substep and substeps 2, 4, 8, 16 at 25 iterations, for solver pgs and jacobi, every push
/// method of the table (parameter("push").choices, in its order), friction model fixed and
/// coupled where the scene has friction. Quick: iterations 1, 4, 16, 25, 64 at 1 substep and 4
/// substeps at 25 iterations, friction model fixed only, Jacobi only for the paper's push
/// methods (is_paper_push; the others at PGS only, which keeps the quick sweep near 2 minutes
/// with five methods: 250 runs for the paper's five scenes, 160 with two). All of these
/// start cold (warm start 0, the paper's). Warm starting (kReportWarmStarts: factors 0.8 and 1)
/// is swept for PGS only, where it matters most: PGS's Gauss-Seidel sweeps carry a good initial
/// guess forward row by row, while Jacobi's simultaneous updates overshoot from any guess (its
/// runs diverge at the paper's settings in the funnel already). Full: the whole iteration line
/// at 1 substep for each warm factor, every push method and the friction models as above (20
/// runs per push and friction model). Quick: iterations 1, 4, 16, 25 at 1 substep for
/// each warm factor, push baumgarte and fixed friction only (8 runs per scene; with the two
/// paper methods, 24 + 8 = 32 runs per scene).
/// The warm start factors (dimensionless) the sweep runs beside the cold start 0.
inline constexpr double kReportWarmStarts[] = {0.8, 1.0};

/// The iteration counts of the quick sweep's warm lines (1 substep).
inline constexpr int kQuickWarmIterations[] = {1, 4, 16, 25};
std::vector<RunSpec> plan_runs(const std::vector<const scenes::Scene*>& scenes, bool quick);

/// Runs one spec: the error run (residuals measured) and `repeats` timing runs of the physics
/// step alone; the wall time per simulated second is their median (timing_repeats: how many;
/// one if the error run took over 2 s; a diverged run is timed until it diverged,
/// diverged_at_s). The trajectory error (m) is the RMS distance of the movable bodies from a
/// reference run (PGS, 256 iterations, 16 substeps, same push and friction model) at the scene's
/// Scene::report_trajectory_time_s(); reference_check_m (m) is the reference's distance from
/// the same run at 8 substeps, an estimate of its own error. Returns its CSV row, without the
/// sweep columns (sweep, quick), which the caller adds.
Row execute_run(const RunSpec& spec, int repeats);

/// The ids (RunSpec::id) of the runs that the sweeps named in `rows` plan (plan_runs of the
/// row's sweep column, a scene selector as select_scenes takes, and its quick column) and that
/// no row holds, in plan order. A row without a sweep column (an older build's CSV) belongs to
/// the full sweep of its own scene. `planned` is set to the number of distinct planned runs.
std::vector<std::string> missing_runs(const std::vector<Row>& rows, std::size_t& planned);

/// Writes DIR/SCENE.csv (one per scene present in rows, columns sorted with the settings first),
/// the work-precision diagrams DIR/SCENE_<measure>.png, .svg and .pdf through gnuplot (a panel per
/// solver, push and friction model on shared axes, the warm-started iteration lines in the cold
/// run's panel; diverged runs on the top edge; values under
/// the measure's round-off floor drawn on it), DIR/mass_ratio.csv (the mass ratio pair: held or
/// not per ratio, solver and push) and DIR/report.md, whose section per scene opens with the
/// table "Warm starting: what PGS needs to reach the paper's error" (per warm start factor, 0
/// included: the fewest iterations at PGS, Baumgarte, fixed friction, 1 substep whose primary
/// measure is at most the paper's run's, that run's time, its ratio to the paper run's, and
/// the iterations saved, 25 minus the count). If `missing` (run ids, of `planned`) is
/// not empty, report.md opens with INCOMPLETE and names them, and every diagram's title says
/// so. Throws std::runtime_error if a file cannot be written or gnuplot fails (the message says
/// to install gnuplot-nox when it is missing; the CSVs are kept).
void write_report(const std::filesystem::path& dir, const std::vector<Row>& rows,
                  const std::vector<std::string>& missing, std::size_t planned);

/// The files write_report may write into DIR for these scenes (plain names): report.md,
/// mass_ratio.csv, and per scene SCENE.csv and each measure's SCENE_<measure>.png, .svg and .pdf. Every
/// one is checked by the output rule (output.h) before a report's work begins.
std::vector<std::string> report_files(const std::vector<std::string>& scenes);

/// The files write_report may write into DIR/plots for these scenes: each measure's gnuplot data
/// SCENE_<measure>.dat and script SCENE_<measure>.gp.
std::vector<std::string> plot_files(const std::vector<std::string>& scenes);

/// Reads every *.csv below the given folders (as written by write_report or `--run`), except
/// mass_ratio.csv, which holds no runs. Throws UsageError naming a folder that does not exist
/// or a file that is not a report CSV.
std::vector<Row> read_rows(const std::vector<std::filesystem::path>& dirs);

/// Writes rows as one CSV file (header, then one line per row), atomically (atomic_file.h).
/// Throws std::runtime_error "cannot write FILE: REASON" on failure.
void write_csv(const std::filesystem::path& file, const std::vector<Row>& rows);

/// A number as the report's CSVs and tables write it: 6 significant digits (printf "%.6g"), ""
/// for a value that is not finite.
std::string number(double v);

/// False once the state is not finite, or a body is further than 1e6 m away or faster than
/// 1e6 m/s: the run has blown up and goes no further.
bool sane_state(const World& world);

/// Runs gnuplot on `script` (a file). Throws std::runtime_error naming the script, gnuplot's exit
/// status and the first 400 characters of its output if it fails (saying to install
/// gnuplot-nox when it is missing).
void run_gnuplot(const std::filesystem::path& script);

/// `s` as a gnuplot string: in single quotes, a quote inside doubled.
std::string gp_text(const std::string& s);

/// The mass ratios R (heavy cube mass / light cube mass, dimensionless) of the report's mass
/// ratio table (stress scenes mass_ratio_R), ascending.
inline constexpr double kMassRatios[] = {10.0, 100.0, 1000.0};

/// How long each run of the mass ratio table lasts (s of simulated time).
inline constexpr double kPairSeconds = 5.0;

/// The mass ratio pair (stress scenes mass_ratio_R: a heavy cube of R kg resting on a light cube
/// of 1 kg on the ground, both of half edge h = scenes::kMassRatioHalfEdge) at the end of a run.
struct PairOutcome {
  bool finite = false;                    ///< false: the run blew up (nothing below is measured)
  double light_offset_m = std::nan("");   ///< light cube centre to the heavy cube's vertical axis
  double heavy_height_m = std::nan("");   ///< heavy cube centre height; 3 h = 1.5 m when stacked
  double overlap_m = std::nan("");        ///< deepest overlap between any two bodies now (m)
  /// Held: the light cube is still between the heavy cube and the ground, its centre within h
  /// of the heavy cube's vertical axis and the heavy cube's centre within h / 2 of its stacked
  /// height 3 h.
  bool held = false;
};

/// Runs the pair of mass ratio `ratio` (> 0) from rest for `seconds` (s) at the paper's settings
/// (scenes::mass_ratio_world_def(): 60 Hz, beta 0.2, mu 0.5) with this solver, push and
/// iteration count (>= 1). A run that blows up (sane_state) stops and returns finite = false.
PairOutcome run_pair(double ratio, SolverKind solver, PushMode push, int iterations,
                     double seconds);

}  // namespace cps::cli
