#include "report/sweep.h"

#include "options/options.h"
#include "options/progress.h"
#include "output/output.h"
#include "report/mass_ratio.h"
#include "report/report.h"
#include "report/run.h"
#include "report/tasks.h"
#include "scene_file.h"

#include <algorithm>
#include <chrono>
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

// Refuses (UsageError) scenes whose report files would share a name: two scenes (as typed: a
// built-in name, or a scene file's path) with one output name (file_stem), such as a scene file
// whose "name" is "stack" beside the built-in stack, or a scene whose output name is one of the
// report's own files.
const std::vector<std::string>& distinct_outputs(const std::vector<std::string>& scenes) {
  std::map<std::string, std::string> by_output;
  for (const std::string& scene : scenes) {
    const std::string stem = file_stem(scene);
    for (const std::string_view reserved : scenes::kReservedOutputNames) {
      if (stem == reserved) {
        throw UsageError("scene " + scene + ": its report files would be named " + stem +
                         ", as the report's own; rename it (its file, or its \"name\")");
      }
    }
    const auto [it, inserted] = by_output.emplace(stem, scene);
    if (!inserted && it->second != scene) {
      throw UsageError("scenes " + it->second + " and " + scene + " are two scenes with one output "
                       "name, " + stem + ": their rows would share " + stem + ".csv and its "
                       "plots; nothing was written. Rename one (its file, or its \"name\"), or "
                       "report them into two --out folders");
    }
  }
  return scenes;
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
                          .files = report_files(distinct_outputs(scenes)),
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
    info["engine_steps"] = World::steps_in_process();
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

// The studies of `tables` (of `studies`, one each), read back as the report draws them.
ReportStudies read_studies(const std::vector<StudySpec>& studies, const std::vector<CsvTable>& tables) {
  ReportStudies read;
  for (std::size_t i = 0; i < studies.size(); ++i) add_study_table(tables[i], studies[i].file_name(), read);
  return read;
}

}  // namespace

int run_sweep(const SweepOutput& to, const std::vector<const scenes::Scene*>& scenes) {
  const std::vector<RunSpec> runs = plan_runs(scenes, to.quick);
  ReportOutput output(to.out, scene_names(scenes), to.force, to.info, /*record_scenes=*/true);

  // What is computed before anything is written: the studies and the error runs, on to.jobs
  // threads, the long studies first.
  const std::vector<StudySpec> studies = plan_studies(scenes, to.quick);
  std::vector<CsvTable> study_tables(studies.size());
  std::vector<std::function<void()>> tasks;
  for (std::size_t i = 0; i < studies.size(); ++i) {
    tasks.push_back([&study_tables, &studies, i] { study_tables[i] = run_study(studies[i]); });
  }
  const std::size_t first_run = tasks.size();
  std::vector<MeasuredRun> measured(runs.size());
  std::vector<bool> run_done(runs.size(), false);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    tasks.push_back([&measured, &runs, i] { measured[i] = measure_errors(runs[i]); });
  }

  // One progress line over every phase. The time left: the computing's rate so far over what
  // is left of it, plus the timing's estimate (each run's error run as the cost of a repeat, at
  // least kMinRepeatSeconds; the median of those measured for the others; spread over the
  // threads), then the timing's own rate once it has begun. Writing the files is not estimated.
  const long long repeats_total = static_cast<long long>(runs.size()) * (to.repeats + 1);
  Progress progress("report " + to.sweep,
                    static_cast<long long>(tasks.size()) + repeats_total + 1, "tasks");
  const auto timing_estimate = [&] {
    std::vector<double> known;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (run_done[i]) known.push_back(std::max(measured[i].timing.error_run_cpu_s, kMinRepeatSeconds));
    }
    const double typical = known.empty() ? kMinRepeatSeconds : quartiles(known).median;
    double sum = 0.0;
    for (const double k : known) sum += k;
    sum += typical * static_cast<double>(runs.size() - known.size());
    const auto threads = static_cast<double>(std::clamp<std::size_t>(runs.size(), 1, to.jobs));
    return sum * (to.repeats + 1) / threads;
  };
  const auto started = std::chrono::steady_clock::now();
  const auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  long long done = 0;
  run_tasks(tasks, to.jobs, [&](std::size_t i) {
    if (i >= first_run) run_done[i - first_run] = true;
    ++done;
    const double compute_left =
        since(started) * static_cast<double>(static_cast<long long>(tasks.size()) - done) /
        static_cast<double>(done);
    progress.update(done, compute_left + timing_estimate());
  });

  // The timed repeats of every run, interleaved (time_runs).
  std::vector<TimedRun*> timed;
  for (MeasuredRun& m : measured) timed.push_back(&m.timing);
  const std::string load_before = load_average();
  const long long computed = done;
  const double timing_first_estimate = timing_estimate();
  const auto timing_started = std::chrono::steady_clock::now();
  time_runs(timed, to.repeats, to.max_work, to.jobs, [&](long long repeats_done) {
    const double left =
        repeats_done > 0 ? since(timing_started) * static_cast<double>(repeats_total - repeats_done) /
                               static_cast<double>(repeats_done)
                         : timing_first_estimate;
    progress.update(computed + repeats_done, left);
  });
  const std::string load_after = load_average();
  const std::string load = "Load averages (1, 5, 15 min, /proc/loadavg) " + load_before +
                           " when the timing began and " + load_after + " when it ended.";
  if (output.info.contains("timing")) {
    output.info["timing"]["load_average_timing_began"] = load_before;
    output.info["timing"]["load_average_timing_ended"] = load_after;
  }
  std::vector<RunResult> results;
  for (MeasuredRun& m : measured) {
    record_timing(m.timing, static_cast<int>(std::min<std::size_t>(to.jobs, measured.size())), m.result);
    results.push_back(in_sweep(to, std::move(m.result)));
  }
  // The report is written from the studies as their CSVs read back, as a merge reads them.
  const ReportStudies read = read_studies(studies, study_tables);
  output.write([&] {
    write_report(to.out, results, read.scenes, read.pairs, {}, results.size() + studies.size(), load);
  });
  progress.finish();
  std::printf("%zu runs: %s/report.md\n", results.size(), to.out.c_str());
  return 0;
}

