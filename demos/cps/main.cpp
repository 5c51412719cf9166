// The cps command: list the scenes, simulate them headless, render them to PNG frames.
#include "options.h"
#include "simulate.h"
#include "state_hash.h"

#include "bench.h"
#include "output.h"
#include "progress.h"
#include "report.h"

#ifdef CPS_HAVE_RENDERER
#include "draw.h"
#include "figure.h"
#include "render.h"
#include "video.h"
#endif

#include <chrono>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <sstream>
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

#ifdef CPS_HAVE_RENDERER
// The overlay and camera flags shared by render and figure.
struct ViewFlags {
  cli::Overlays overlays;
  bool label = false;
  std::string camera = "preset";
};

void add_view_options(CLI::App& cmd, ViewFlags& v, bool label_default) {
  v.label = label_default;
  cmd.add_flag("--contacts", v.overlays.contacts,
               "draw the last step's contact points (red spheres) and normals (red segments, about "
               "one body size long (m), from body a towards body b); default: off");
  cmd.add_flag("--rods,!--no-rods", v.overlays.rods,
               "draw distance constraints as rods; default: on (--no-rods hides them)");
  cmd.add_flag("--label,!--no-label", v.label,
               std::string("write scene, variant and time (s) on each picture; default: ") +
                   (label_default ? "on (--no-label leaves the pictures bare)" : "off (variants of --compare are always labelled)"));
  std::string names;
  for (std::string_view n : cli::camera_names()) names += (names.empty() ? "" : ", ") + std::string(n);
  cmd.add_option("--camera", v.camera,
                 "view: preset (the scene's own), auto (framed on the bodies as built), front, side "
                 "or top (the preset's target from the same distance)")
      ->capture_default_str()
      ->check(CLI::IsMember(std::vector<std::string>(cli::camera_names().begin(),
                                                     cli::camera_names().end())));
  cmd.add_option("--orbit", v.overlays.orbit_deg_per_s,
                 "turn the camera about the vertical axis through its target (degrees per "
                 "simulated second; 0 = fixed, typical 10)")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& input) -> std::string {
            double value = 0.0;
            std::istringstream in(input);
            if (!(in >> value) || !in.eof() || !std::isfinite(value) || std::abs(value) > 36000.0) {
              return "--orbit " + input + ": give a finite rate in degrees per second, |rate| <= 36000";
            }
            return {};
          },
          "DEG/S"));
}
#endif

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

#ifdef CPS_HAVE_RENDERER
// `cps figure`: everything is checked (scene, times, size, variants, output ownership) before
// anything is rendered or written.
int run_figure(int argc, char** argv, const std::string& scene_name, const std::string& times_text,
               const std::string& compare, const std::string& size_text, const std::string& out,
               bool force, const scenes::Overrides& overrides, const ViewFlags& view) {
  namespace fs = std::filesystem;
  const SizeWxH size = parse_size(size_text);
  struct Planned {
    cli::FigureSpec spec;
    fs::path png;
  };
  std::vector<Planned> plan;
  const auto base_spec = [&](const scenes::Scene* scene) {
    cli::FigureSpec spec;
    spec.scene = scene;
    spec.panel_width = size.width;
    spec.panel_height = size.height;
    spec.camera = view.camera;
    spec.overlays = view.overlays;
    spec.label = view.label;
    return spec;
  };
  if (scene_name == "paper") {
    if (!times_text.empty() || !compare.empty()) {
      throw cli::UsageError("cps figure paper chooses its own --times and --compare for each "
                            "figure; drop them, or name a scene (e.g. cps figure "
                            "intersecting_stack --times 0,0.5 --compare push)");
    }
    const fs::path folder = out.empty() ? fs::path("out/figures") : fs::path(out);
    for (const cli::PaperFigure& f : cli::paper_figures()) {
      cli::FigureSpec spec = base_spec(cli::select_scenes(f.scene).front());
      spec.times = f.times;
      spec.compare = f.compare;
      spec.variants = cli::compare_variants(f.compare, overrides);
      spec.caption = f.caption + " counterpart";
      spec.tags = f.tags;
      spec.preset = f.preset;
      spec.what = f.what;
      plan.push_back({spec, folder / f.file});
    }
  } else {
    const std::vector<const scenes::Scene*> chosen = cli::select_scenes(scene_name);
    if (scene_name == "all" || scene_name == "stress") {
      throw cli::UsageError("figure takes one scene or 'paper', not '" + scene_name + "'");
    }
    if (times_text.empty()) {
      throw cli::UsageError("--times is required: the simulated times (s) of the columns, e.g. "
                            "--times 0,0.5,2");
    }
    cli::FigureSpec spec = base_spec(chosen.front());
    spec.times = cli::parse_times(times_text);
    spec.compare = compare;
    spec.variants = cli::compare_variants(compare, overrides);
    const fs::path png = out.empty() ? fs::path("out/figures") /
                                           (scene_name + (compare.empty() ? "" : "-compare-" + compare) + ".png")
                                     : fs::path(out);
    if (png.extension() != ".png") {
      throw cli::UsageError("--out " + png.string() + ": the figure is a PNG; give a name ending in .png");
    }
    plan.push_back({spec, png});
  }
  for (Planned& p : plan) {
    for (const cli::Variant& v : p.spec.variants) cli::make_run_or_usage_error(*p.spec.scene, v.overrides);
    const long long w = static_cast<long long>(p.spec.times.size()) * size.width;
    const long long h = static_cast<long long>(p.spec.variants.size()) * size.height;
    if (w > 16384 || h > 16384) {
      throw cli::UsageError("the figure would be " + std::to_string(w) + "x" + std::to_string(h) +
                            " pixels (more than 16384 on a side); give fewer --times or a "
                            "smaller --size");
    }
    cli::check_output_is_ours(p.png, force);
  }
  render::Renderer renderer(size.width, size.height);
  for (Planned& p : plan) {
    const render::Image image = cli::render_figure(p.spec, renderer);
    cli::write_figure(p.png, image, cli::figure_json(p.spec, argc, argv));
    std::printf("%s: %dx%d pixels, %zu times x %zu variants (%s)\n", p.png.c_str(), image.width,
                image.height, p.spec.times.size(), p.spec.variants.size(),
                cli::sidecar_path(p.png).filename().c_str());
  }
  return 0;
}
#endif

