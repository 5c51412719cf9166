#include "report/sweep.h"

#include "options/options.h"
#include "options/progress.h"
#include "output/output.h"
#include "report/mass_ratio.h"
#include "report/report.h"
#include "report/run.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

namespace cps::cli {
namespace {

namespace fs = std::filesystem;

// The scene (scene_source) of each of `files` (made by `files_of` from scene names) that belongs
// to one scene; the files of every scene (report.md, mass_ratio.csv) are left out.
template <class FilesOf>
std::map<std::string, std::string> scenes_of_files(const std::vector<std::string>& scenes,
                                                   FilesOf files_of) {
  const std::vector<std::string> common = files_of(std::vector<std::string>{});
  std::map<std::string, std::string> out;
  for (const std::string& scene : scenes) {
    for (const std::string& f : files_of(std::vector<std::string>{scene})) {
      if (std::find(common.begin(), common.end(), f) == common.end()) out.emplace(f, scene_source(scene));
    }
  }
  return out;
}

// The report's two folders (OUT and OUT/plots, both shared: see output.h), checked for the
// report of `scenes` before any work; write() then begins them, calls `body` and ends them, so
// that each folder's run.json lists what was written. With `record_scenes`, each scene's files
// record it (a file of another scene of one name is then refused); a merge's scenes are names
// typed in other runs, so it records none.
struct ReportOutput {
  OutputPlan main;
  OutputPlan plots;
  nlohmann::json info;

  ReportOutput(const fs::path& out, const std::vector<std::string>& scenes, bool force,
               nlohmann::json run, bool record_scenes)
      : main(plan_output({.folder = out,
                          .files = report_files(scenes),
                          .command = "report",
                          .use = FolderUse::shared,
                          .scenes = record_scenes ? scenes_of_files(scenes, report_files)
                                                  : std::map<std::string, std::string>{},
                          .force = force})),
        plots(plan_output({.folder = out / "plots",
                           .files = plot_files(scenes),
                           .command = "report",
                           .use = FolderUse::shared,
                           .scenes = record_scenes ? scenes_of_files(scenes, plot_files)
                                                   : std::map<std::string, std::string>{},
                           .force = force})),
        info(std::move(run)) {}