std::string item_id(const PlanItem& item) {
  return std::visit([](const auto& spec) { return spec.id(); }, item);
}

std::vector<PlanItem> plan_items(const std::vector<const scenes::Scene*>& scenes, bool quick) {
  std::vector<PlanItem> items;
  for (const StudySpec& s : plan_studies(scenes, quick)) items.emplace_back(s);
  for (const RunSpec& r : plan_runs(scenes, quick)) items.emplace_back(r);
  return items;
}

int run_one(const SweepOutput& to, const PlanItem& item) {
  const StudySpec* study = std::get_if<StudySpec>(&item);
  const std::string file = study ? study->file_name() : run_file_name(std::get<RunSpec>(item));
  const std::string scene = study ? study->scene : std::get<RunSpec>(item).scene;
  const OutputPlan plan = plan_output({.folder = to.out,
                                       .files = {file},
                                       .command = "report",
                                       .use = FolderUse::shared,
                                       .scenes = scene.empty()
                                                     ? std::map<std::string, std::string>{}
                                                     : std::map<std::string, std::string>{
                                                           {file, scene_source(scene)}},
                                       .force = to.force});
  nlohmann::json info = to.info;
  if (study) {
    StudySpec spec = *study;
    spec.quick = to.quick;
    const CsvTable table = run_study(spec);
    info["engine_steps"] = World::steps_in_process();
    begin_output(plan, info);
    write_csv(to.out / file, table);
  } else {
    const RunResult result = in_sweep(to, execute_run(std::get<RunSpec>(item), to.repeats, to.max_work));
    info["engine_steps"] = World::steps_in_process();
    begin_output(plan, info);
    write_results(to.out / file, {result});
  }
  end_output(plan, info);
  return 0;
}

std::vector<PlanItem> shard_runs(const std::vector<PlanItem>& runs, Shard shard) {
  std::vector<PlanItem> taken;
  for (std::size_t i = static_cast<std::size_t>(shard.index); i < runs.size();
       i += static_cast<std::size_t>(shard.count)) {
    taken.push_back(runs[i]);
  }
  return taken;
}