int run(int argc, char** argv) {
  CLI::App app{"cps: the constraint based physics solver of Tamis & Maggiore (2015)"};
  app.require_subcommand(1);

  CLI::App* list = app.add_subcommand(
      "list", "print the scenes with their default duration (s) and a summary");

  std::string sim_scene;
  std::optional<double> sim_seconds;
  bool sim_json = false;
  std::string sim_trace;
  bool sim_force = false;
  std::string sim_expect_hash;
  scenes::Overrides sim_overrides;
  CLI::App* simulate = app.add_subcommand("simulate", "run a scene headless and report metrics");
  simulate->add_option("scene", sim_scene, "scene name (see 'cps list')")->required();
  simulate->add_option("--seconds", sim_seconds, "simulated time (s), > 0; default: the scene's")
      ->check(cli::kFinitePositive);
  simulate->add_flag("--json", sim_json, "print one JSON object (keys carry their unit: _s, _m, ...)");
  simulate->add_option("--trace", sim_trace,
                       "write every body's state per step to this CSV: step, t (s), body index, "
                       "position (m), orientation quaternion w x y z, velocity (m/s), angular "
                       "velocity (rad/s); one row per body per step, step 0 = as built");
  simulate->add_flag("--force", sim_force,
                     "let --trace replace an existing file that is not a cps trace (a file whose "
                     "first line is the cps trace header is replaced without it)");
  simulate->add_option("--expect-hash", sim_expect_hash,
                       "the state_hash (16 hex digits) the run must end with: if the run ends in "
                       "another state, print both hashes and exit 1 (a CI check that the physics "
                       "did not change)");
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
  bench->add_flag("--quick", bench_quick, "smaller scenes and fewer steps (results in us/step, ms/frame)");
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
      ->check(CLI::IsMember(cli::comparable_options()));
  bool render_force = false;
  render->add_flag("--force", render_force,
                   "write into an output folder that holds files no earlier cps run wrote there "
                   "(they are kept; same-named files are replaced)");
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
  ViewFlags render_view;
  add_view_options(*render, render_view, /*label_default=*/false);

  std::string fig_scene;
  std::string fig_times_text;
  std::string fig_compare;
  std::string fig_size_text = "640x360";
  std::string fig_out;
  bool fig_force = false;
  scenes::Overrides fig_overrides;
  ViewFlags fig_view;
  CLI::App* figure = app.add_subcommand(
      "figure",
      "one labelled PNG of a scene: a panel per time (columns) and per variant (rows); "
      "'cps figure paper' writes the counterparts of the paper's Figs. 6-10");
  figure->add_option("scene", fig_scene, "scene name (see 'cps list') or 'paper'")->required();
  figure->add_option("--times", fig_times_text,
                     "simulated times of the columns (s), comma separated, finite, >= 0, "
                     "increasing, e.g. 0,0.5,2; required except for 'paper'");
  figure->add_option("--compare", fig_compare,
                     "one row per value of this option (default: one row, the scene's settings)")
      ->check(CLI::IsMember(cli::comparable_options()));
  figure->add_option("--size", fig_size_text, "size of ONE panel, WxH in pixels, each in [16, 8192]")
      ->capture_default_str();
  figure->add_option("--out", fig_out,
                     "output PNG (default out/figures/SCENE[-compare-OPTION].png); for 'paper', "
                     "the folder (default out/figures); a FILE.json sidecar records the run");
  figure->add_flag("--force", fig_force,
                   "replace an output file that cps figure did not write (one without its sidecar)");
  cli::add_world_options(*figure, fig_overrides);
  add_view_options(*figure, fig_view, /*label_default=*/true);
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
      std::optional<std::uint64_t> expected_hash;
      if (!sim_expect_hash.empty()) {
        expected_hash = scenes::parse_hash(sim_expect_hash);
        if (!expected_hash) {
          throw cli::UsageError("--expect-hash " + sim_expect_hash +
                                ": give the 16 hex digits of a state_hash, as simulate --json "
                                "prints it (e.g. 0123456789abcdef)");
        }
      }
      scenes::Run r = cli::make_run_or_usage_error(*scene, sim_overrides);
      const double seconds = sim_seconds.value_or(scene->default_seconds);
      std::optional<cli::TraceWriter> trace;
      if (!sim_trace.empty()) trace.emplace(sim_trace, sim_force);
      // Steps on stderr, only once the run has taken 2 s (short runs and --json stay clean).
      cli::Progress progress("simulate " + sim_scene,
                             std::llround(seconds / r.world.def().dt), "steps", 2.0);
      r.metrics = std::make_unique<ProgressMetrics>(std::move(r.metrics), progress);
      const nlohmann::json summary =
          cli::simulate(*scene, r, seconds, trace ? &*trace : nullptr);
      progress.finish();
      if (trace) {
        const long rows = trace->finish();
        std::cerr << "trace: " << rows << " rows (" << r.world.bodies().size()
                  << " bodies per step) in " << sim_trace << "\n";
      }
      if (sim_json) {
        std::cout << summary.dump(2) << "\n";
      } else {
        std::cout << scene->name << ": " << summary["steps"] << " steps, "
                  << summary["simulated_s"] << " s simulated in " << summary["wall_s"] << " s ("
                  << summary["us_per_step"] << " us/step)\nmetrics: " << summary["metrics"].dump()
                  << "\nstate hash: " << std::string(summary["state_hash"]) << "\n";
      }
      if (expected_hash) {
        const std::string got = summary["state_hash"];
        if (got != scenes::format_hash(*expected_hash)) {
          std::cerr << "cps: state hash " << got << " differs from the expected "
                    << scenes::format_hash(*expected_hash) << " (--expect-hash): the run ended in "
                    << "another state\n";
          return 1;
        }
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
      const float aspect = static_cast<float>(panel_width) / static_cast<float>(size.height);
      // The camera flag reaches render.cpp as the scene's preset, the overlays in the RenderJob.
      std::vector<scenes::Scene> viewed;  // the scenes with the chosen camera as their preset
      viewed.reserve(jobs.size());
      for (Job& job : jobs) {
        viewed.push_back(*job.scene);
        try {
          viewed.back().camera = cli::camera_preset(*job.scene, job.runs.front().world,
                                                    render_view.camera, aspect);
        } catch (const std::invalid_argument& e) {
          throw cli::UsageError(e.what());
        }
        job.scene = &viewed.back();
      }
      // Every output folder is checked (foreign files, see output.h) before any is written.
      std::vector<cli::RenderJob> specs;
      std::vector<cli::OutputPlan> plans;
      for (Job& job : jobs) {
        cli::RenderJob spec;
        spec.seconds = render_seconds.value_or(job.scene->default_seconds);
        spec.fps = fps;
        spec.overlays = render_view.overlays;
        spec.folder = std::filesystem::path(out_dir) /
                      (std::string(job.scene->name) + (compare.empty() ? "" : "-compare-" + compare));
        std::vector<std::string> files;
        for (int k = 0; k < cli::frame_count(spec); ++k) files.push_back(cli::frame_name(k));
        plans.push_back(cli::plan_output(spec.folder, std::move(files), render_force));
        specs.push_back(spec);
      }
      render::Renderer renderer(panel_width, size.height,
                                *render::parse_backend(render_backend));
      std::fprintf(stderr, "render: %s\n", renderer.context_description().c_str());
      // Encoding overlaps drawing: one encoder thread keeps up with llvmpipe (see cps bench).
      render::PngWriter writer(1, 3);
      for (std::size_t j = 0; j < jobs.size(); ++j) {
        Job& job = jobs[j];
        const cli::RenderJob& spec = specs[j];
        std::vector<cli::Panel> panels;
        nlohmann::json world = nlohmann::json::array();
        for (std::size_t v = 0; v < variants.size(); ++v) {
          std::string label = variants[v].label;
          if (render_view.label) {
            label = std::string(job.scene->name) + (label.empty() ? "" : "\n" + label);
          }
          panels.push_back({&job.runs[v], label});
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
             {"backend", render_backend},
             {"camera", render_view.camera},
             {"orbit_deg_per_s", render_view.overlays.orbit_deg_per_s},
             {"contacts", render_view.overlays.contacts},
             {"rods", render_view.overlays.rods},
             {"label", render_view.label},
             {"overrides", cli::overrides_json(render_overrides)},
             {"world", world}});
        cli::begin_output(plans[j], info);
        cli::Progress progress("render " + spec.folder.filename().string(), cli::frame_count(spec),
                               "frames");
        const int frames = cli::render_frames(*job.scene, panels, spec, renderer, writer, &progress);
        cli::end_output(plans[j], info);
        const std::string folder = spec.folder.filename().string();
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
    if (*figure) return run_figure(argc, argv, fig_scene, fig_times_text, fig_compare,
                                   fig_size_text, fig_out, fig_force, fig_overrides, fig_view);
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
