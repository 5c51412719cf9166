// The cps command: list the scenes, simulate them headless, render them to PNG frames.
#include "options.h"
#include "simulate.h"

#include "bench.h"
#include "report.h"

#ifdef CPS_HAVE_RENDERER
#include "render.h"
#include "video.h"
#endif

#include <chrono>
#include <unistd.h>

#include <cstdio>
#include <iostream>
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

// The absolute path of this executable, for commands that must run anywhere.
std::string self_path() {
  char path[4096];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return "cps";
  path[n] = '\0';
  return path;
}

int run_report(const std::string& scene_name, const std::string& out, bool quick, bool list,
               const std::vector<std::string>& merge, const std::string& one_run) {
  namespace fs = std::filesystem;
  const int repeats = quick ? 1 : 3;
  if (!merge.empty()) {
    std::vector<fs::path> dirs(merge.begin(), merge.end());
    const std::vector<cli::Row> rows = cli::read_rows(dirs);
    if (rows.empty()) throw cli::UsageError("--merge: no report CSV found below the given folders");
    cli::write_report(out, rows);
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
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < runs.size(); ++i) {
    rows.push_back(cli::execute_run(runs[i], repeats));
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double left = elapsed / static_cast<double>(i + 1) * static_cast<double>(runs.size() - i - 1);
    std::fprintf(stderr, "report: %zu/%zu %s (%.0f s elapsed, about %.0f s left)\n", i + 1,
                 runs.size(), runs[i].id().c_str(), elapsed, left);
  }
  cli::write_report(out, rows);
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
  cli::add_world_options(*render, render_overrides);
  std::string render_backend = "osmesa";
  render->add_option("--backend", render_backend,
                     "OpenGL context: osmesa (libOSMesa, CPU) or egl (headless EGL: GPU if any, "
                     "else llvmpipe)")
      ->capture_default_str()
      ->check(CLI::IsMember({"osmesa", "egl"}));
  std::string render_video;
  render->add_option("--video", render_video,
                     "after the frames, assemble them with ffmpeg into OUT/SCENE.mp4 (H.264) or "
                     "OUT/SCENE.gif")
      ->check(CLI::IsMember({"mp4", "gif"}));
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
      const nlohmann::json summary =
          cli::simulate(*scene, r, sim_seconds.value_or(scene->default_seconds));
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
    if (*bench) return cli::run_bench(bench_quick);
    if (*report) {
      return run_report(report_scene, report_out, report_quick, report_list, report_merge,
                        report_run);
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
      // --video: ffmpeg is looked for before rendering; without it the frames are still
      // rendered and kept, and the command ends with an error saying how to finish the video.
      std::optional<std::filesystem::path> ffmpeg;
      std::vector<cli::VideoJob> videos_left;
      if (!render_video.empty()) {
        ffmpeg = cli::find_on_path("ffmpeg");
        if (!ffmpeg) {
          std::fprintf(stderr,
                       "cps: warning: --video %s: ffmpeg is not on PATH; the frames will be "
                       "rendered and kept, but no video made (install it: apt-get install ffmpeg)\n",
                       render_video.c_str());
        }
      }
      const int panel_width = size.width / static_cast<int>(variants.size());
      render::Renderer renderer(panel_width, size.height,
                                *render::parse_backend(render_backend));
      std::fprintf(stderr, "render: %s\n", renderer.context_description().c_str());
      for (Job& job : jobs) {
        std::vector<cli::Panel> panels;
        for (std::size_t v = 0; v < variants.size(); ++v) {
          panels.push_back({&job.runs[v], variants[v].label});
        }
        cli::RenderJob spec;
        spec.seconds = render_seconds.value_or(job.scene->default_seconds);
        spec.fps = fps;
        const std::string folder = std::string(job.scene->name) +
                                   (compare.empty() ? "" : "-compare-" + compare);
        spec.folder = std::filesystem::path(out_dir) / folder;
        const int frames = cli::render_frames(*job.scene, panels, spec, renderer);
        std::printf("%s: %d frames in %s\n", folder.c_str(), frames, spec.folder.c_str());
        if (!render_video.empty()) {
          cli::VideoJob video;
          video.format = *cli::parse_video_format(render_video);
          video.frames_folder = spec.folder;
          video.frames = frames;
          video.fps = fps;
          video.width = panel_width * static_cast<int>(variants.size());
          video.height = size.height;
          video.output = std::filesystem::path(out_dir) / (folder + "." + render_video);
          if (!ffmpeg) {
            videos_left.push_back(video);
            continue;
          }
          cli::encode_video(*ffmpeg, video);
          std::printf("%s: video %s (%ju bytes)\n", folder.c_str(), video.output.c_str(),
                      static_cast<std::uintmax_t>(std::filesystem::file_size(video.output)));
        }
      }
      if (!videos_left.empty()) {
        std::string how;
        for (const cli::VideoJob& v : videos_left) {
          how += "\n  " + cli::shell_command(cli::ffmpeg_arguments("ffmpeg", v, v.output));
        }
        throw cli::VideoError("--video " + render_video +
                              ": ffmpeg is not on PATH, so no video was made; install it "
                              "(apt-get install ffmpeg). The frames are kept; to assemble them "
                              "without rendering again, run:" + how);
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