  template <class Body>
  void write(Body&& body) {
    begin_output(main, info);
    begin_output(plots, info);
    body();
    end_output(plots, info);
    end_output(main, info);
  }
};

// A result with the sweep it belongs to.
RunResult in_sweep(const SweepOutput& to, RunResult r) {
  r.sweep = to.sweep;
  r.quick = to.quick;
  return r;
}

// The scenes of `runs`, in the order of their first run.
std::vector<std::string> scenes_of(const std::vector<RunResult>& runs) {
  std::vector<std::string> scenes;
  for (const RunResult& r : runs) {
    if (std::find(scenes.begin(), scenes.end(), r.scene) == scenes.end()) scenes.push_back(r.scene);
  }
  return scenes;
}

}  // namespace

int run_sweep(const SweepOutput& to, const std::vector<const scenes::Scene*>& scenes) {
  const std::vector<RunSpec> runs = plan_runs(scenes, to.quick);
  ReportOutput output(to.out, scene_names(scenes), to.force, to.info, /*record_scenes=*/true);
  std::vector<MeasuredRun> measured;
  measured.reserve(runs.size());
  {
    Progress progress("report " + to.sweep, static_cast<long long>(runs.size()), "runs");
    for (std::size_t i = 0; i < runs.size(); ++i) {
      measured.push_back(measure_errors(runs[i]));
      progress.update(static_cast<long long>(i + 1));
    }
    progress.finish();
  }
  // The timed repeats of every run, interleaved (time_runs).
  std::vector<TimedRun*> timed;
  for (MeasuredRun& m : measured) timed.push_back(&m.timing);
  const std::string load_before = load_average();
  {
    Progress progress("report " + to.sweep + " timing",
                      static_cast<long long>(runs.size()) * (to.repeats + 1), "repeats");
    time_runs(timed, to.repeats, to.max_work, [&](long long done) { progress.update(done); });
    progress.finish();
  }
  const std::string load_after = load_average();
  const std::string load = "Load averages (1, 5, 15 min, /proc/loadavg) " + load_before +
                           " when the timing began and " + load_after + " when it ended.";
  if (output.info.contains("timing")) {
    output.info["timing"]["load_average_timing_began"] = load_before;
    output.info["timing"]["load_average_timing_ended"] = load_after;
  }
  std::vector<RunResult> results;
  for (MeasuredRun& m : measured) {
    record_timing(m.timing, m.result);
    results.push_back(in_sweep(to, std::move(m.result)));
  }
  output.write([&] { write_report(to.out, results, mass_ratio_study(), {}, results.size(), load); });
  std::printf("%zu runs: %s/report.md\n", results.size(), to.out.c_str());
  return 0;
}

int run_one(const SweepOutput& to, const RunSpec& spec) {
  const std::string file = run_file_name(spec);
  const OutputPlan plan = plan_output({.folder = to.out,
                                       .files = {file},
                                       .command = "report",
                                       .use = FolderUse::shared,
                                       .scenes = {{file, scene_source(spec.scene)}},
                                       .force = to.force});
  const RunResult result = in_sweep(to, execute_run(spec, to.repeats, to.max_work));
  begin_output(plan, to.info);
  write_results(to.out / file, {result});
  end_output(plan, to.info);
  return 0;
}

std::vector<std::string> run_commands(const std::string& exe, const SweepOutput& to,
                                      const std::vector<RunSpec>& runs) {
  std::vector<std::string> lines;
  const std::string out = to.out.string();
  for (const RunSpec& r : runs) {
    lines.push_back("'" + exe + "' report '" + to.sweep + "' --run " + r.id() + " --out '" + out +
                    "/runs'" + (to.quick ? " --quick" : "") +
                    (to.repeats != kDefaultRepeats ? " --repeats " + std::to_string(to.repeats) : ""));
  }
  lines.push_back("# when all have finished: '" + exe + "' report --merge '" + out +
                  "/runs' --out '" + out + "'");
  return lines;
}

std::vector<std::string> missing_runs(const std::vector<RunResult>& runs, std::size_t& planned) {
  std::set<std::pair<std::string, bool>> sweeps;
  std::set<std::string> present;
  for (const RunResult& r : runs) {
    sweeps.emplace(r.sweep.value_or(r.scene), r.quick.value_or(false));
    present.insert(r.id());
  }
  std::vector<std::string> missing;
  std::set<std::string> seen;
  for (const auto& [sweep, quick] : sweeps) {
    std::vector<const scenes::Scene*> scenes;
    try {
      scenes = select_scenes(sweep);
    } catch (const std::exception&) {
      // A sweep this build does not know (a CSV of another build): its plan is unknown.
    }
    for (const RunSpec& spec : plan_runs(scenes, quick)) {
      const std::string id = spec.id();
      if (seen.insert(id).second && !present.count(id)) missing.push_back(id);
    }
  }
  planned = seen.size();
  return missing;
}

int merge_report(const SweepOutput& to, const std::vector<fs::path>& dirs) {
  const std::vector<RunResult> runs = read_results(dirs);
  if (runs.empty()) throw UsageError("--merge: no report CSV found below the given folders");
  std::size_t planned = 0;
  const std::vector<std::string> missing = missing_runs(runs, planned);
  ReportOutput output(to.out, scenes_of(runs), to.force, to.info, /*record_scenes=*/false);
  output.write([&] { write_report(to.out, runs, mass_ratio_study(), missing, planned); });
  if (missing.empty()) {
    std::printf("merged %zu runs into %s/report.md\n", runs.size(), to.out.c_str());
    return 0;
  }
  std::string named;
  for (std::size_t i = 0; i < missing.size() && i < 5; ++i) named += (i ? ", " : "") + missing[i];
  if (missing.size() > 5) named += " and " + std::to_string(missing.size() - 5) + " more";
  std::fprintf(stderr,
               "report --merge: %zu of the %zu planned runs are missing: %s. %s/report.md "
               "is marked INCOMPLETE.\n",
               missing.size(), planned, named.c_str(), to.out.c_str());
  return 1;
}

}  // namespace cps::cli
