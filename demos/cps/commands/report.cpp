// `cps report`: the error against run time sweeps and the push methods side by side. The
// options are read here; the work is the report library's (report/): sweep.h carries out the
// sweeps, push_report.h the push methods.
#include "command.h"
#include "options/diagnostics.h"

#include "options/options.h"
#include "output/output.h"
#include "report/push/report.h"
#include "report/result.h"
#include "report/run.h"
#include "report/sweep.h"
#include "report/tasks.h"
#include "report/timing.h"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string_view>
#include <utility>

namespace cps::cli {
namespace {

// The options of `cps report`.
struct ReportOptions {
  std::string scene = "all";
  std::string out = "out/report";
  bool quick = false;
  bool list = false;
  std::vector<std::string> merge;
  std::string run;
  std::string shard;  // "I/N" or "slurm"; empty: the whole sweep
  bool force = false;
  double max_work = kDefaultMaxWork;  // body-iterations a run
  int repeats = 0;                    // timed repeats a run; 0: default_repeats(quick)
  int jobs = 0;                       // threads that compute; 0: default_jobs()
};

// CLI11 validator for a count option: a whole number (decimal digits) in [lo, hi]. Its message
// names the text, what is counted (`things`: "timed repeats"), what must be in range (`bound`:
// "timed repeats per run") and the range.
CLI::Validator count_in_range(int lo, int hi, const std::string& things, const std::string& bound) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [range, lo, hi, things, bound](std::string& input) -> std::string {
        int n = 0;
        const char* last = input.c_str() + input.size();
        const auto [end, ec] = std::from_chars(input.c_str(), last, n);
        if (input.empty() || ec == std::errc::invalid_argument || end != last) {
          return "'" + input + "' is not a whole number; give a count of " + things + " in " + range;
        }
        if (ec == std::errc::result_out_of_range || n < lo || n > hi) {
          return "'" + input + "': " + bound + " must be in " + range;
        }
        return {};
      },
      "N in " + range);
}

// Refuses (UsageError, check_work) the first of `runs` whose work to its scene's report horizon
// passes max_work (body-iterations), or whose error run, warm-up and `repeats` timed repeats
// together do, before any of them runs. Bodies are counted once a scene.
void check_runs_work(const std::vector<RunSpec>& runs, double max_work, int repeats) {
  std::map<std::string, std::size_t> bodies;
  for (const RunSpec& r : runs) {
    const scenes::Scene& scene = r.scene_def();
    auto it = bodies.find(r.scene);
    if (it == bodies.end()) {
      it = bodies.emplace(r.scene, make_run_or_usage_error(scene, {}).world.bodies().size()).first;
    }
    const WorldDef def = scenes::world_def_with(scene, r.overrides());
    check_work("run " + r.id(), it->second, def, r.horizon_s(), max_work,
               "give a run with fewer substeps or iterations, or raise --max-work");
    const double work = run_work(it->second, def, r.horizon_s());
    const double total = work * (repeats + 2);
    if (total > max_work) {
      throw UsageError("run " + r.id() + ": its error run, the warm-up and " +
                       std::to_string(repeats) + " timed repeats (--repeats) are " +
                       std::to_string(repeats + 2) + " x " + shortest_decimal(work) + " = " +
                       shortest_decimal(total) + " body-iterations of work, more than the budget "
                       "of " + shortest_decimal(max_work) + " body-iterations a run may take "
                       "(--max-work); give fewer --repeats or raise --max-work");
    }
  }
}

// A whole number in [lo, hi] from all of `text`, or nullopt.
std::optional<int> whole_number(std::string_view text, int lo, int hi) {
  int n = 0;
  const char* last = text.data() + text.size();
  const auto [end, ec] = std::from_chars(text.data(), last, n);
  if (text.empty() || ec != std::errc{} || end != last || n < lo || n > hi) return std::nullopt;
  return n;
}

