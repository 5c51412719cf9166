#pragma once
// The sweeps of `cps report`, carried out: a whole sweep into a report folder, one run by its id,
// the commands that spread a sweep over machines, and the merge of their CSVs.

#include "report/plan.h"
#include "report/result.h"
#include "report/studies.h"
#include "report/timing.h"
#include "options/options.h"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <set>
#include <string>
#include <variant>
#include <vector>

namespace cps::cli {

/// Where a sweep's outputs go and what they record.
struct SweepOutput {
  std::string sweep;           ///< the scene argument: a scene, "all" or "stress" (RunResult::sweep)
  bool quick = false;          ///< the quick sweep (RunResult::quick)
  std::filesystem::path out;   ///< the output folder
  bool force = false;          ///< replace same-named foreign files (output.h)
  nlohmann::json info;         ///< run_info for the folders' run.json
  int repeats = kDefaultRepeats;   ///< timed repeats per run (time_runs), in [kMinRepeats, kMaxRepeats]
  double max_work = kDefaultMaxWork;  ///< work budget of a run (body-iterations, --max-work)
  int jobs = 1;  ///< threads that compute the runs and studies (>= 1; --jobs); timing uses one
};

/// One run of a sweep's plan: a study (studies.h) or an error run (plan.h).
using PlanItem = std::variant<StudySpec, RunSpec>;

/// Its id (StudySpec::id, RunSpec::id). No errors.
std::string item_id(const PlanItem& item);

/// The plan of the sweep of `scenes`: its studies (plan_studies), then its error runs
/// (plan_runs), each with `quick`. No errors.
std::vector<PlanItem> plan_items(const std::vector<const scenes::Scene*>& scenes, bool quick);

/// Computes the studies (run_study) and the error runs of plan_items(scenes, quick) on to.jobs
/// threads; then times the runs on this thread alone
/// (to.repeats timed repeats of each, interleaved across the sweep: time_runs); then writes the
/// report (write_report), which steps no world, into `to.out` and
/// `to.out`/plots, both shared folders (output.h). One progress line on stderr covers every
/// phase, with the time left. The results do not depend on to.jobs. Every target is checked before any work:
/// throws UsageError naming a foreign file it would replace (without force) or an unusable
/// folder; std::runtime_error if a file cannot be written or gnuplot fails. Prints "N runs:
/// OUT/report.md" on stdout. Returns the exit code, 0.
int run_sweep(const SweepOutput& to, const std::vector<const scenes::Scene*>& scenes);

/// Runs `item` alone and writes its CSV into `to.out`, a shared folder: a study's table
/// (run_study, StudySpec::file_name), or an error run's one row (execute_run, to.repeats timed
/// repeats, run_file_name) with the sweep it belongs to. Throws as run_sweep does. Returns the
/// exit code, 0.
int run_one(const SweepOutput& to, const PlanItem& item);

/// One shard of a sweep spread over a scheduler (`--shard I/N`): `index` in [0, count), count >= 1.
struct Shard {
  int index = 0;
  int count = 1;
};

/// The runs of `runs` (a plan, plan_items) that `shard` takes: those whose place in the plan is
/// shard.index modulo shard.count, in plan order, so the shards of one count take every run once.
/// Throws nothing.
std::vector<PlanItem> shard_runs(const std::vector<PlanItem>& runs, Shard shard);

/// Runs `runs` (one shard's) one after another as run_one does, each CSV written into `to.out`
/// as soon as its run ends, so a shard stopped half way keeps the runs it finished. Throws as
/// run_one does. Prints one line on stdout with the count and the merge command. Returns 0.
int run_shard(const SweepOutput& to, const std::vector<PlanItem>& runs, Shard shard);

/// The commands of `--list-runs`: per run of `runs`, `'EXE' report 'SWEEP' --run ID --out
/// 'OUT/runs'` (with --quick for a quick sweep, and --repeats N where to.repeats is not
/// default_repeats(to.quick)), then a comment line with the merge command.
std::vector<std::string> run_commands(const std::string& exe, const SweepOutput& to,
                                      const std::vector<PlanItem>& runs);

/// The ids (item_id) of the runs that the sweeps named in `runs` plan (plan_items of the
/// run's sweep, a scene selector as select_scenes takes, and its quick flag) and that neither a
/// run nor a study of `study_ids` holds, in plan order. A run without a sweep (an older build's CSV) belongs to the full sweep
/// of its own scene; a sweep this build cannot select plans nothing. `planned` is set to the
/// number of distinct planned runs.
std::vector<std::string> missing_runs(const std::vector<RunResult>& runs,
                                      const std::set<std::string>& study_ids, std::size_t& planned);

/// Reads the CSVs below `dirs` (read_results: the runs and the studies) and writes one report
/// of them into `to.out` (as run_sweep; `to.sweep` and `to.quick` are not used). Steps no world:
/// a study missing from the CSVs is named as a missing run. Throws
/// UsageError if no report CSV is found or a file is not one, and as run_sweep does. If planned
/// runs are missing (missing_runs), the report is marked INCOMPLETE, stderr names the first 5
/// and the return is 1; else stdout says "merged N runs into OUT/report.md" and the return is 0.
int merge_report(const SweepOutput& to, const std::vector<std::filesystem::path>& dirs);

}  // namespace cps::cli
