// The cps command: list the scenes, simulate them headless, render them to PNG frames.
#include "options.h"
#include "simulate.h"

#include "bench.h"
#include "output.h"
#include "progress.h"
#include "report.h"

#ifdef CPS_HAVE_RENDERER
#include "render.h"
#endif

#include <chrono>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <regex>

namespace {

using namespace cps;

struct SizeWxH {
  int width = 1280;
  int height = 720;
};

SizeWxH parse_size(const std::string& text) {
  static const std::regex pattern(R"((\d{1,5})x(\d{1,5}))");
  std::smatch m;
  if (!std::regex_match(text, m, pattern)) {
    throw cli::UsageError("--size " + text + " is not WxH (e.g. 1280x720)");
  }
  SizeWxH s{std::stoi(m[1]), std::stoi(m[2])};
  if (s.width < 16 || s.width > 8192 || s.height < 16 || s.height > 8192) {
    throw cli::UsageError("--size " + text + ": width and height must be in [16, 8192] pixels");
  }
  return s;
}

// Metrics that also report steps done to a Progress: the hook called after every step, so a long
// `cps simulate` shows progress without changing how it runs.
class ProgressMetrics final : public scenes::Metrics {
 public:
  ProgressMetrics(std::unique_ptr<scenes::Metrics> inner, cli::Progress& progress)
      : inner_(std::move(inner)), progress_(progress) {}
  void observe(const World& world) override {
    inner_->observe(world);
    progress_.update(++steps_);
  }
  nlohmann::json report() const override { return inner_->report(); }