// `--shard I/N` (I in [1, N], N in [1, kMaxShards]), or `--shard slurm`: the array task's place
// among the array's tasks, from SLURM_ARRAY_TASK_ID, SLURM_ARRAY_TASK_MIN, SLURM_ARRAY_TASK_STEP
// (1 when unset) and SLURM_ARRAY_TASK_COUNT. Throws UsageError naming the bad value.
constexpr int kMaxShards = 100000;  // shards a sweep may be split into (count)
Shard parse_shard(const std::string& text) {
  if (text == "slurm") {
    const auto read = [](const char* name, bool required, int fallback) {
      const char* value = std::getenv(name);
      if (value == nullptr) {
        if (!required) return fallback;
        throw UsageError(std::string("--shard slurm: ") + name + " is not set (run it as a task of "
                         "a Slurm job array: sbatch --array=...), or give --shard I/N");
      }
      const std::optional<int> n = whole_number(value, 0, kMaxShards * 100);
      if (!n) {
        throw UsageError(std::string("--shard slurm: ") + name + "='" + value +
                         "' is not a whole number in [0, " + std::to_string(kMaxShards * 100) + "]");
      }
      return *n;
    };
    const int id = read("SLURM_ARRAY_TASK_ID", true, 0);
    const int min = read("SLURM_ARRAY_TASK_MIN", true, 0);
    const int step = read("SLURM_ARRAY_TASK_STEP", false, 1);
    const int count = read("SLURM_ARRAY_TASK_COUNT", true, 0);
    if (step < 1 || count < 1 || count > kMaxShards || id < min || (id - min) % step != 0 ||
        (id - min) / step >= count) {
      throw UsageError("--shard slurm: task " + std::to_string(id) + " of an array from " +
                       std::to_string(min) + " in steps of " + std::to_string(step) + " with " +
                       std::to_string(count) + " tasks is not one of its tasks (tasks in [1, " +
                       std::to_string(kMaxShards) + "])");
    }
    return {(id - min) / step, count};
  }
  const std::size_t slash = text.find('/');
  const std::optional<int> count =
      slash == std::string::npos ? std::nullopt : whole_number(std::string_view(text).substr(slash + 1), 1, kMaxShards);
  const std::optional<int> index =
      count ? whole_number(std::string_view(text).substr(0, slash), 1, *count) : std::nullopt;
  if (!index) {
    throw UsageError("--shard '" + text + "': give I/N, this shard I of N shards (whole numbers, "
                     "1 <= I <= N <= " + std::to_string(kMaxShards) + "), or 'slurm'");
  }
  return {*index - 1, *count};
}

// The absolute path of this executable, for commands that must run anywhere.
std::string self_path() {
  char path[4096];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return "cps";
  path[n] = '\0';
  return path;
}

// select_scenes for the report's scene argument: its error also names 'push'.
std::vector<const scenes::Scene*> report_scenes(const std::string& name) {
  try {
    return select_scenes(name);
  } catch (const UsageError& e) {
    throw UsageError(std::string(e.what()) + "; cps report also takes '" + kPushReport +
                     "' (every push method side by side: cps report push [--quick] [--out DIR])");
  }
}

// `cps report push`: refuses the sweeps' options, then runs the push methods side by side.
int run_push(const ReportOptions& o, const nlohmann::json& info) {
  const char* sweep_only = !o.run.empty() ? "--run" : !o.merge.empty() ? "--merge"
                           : o.list        ? "--list-runs"
                           : !o.shard.empty() ? "--shard"
                           : o.max_work != kDefaultMaxWork ? "--max-work"
                           : o.repeats != 0                ? "--repeats"
                           : o.jobs != 0                   ? "--jobs" : nullptr;
  if (sweep_only) {
    throw UsageError(std::string("report push: ") + sweep_only +
                     " applies to the sweeps (a scene, 'all' or 'stress'), not to the push "
                     "methods side by side; cps report push takes --out, --quick and --force");
  }
  return run_push_report(o.out, o.quick, o.force, info);
}

