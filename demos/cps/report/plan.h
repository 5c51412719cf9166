#pragma once
// The plan of `cps report`'s sweeps: which runs a sweep holds (RunSpec), their ids, and the names
// of the files they go to. Plain data: nothing here steps a world.

#include "scene.h"

#include <string>
#include <vector>

namespace cps::cli {

/// The paper's settings of a run (Secs. 7, 10): PGS, Baumgarte push, fixed friction, this many
/// iterations, 1 substep (60 Hz), cold start.
inline constexpr int kPaperIterations = 25;

/// The most substeps a run may take per 1/60 s frame (count): dt = 1 / (60 x 1000) s at least.
inline constexpr int kMaxSubsteps = 1000;

/// The warm start factors (dimensionless) the sweep runs beside the cold start 0.
inline constexpr double kReportWarmStarts[] = {0.8, 1.0};

/// The iteration counts of the quick sweep's warm lines (1 substep).
inline constexpr int kQuickWarmIterations[] = {1, 4, 16, 25};

/// One run of the sweep: a scene and the settings it runs with. iterations >= 1; substeps >= 1
/// steps per 1/60 s frame, so dt = 1 / (60 substeps) s; warm_start is the warm start factor
/// (dimensionless, in [0, 1]; the world parameter warm_start, Sec. 6.2.3): 0, the default, is
/// the paper's cold start from lambda = 0, typical warm values 0.8 and 1.
struct RunSpec {
  std::string scene;
  SolverKind solver = SolverKind::pgs;
  PushMode push = PushMode::baumgarte;
  FrictionModel friction_model = FrictionModel::fixed;
  int iterations = kPaperIterations;
  int substeps = 1;
  double warm_start = 0.0;
  /// The run belongs to the quick sweep: it lasts the scene's quick horizon
  /// (Scene::report_horizon_s) and its reference runs at kQuickReferenceSubsteps. Not in id():
  /// the sweep a run belongs to is recorded beside it (RunResult::quick).
  bool quick = false;

  /// The run's horizon (s): the scene's report_horizon_s(quick). Throws as scene_def().
  double horizon_s() const;

  /// "scene.solver.push.friction.itN.ssM", e.g. "stack.pgs.baumgarte.fixed.it25.ss1", with
  /// ".wsF" after it only when warm_start is not 0 (F its shortest decimal form that reads back
  /// exactly: "stack.pgs.baumgarte.fixed.it4.ss1.ws0.8", ".ws1"), so that the ids of cold runs
  /// are those of builds before warm starting.
  std::string id() const;
  /// The inverse of id(); ".ws0" is taken as a cold run too. Throws UsageError naming the id if
  /// it is malformed, the scene unknown, a count out of range, the warm start factor not a
  /// number in [0, 1], or the run longer than kMaxSteps steps.
  static RunSpec parse(const std::string& id);

  /// The scene (scenes::find_scene). Throws UsageError naming it if this build has none.
  const scenes::Scene& scene_def() const;
  /// The world parameters the run overrides: solver, push, friction model, iterations, warm
  /// start and dt (s): 1 / (60 substeps) for the paper's scenes (substeps of the paper's 60 Hz
  /// frame), the scene's own dt / substeps for the others (stress scenes choose their dt on
  /// purpose). Throws UsageError for an unknown scene.
  scenes::Overrides overrides() const;
};

/// The id of a run from its settings' names (solver, push and friction model as the parameter
/// table names them, e.g. "pgs"): what RunSpec::id() returns for the same settings.
std::string run_id(const std::string& scene, const std::string& solver, const std::string& push,
                   const std::string& friction_model, int iterations, int substeps,
                   double warm_start);

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
/// paper methods, 24 + 8 = 32 runs per scene). A push method runs only the settings it reads
/// (push_reads): avbd at PGS, fixed friction and no warm start alone; xpbd at fixed friction and
/// no warm start alone; the others would repeat the same run under another name.
std::vector<RunSpec> plan_runs(const std::vector<const scenes::Scene*>& scenes, bool quick);

/// The name a scene's files start with: scenes::output_name, never a scene file's path as typed
/// ("runs/drop.json" gives its "name", else "drop"; a scene file that can no longer be read, its
/// stem), so that no file lands in another folder. One report holds one scene file, so file
/// names stay distinct within it. No errors.
std::string file_stem(const std::string& scene);

/// The CSV file name of one run (`cps report --run ID`): its id with the scene part as
/// file_stem, then ".csv" ("stack.pgs.split.fixed.it4.ss1.csv").
std::string run_file_name(const RunSpec& spec);

/// The names of these scenes.
std::vector<std::string> scene_names(const std::vector<const scenes::Scene*>& scenes);

}  // namespace cps::cli