int run_shard(const SweepOutput& to, const std::vector<PlanItem>& runs, Shard shard) {
  Progress progress("report " + to.sweep + " shard " + std::to_string(shard.index + 1) + "/" +
                        std::to_string(shard.count),
                    static_cast<long long>(runs.size()), "runs");
  long long done = 0;
  for (const PlanItem& item : runs) {
    run_one(to, item);
    progress.update(++done);
  }
  progress.finish();
  std::printf("shard %d/%d: %zu runs in %s; when every shard has finished: cps report --merge %s "
              "--out REPORT_FOLDER\n",
              shard.index + 1, shard.count, runs.size(), to.out.c_str(),
              shell_quote(to.out.string()).c_str());
  return 0;
}

std::vector<std::string> run_commands(const std::string& exe, const SweepOutput& to,
                                      const std::vector<PlanItem>& runs) {
  std::vector<std::string> lines;
  const std::string out = to.out.string();
  for (const PlanItem& r : runs) {
    lines.push_back(shell_quote(exe) + " report " + shell_quote(to.sweep) + " --run " +
                    shell_quote(item_id(r)) + " --out " + shell_quote(out + "/runs") +
                    (to.quick ? " --quick" : "") +
                    (to.repeats != default_repeats(to.quick) ? " --repeats " + std::to_string(to.repeats) : ""));
  }
  lines.push_back("# when all have finished: " + shell_quote(exe) + " report --merge " +
                  shell_quote(out + "/runs") + " --out " + shell_quote(out));
  return lines;
}

std::vector<std::string> missing_runs(const std::vector<RunResult>& runs,
                                      const std::set<std::string>& study_ids, std::size_t& planned) {
  std::set<std::pair<std::string, bool>> sweeps;
  std::set<std::string> present = study_ids;
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
    for (const PlanItem& item : plan_items(scenes, quick)) {
      const std::string id = item_id(item);
      if (seen.insert(id).second && !present.count(id)) missing.push_back(id);
    }
  }
  planned = seen.size();
  return missing;
}

int merge_report(const SweepOutput& to, const std::vector<fs::path>& dirs) {
  const ReportCsvs csvs = read_results(dirs);
  const std::vector<RunResult>& runs = csvs.runs;
  // The merged report's CSVs would be read as runs by the next merge of that folder.
  const auto resolved = [](const fs::path& p, std::error_code& ec) {
    fs::path r = fs::weakly_canonical(fs::absolute(p), ec).lexically_normal();
    return r.has_filename() ? r : r.parent_path();  // "a/b/" as "a/b"
  };
  std::error_code ec;
  const fs::path out = resolved(to.out, ec);
  for (const fs::path& dir : dirs) {
    std::error_code dir_ec;
    const fs::path from = resolved(dir, dir_ec);
    if (ec || dir_ec) continue;
    const auto [end, at] = std::mismatch(from.begin(), from.end(), out.begin(), out.end());
    if (end == from.end()) {
      throw UsageError("--out " + to.out.string() + " is " + (at == out.end() ? "" : "inside ") +
                       "the --merge folder " + dir.string() + ": the next merge of it would read "
                       "the merged report's CSVs as runs; choose an --out outside every --merge "
                       "folder");
    }
  }
  if (runs.empty()) throw UsageError("--merge: no report CSV found below the given folders");
  ReportStudies studies;
  for (const auto& [source, table] : csvs.studies) add_study_table(table, source, studies);
  std::size_t planned = 0;
  const std::vector<std::string> missing = missing_runs(runs, studies.ids, planned);
  std::vector<std::string> scenes = scenes_of(runs);
  for (const auto& [scene, s] : studies.scenes) {
    if (std::find(scenes.begin(), scenes.end(), scene) == scenes.end()) scenes.push_back(scene);
  }
  ReportOutput output(to.out, scenes, to.force, to.info, /*record_scenes=*/false);
  output.write([&] { write_report(to.out, runs, studies.scenes, studies.pairs, missing, planned); });
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