int run_report(ReportOptions o, int argc, char** argv) {
  if (o.scene != kPushReport && o.repeats == 0) o.repeats = default_repeats(o.quick);
  nlohmann::json merged = nlohmann::json::array();
  for (const std::string& m : o.merge) merged.push_back(m);
  nlohmann::json info = run_info(
      "report", argc, argv,
      {{"scene", o.scene}, {"quick", o.quick}, {"repeats", o.repeats},
       {"jobs", o.jobs != 0 ? o.jobs : default_jobs()}, {"merge", merged},
       {"run", o.run.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.run)}});
  if (o.scene == kPushReport) return run_push(o, info);
  // What the times are measured on (report/timing.h); a merge's times were measured by the
  // runs it reads, whose CSV rows say where.
  if (o.merge.empty()) {
    info["timing"] = {{"clock", "CLOCK_THREAD_CPUTIME_ID"},
                      {"machine", this_machine()},
                      {"build", this_build()},
                      {"load_average_at_start", load_average()}};
  }
  const SweepOutput to{o.scene, o.quick, o.out,      o.force, info,
                       o.repeats, o.max_work, o.jobs != 0 ? o.jobs : default_jobs()};
  if (!o.merge.empty()) return merge_report(to, {o.merge.begin(), o.merge.end()});
  if (!o.run.empty()) {
    report_scenes(o.scene);  // the sweep it belongs to must be one
    if (std::optional<StudySpec> study = StudySpec::parse(o.run)) {
      study->quick = o.quick;
      return run_one(to, *study);
    }
    RunSpec spec = RunSpec::parse(o.run);
    spec.quick = o.quick;
    check_runs_work({spec}, o.max_work, o.repeats);
    return run_one(to, spec);
  }
  const std::vector<const scenes::Scene*> scenes = report_scenes(o.scene);
  check_runs_work(plan_runs(scenes, o.quick), o.max_work, o.repeats);
  const std::vector<PlanItem> runs = plan_items(scenes, o.quick);
  if (!o.shard.empty()) {
    const Shard shard = parse_shard(o.shard);
    return run_shard(to, shard_runs(runs, shard), shard);
  }
  if (o.list) {
    // One command a line: a newline or another control character in a quoted word would split it.
    for (const auto& [what, text] : {std::pair<std::string, std::string>{"--out", o.out},
                                     {"the scene argument", o.scene},
                                     {"this executable's path", self_path()}}) {
      for (const char c : text) {
        if (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f) continue;
        char code[8];
        std::snprintf(code, sizeof code, "0x%02x", static_cast<unsigned>(static_cast<unsigned char>(c)));
        throw UsageError("--list-runs: " + what + " holds the control character " + code +
                         ", and the listed commands are one a line; give it without control "
                         "characters (newlines, tabs, escapes)");
      }
    }
    // Each run's command carries a --max-work given here (and --repeats: run_commands).
    const std::string budget =
        o.max_work != kDefaultMaxWork ? " --max-work " + shortest_decimal(o.max_work) : "";
    for (const std::string& line : run_commands(self_path(), to, runs)) {
      std::printf("%s%s\n", line.c_str(), line.rfind("#", 0) == 0 ? "" : budget.c_str());
    }
    return 0;
  }
  return run_sweep(to, scenes);
}

}  // namespace