 private:
  std::unique_ptr<scenes::Metrics> inner_;
  cli::Progress& progress_;
  long long steps_ = 0;
};

// The absolute path of this executable, for commands that must run anywhere.
std::string self_path() {
  char path[4096];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return "cps";
  path[n] = '\0';
  return path;
}

int run_report(const std::string& scene_name, const std::string& out, bool quick, bool list,
               const std::vector<std::string>& merge, const std::string& one_run, int argc,
               char** argv) {
  namespace fs = std::filesystem;
  // run.json in the report folder: what produced it (written after the report, atomically).
  const auto write_run_json = [&] {
    nlohmann::json merged = nlohmann::json::array();
    for (const std::string& m : merge) merged.push_back(m);
    const nlohmann::json info = cli::run_info(
        "report", argc, argv,
        {{"scene", scene_name}, {"quick", quick}, {"repeats", quick ? 1 : 3}, {"merge", merged}});
    nlohmann::json j = info;
    j["tool"] = "cps";
    cli::write_json_atomic(fs::path(out) / cli::k_manifest_name, j);
  };
  const int repeats = quick ? 1 : 3;
  if (!merge.empty()) {
    std::vector<fs::path> dirs(merge.begin(), merge.end());
    const std::vector<cli::Row> rows = cli::read_rows(dirs);
    if (rows.empty()) throw cli::UsageError("--merge: no report CSV found below the given folders");
    cli::write_report(out, rows);
    write_run_json();
    std::printf("merged %zu runs into %s/report.md\n", rows.size(), out.c_str());
    return 0;
  }
  if (!one_run.empty()) {
    const cli::RunSpec spec = cli::RunSpec::parse(one_run);
    const cli::Row row = cli::execute_run(spec, repeats);
    fs::create_directories(out);
    cli::write_csv(fs::path(out) / (spec.id() + ".csv"), {row});
    return 0;
  }
  const std::vector<cli::RunSpec> runs = cli::plan_runs(cli::select_scenes(scene_name), quick);
  if (list) {
    const std::string exe = self_path();
    for (const cli::RunSpec& r : runs) {
      std::printf("'%s' report --run %s --out '%s/runs'%s\n", exe.c_str(), r.id().c_str(),
                  out.c_str(), quick ? " --quick" : "");
    }
    std::printf("# when all have finished: '%s' report --merge '%s/runs' --out '%s'\n",
                exe.c_str(), out.c_str(), out.c_str());
    return 0;
  }
  std::vector<cli::Row> rows;
  cli::Progress progress("report " + scene_name, static_cast<long long>(runs.size()), "runs");
  for (std::size_t i = 0; i < runs.size(); ++i) {
    rows.push_back(cli::execute_run(runs[i], repeats));
    progress.update(static_cast<long long>(i + 1));
  }
  progress.finish();
  cli::write_report(out, rows);
  write_run_json();
  std::printf("%zu runs: %s/report.md\n", rows.size(), out.c_str());
  return 0;
}

int run(int argc, char** argv) {
  CLI::App app{"cps: the constraint based physics solver of Tamis & Maggiore (2015)"};
  app.require_subcommand(1);

  CLI::App* list = app.add_subcommand("list", "print the scenes");

  std::string sim_scene;
  std::optional<double> sim_seconds;
  bool sim_json = false;
  scenes::Overrides sim_overrides;
  CLI::App* simulate = app.add_subcommand("simulate", "run a scene headless and report metrics");
  simulate->add_option("scene", sim_scene, "scene name (see 'cps list')")->required();
  simulate->add_option("--seconds", sim_seconds, "simulated time (s), > 0; default: the scene's")
      ->check(cli::kFinitePositive);
  simulate->add_flag("--json", sim_json, "print one JSON object");
  cli::add_world_options(*simulate, sim_overrides);

  std::string report_scene = "all";
  std::string report_out = "out/report";
  bool report_quick = false;
  bool report_list = false;
  std::vector<std::string> report_merge;
  std::string report_run;
  CLI::App* report = app.add_subcommand(
      "report", "error against run time: sweep solver settings, write CSV, plots, report.md");
  report->add_option("scene", report_scene, "scene name, 'all' (the paper's) or 'stress'")
      ->capture_default_str();
  report->add_option("--out", report_out, "output folder")->capture_default_str();
  report->add_flag("--quick", report_quick, "a reduced sweep (about 2 minutes for all scenes)");
  report->add_flag("--list-runs", report_list,
                   "print one self-contained command per run, to spread the sweep over machines");
  report->add_option("--merge", report_merge,
                     "combine the CSV files below these folders into one report in --out");
  report->add_option("--run", report_run, "execute one run by its id (see --list-runs)");

  bool bench_quick = false;
  CLI::App* bench = app.add_subcommand(
      "bench", "microseconds per step (explicit and matrix-free), cost growth, ms per frame");
  bench->add_flag("--quick", bench_quick, "smaller scenes and fewer steps");
  bool bench_rendering = false;
  bench->add_flag("--rendering", bench_rendering,
                  "only the rendering table (ms per frame at 1280x720: draw, PNG, end to end)");

#ifdef CPS_HAVE_RENDERER
  std::string render_scene;
  std::optional<double> render_seconds;
  double fps = 30.0;
  std::string size_text = "1280x720";
  std::string out_dir = "out";
  std::string compare;
  scenes::Overrides render_overrides;
  CLI::App* render = app.add_subcommand("render", "render scenes into PNG frame sequences");
  render->add_option("scene", render_scene, "scene name or 'all'")->required();
  render->add_option("--seconds", render_seconds, "simulated time (s), > 0; default: the scene's")
      ->check(cli::kFinitePositive);
  render->add_option("--fps", fps, "frames per simulated second, > 0")->capture_default_str()
      ->check(cli::kFinitePositive);
  render->add_option("--size", size_text, "frame size WxH in pixels, each in [16, 8192]")->capture_default_str();
  render->add_option("--out", out_dir, "output folder; frames go to OUT/SCENE/")->capture_default_str();
  render->add_option("--compare", compare,
                     "render the two variants of this option side by side, labelled, into "
                     "OUT/SCENE-compare-OPTION/")
      ->check(CLI::IsMember({"push", "solver", "friction-model", "rotation"}));
  bool render_force = false;
  render->add_flag("--force", render_force,
                   "write into an output folder that holds files no earlier cps run wrote there "
                   "(they are kept; same-named files are replaced)");
  cli::add_world_options(*render, render_overrides);
#endif

  std::string names;
  bool known = false;
  for (const CLI::App* sub : app.get_subcommands({})) {
    names += (names.empty() ? "" : ", ") + sub->get_name();
    known = known || (argc > 1 && sub->get_name() == argv[1]);
  }
  if (argc > 1 && argv[1][0] != '-' && !known) {
    std::cerr << "cps: unknown command '" << argv[1] << "'; the commands are: " << names
              << "\nRun 'cps --help' for usage.\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "cps: " << e.what() << "\nRun 'cps --help' or 'cps COMMAND --help' for usage.\n";
    return 2;
  }

  try {
    if (*list) {
      const auto print = [](const char* title, std::span<const scenes::Scene> table) {
        std::printf("%s\n", title);
        for (const scenes::Scene& s : table) {
          std::printf("  %-22s %5.0f s  %s\n", std::string(s.name).c_str(), s.default_seconds,
                      std::string(s.summary).c_str());
        }
      };
      print("The paper's scenes (Sec. 10; 'all'):", scenes::paper_scenes());
      print("Stress scenes ('stress'):", scenes::stress_scenes());
      return 0;
    }
    if (*simulate) {
      const std::vector<const scenes::Scene*> chosen = cli::select_scenes(sim_scene);
      if (sim_scene == "all" || sim_scene == "stress") {
        throw cli::UsageError("simulate takes one scene, not '" + sim_scene + "'");
      }
      const scenes::Scene* scene = chosen.front();
      scenes::Run r = cli::make_run_or_usage_error(*scene, sim_overrides);
      const double seconds = sim_seconds.value_or(scene->default_seconds);
      // Steps on stderr, only once the run has taken 2 s (short runs and --json stay clean).
      cli::Progress progress("simulate " + sim_scene,
                             std::llround(seconds / r.world.def().dt), "steps", 2.0);
      r.metrics = std::make_unique<ProgressMetrics>(std::move(r.metrics), progress);
      const nlohmann::json summary = cli::simulate(*scene, r, seconds);
      progress.finish();
      if (sim_json) {
        std::cout << summary.dump(2) << "\n";
      } else {
        std::cout << scene->name << ": " << summary["steps"] << " steps, "
                  << summary["simulated_s"] << " s simulated in " << summary["wall_s"] << " s ("
                  << summary["us_per_step"] << " us/step)\nmetrics: " << summary["metrics"].dump()
                  << "\n";
      }
      return 0;
    }
    if (*bench) return cli::run_bench(bench_quick, bench_rendering);
    if (*report) {
      return run_report(report_scene, report_out, report_quick, report_list, report_merge,
                        report_run, argc, argv);
    }
#ifdef CPS_HAVE_RENDERER
    if (*render) {
      // Everything is checked before anything is written.
      const SizeWxH size = parse_size(size_text);
      const std::vector<const scenes::Scene*> selected = cli::select_scenes(render_scene);
      const std::vector<cli::Variant> variants = cli::compare_variants(compare, render_overrides);
      if (!compare.empty() && size.width < 32) {
        throw cli::UsageError("--size " + size_text + ": --compare needs a width of at least 32");
      }
      struct Job {
        const scenes::Scene* scene;
        std::vector<scenes::Run> runs;
      };
      std::vector<Job> jobs;
      for (const scenes::Scene* s : selected) {
        Job job{s, {}};
        for (const cli::Variant& v : variants) {
          job.runs.push_back(cli::make_run_or_usage_error(*s, v.overrides));
        }
        jobs.push_back(std::move(job));
      }
      // Every output folder is checked (foreign files, see output.h) before any is written.
      std::vector<cli::RenderJob> specs;
      std::vector<cli::OutputPlan> plans;
      for (Job& job : jobs) {
        cli::RenderJob spec;
        spec.seconds = render_seconds.value_or(job.scene->default_seconds);
        spec.fps = fps;
        spec.folder = std::filesystem::path(out_dir) /
                      (std::string(job.scene->name) + (compare.empty() ? "" : "-compare-" + compare));
        std::vector<std::string> files;
        for (int k = 0; k < cli::frame_count(spec); ++k) files.push_back(cli::frame_name(k));
        plans.push_back(cli::plan_output(spec.folder, std::move(files), render_force));
        specs.push_back(spec);
      }
      const int panel_width = size.width / static_cast<int>(variants.size());
      render::Renderer renderer(panel_width, size.height);
      // Encoding overlaps drawing: one encoder thread keeps up with llvmpipe (see cps bench).
      render::PngWriter writer(1, 3);
      for (std::size_t j = 0; j < jobs.size(); ++j) {
        Job& job = jobs[j];
        const cli::RenderJob& spec = specs[j];
        std::vector<cli::Panel> panels;
        nlohmann::json world = nlohmann::json::array();
        for (std::size_t v = 0; v < variants.size(); ++v) {
          panels.push_back({&job.runs[v], variants[v].label});
          world.push_back({{"label", variants[v].label},
                           {"overrides", cli::overrides_json(variants[v].overrides)},
                           {"parameters", cli::parameters_json(job.runs[v].world.def())}});
        }
        const nlohmann::json info = cli::run_info(
            "render", argc, argv,
            {{"scene", job.scene->name},
             {"seconds", spec.seconds},
             {"fps", spec.fps},
             {"frames", cli::frame_count(spec)},
             {"size", {{"width", size.width}, {"height", size.height}}},
             {"compare", compare.empty() ? nlohmann::json(nullptr) : nlohmann::json(compare)},
             {"overrides", cli::overrides_json(render_overrides)},
             {"world", world}});
        cli::begin_output(plans[j], info);
        cli::Progress progress("render " + spec.folder.filename().string(), cli::frame_count(spec),
                               "frames");
        const int frames = cli::render_frames(*job.scene, panels, spec, renderer, writer, &progress);
        cli::end_output(plans[j], info);
        std::printf("%s: %d frames in %s\n", spec.folder.filename().c_str(), frames,
                    spec.folder.c_str());
      }
      return 0;
    }
#endif
  } catch (const cli::UsageError& e) {
    std::cerr << "cps: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "cps: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return run(argc, argv); }