Command add_report(CLI::App& app, int argc, char** argv) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* sub = app.add_subcommand(
      "report", "error against run time: sweep solver settings, write CSV, plots, report.md; "
                "'cps report push': every push method side by side (push.csv, push.md, plots)");
  sub->add_option("scene", o->scene,
                  "scene name, the path of a scene file (.json), 'all' (the paper's) or "
                  "'stress'; with --run, the sweep the run belongs to; 'push': instead of a "
                  "sweep, every push method (the choices of --push) on the same cases: the "
                  "intersecting stack and sphere_in_box (overlaps resolved, energy injected, "
                  "final heights), the stack over 600 s (60 s with --quick), the mass ratios "
                  "that hold, the pendulums' rod and phase errors and the cost per step, into "
                  "push.csv, push.md, push_overlap.png and push_speed.png in --out")
      ->capture_default_str();
  add_seed_option(*sub, o->scene);
  sub->add_option("--out", o->out, "output folder")->capture_default_str()->check(kNotEmpty);
  const std::size_t quick_runs = plan_runs(select_scenes("all"), true).size();
  sub->add_flag("--quick", o->quick,
                "a reduced sweep: iterations 1, 4, 16, 25, 64 and 4 substeps, fixed friction "
                "only, Jacobi for the paper's push methods only, and warm-started PGS (warm "
                "start 0.8 and 1) at iterations 1, 4, 16, 25 with Baumgarte push; references "
                "at " + std::to_string(kQuickReferenceSubsteps) + " substeps, the pendulum "
                "wave over its first " + shortest_decimal(*scenes::find_scene("pendulum_wave")->report.quick_horizon_s) +
                " s, " + std::to_string(kQuickRepeats) + " timed repeats (the paper's five "
                "scenes: " + std::to_string(quick_runs) + " runs; its time: docs/benchmarks.md); "
                "with 'push': the stack over 60 s "
                "and the pendulum wave over 10 s");
  CLI::Option* list = sub->add_flag("--list-runs", o->list,
                "print one self-contained command per run, to spread the sweep over machines");
  CLI::Option* merge = sub->add_option("--merge", o->merge,
                  "combine the CSV files below these folders into one report in --out; if runs "
                  "of the sweeps they belong to are missing, it names them on stderr, writes the "
                  "report marked INCOMPLETE at the top (and in every diagram's title) and exits "
                  "with 1; refused (exit 2, nothing written): a run id found twice, a folder "
                  "given twice, a cell that is not finite, and CSVs estimated past " +
                  std::to_string(kMergeMemoryLimit >> 20) + " MiB of memory")
      ->check(kNotEmpty);
  CLI::Option* run = sub->add_option("--run", o->run,
                  "execute one run of the plan, an error run or a study, by its id (see --list-runs); "
                  "the scene argument and --quick "
                  "name the sweep it belongs to, recorded in its CSV for --merge")
      ->check(kNotEmpty);
  CLI::Option* shard = sub->add_option("--shard", o->shard,
                  "I/N: run only this shard's part of the sweep, every N-th run of its plan from "
                  "the I-th (1 <= I <= N), each run's CSV written into --out as it ends; 'slurm': "
                  "I and N of this task of a Slurm job array (SLURM_ARRAY_TASK_ID, _MIN, _STEP, "
                  "_COUNT); merge the shards' folders with --merge")
      ->type_name("I/N")
      ->check(kNotEmpty);
  add_max_work_option(*sub, o->max_work);
  sub->add_option("--repeats", o->repeats,
                  "timed repeats of each run, in [" + std::to_string(kMinRepeats) + ", " +
                      std::to_string(kMaxRepeats) + "]; default " +
                      std::to_string(kDefaultRepeats) + ", " + std::to_string(kQuickRepeats) +
                      " with --quick: the CPU time of the stepping thread, "
                      "after one untimed warm-up repeat, a repeat stepping a short run several "
                      "times over to last " + shortest_decimal(kMinRepeatSeconds) + " s; the "
                      "repeats of a sweep's runs are interleaved; the CSV gives their median, "
                      "quartiles and least; the error run, the warm-up and the repeats together "
                      "must stay within --max-work")
      ->type_name("N")
      ->check(count_in_range(kMinRepeats, kMaxRepeats, "timed repeats", "timed repeats per run"));
  sub->add_option("--jobs", o->jobs,
                  "threads that compute the runs' errors and the scenes' studies and step the "
                      "timed repeats, in [1, " + std::to_string(kMaxJobs) + "]; default: the "
                      "machine's logical CPUs. The errors do not depend on it; each repeat is "
                      "charged its own thread's CPU time, and --jobs 1 times with nothing else "
                      "of the report running beside it")
      ->type_name("N")
      ->check(count_in_range(1, kMaxJobs, "threads", "threads"));
  run->excludes(merge)->excludes(list)->excludes(shard);
  merge->excludes(list)->excludes(shard);
  list->excludes(shard);
  sub->add_flag("--force", o->force,
                "let the report replace files in --out that have the names of its own outputs "
                "but that no earlier cps run wrote there (other files are never touched)");
  add_diagnostic_flags(*sub);
  return {sub, [o, argc, argv] { return run_report(*o, argc, argv); }};
}

}  // namespace cps::cli
