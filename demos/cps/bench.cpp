// `cps bench`: microseconds per physics step (explicit and matrix-free side by side), the cost
// growth with body count, and milliseconds per rendered frame.
#include "command.h"
#include "scene.h"

#ifdef CPS_HAVE_RENDERER
#include "atomic_file.h"
#include "draw.h"
#include "render.h"

#include "cps/render/renderer.h"
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <time.h>
#include <unistd.h>

namespace cps::cli {
namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// CPU time of the calling thread (s): the physics runs on this one thread, so time the machine
// gives to other processes (this one is shared) does not count against it, as wall time would.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Time and work per step of a scene: microseconds (thread CPU time) and constraint rows.
struct StepCost {
  double us = 0.0;    ///< median block's microseconds per step
  double rows = 0.0;  ///< rows per step over the timed blocks (contact, friction, distance)
};

// The cost of `scene` with this assembly: the world is first advanced 1 s into the scene
// (untimed, so contacts have formed), then stepped in 5 timed blocks of `steps`; the median
// block's thread CPU time per step counts.
StepCost step_cost(const scenes::Scene& scene, Assembly assembly, int steps) {
  scenes::Run run = scenes::make_run(scene);
  WorldDef def = run.world.def();
  def.assembly = assembly;
  run.world.set_def(def);
  while (run.world.time() < 1.0) run.world.step();
  std::vector<double> blocks;
  const std::int64_t rows_before = run.world.counters().rows;
  for (int b = 0; b < 5; ++b) {
    const double start = thread_cpu_seconds();
    for (int k = 0; k < steps; ++k) run.world.step();
    blocks.push_back(1e6 * (thread_cpu_seconds() - start) / steps);
  }
  return {median(blocks),
          static_cast<double>(run.world.counters().rows - rows_before) / (5.0 * steps)};
}

double us_per_step(const scenes::Scene& scene, Assembly assembly, int steps) {
  return step_cost(scene, assembly, steps).us;
}

// Least-squares slope of log(time) against log(bodies).
double log_log_slope(const std::vector<std::pair<double, double>>& points) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& [x, y] : points) {
    sx += std::log(x);
    sy += std::log(y);
    sxx += std::log(x) * std::log(x);
    sxy += std::log(x) * std::log(y);
  }
  const double n = static_cast<double>(points.size());
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

#ifdef CPS_HAVE_RENDERER
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The rendering table: per paper scene at 1280x720 over its first second at 30 fps.
//  - Stages, one at a time on this thread: milliseconds per frame of physics, draw (including
//    the readback) and PNG encode + atomic write, each the median over the frames.
//  - "physics + draw": the real loop without the PNG files (advance, draw, drop the image), and
//    "end to end": the real pipeline (render_frames: physics and drawing on this thread, PNG
//    encoding on the writer's thread, until the last file is written); each is the total time /
//    frames of one run, median of `repeats` runs taken in turn (physics + draw, end to end, ...)
//    so that a change in the machine's load hits both alike.
// The renderer first draws the scene's first frame once, untimed: llvmpipe compiles its shader
// variants for a new state on first use (tens of milliseconds), which would otherwise land in
// whichever measurement came first.
void render_table(bool quick) {
  constexpr int k_width = 1280;
  constexpr int k_height = 720;
  constexpr double k_fps = 30.0;
  constexpr double k_seconds = 1.0;
  constexpr float k_aspect = static_cast<float>(k_width) / k_height;
  const int repeats = quick ? 1 : 3;
  std::printf("\n## Rendering at %dx%d: milliseconds per frame (first %.0f s at %.0f fps; stages "
              "one at a time: median over the frames; physics + draw (no PNG) and end to end "
              "(PNG written on a second thread): total / frames, median of %d run%s)\n\n"
              "| scene | physics | draw | PNG encode + write | PNG KiB | physics + draw | "
              "end to end | end to end / (physics + draw) |\n|---|---|---|---|---|---|---|---|\n",
              k_width, k_height, k_seconds, k_fps, repeats, repeats > 1 ? "s" : "");
  render::Renderer renderer(k_width, k_height);
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("cps_bench_frames_" + std::to_string(getpid()));
  std::filesystem::create_directories(folder);
  RenderJob job;
  job.seconds = k_seconds;
  job.fps = k_fps;
  job.folder = folder;
  const int frames = static_cast<int>(frame_count(job));  // a few dozen
  for (const scenes::Scene& scene : scenes::paper_scenes()) {
    std::fprintf(stderr, "bench: rendering %s\n", std::string(scene.name).c_str());
    {  // Warm-up (untimed).
      scenes::Run run = scenes::make_run(scene);
      renderer.draw(draw_list(run.world, resolve_style(scene, run.world, View{}, k_aspect)));
    }
    // Stages, one at a time.
    std::vector<double> physics, draw, encode;
    double bytes = 0.0;
    {
      scenes::Run run = scenes::make_run(scene);
      const DrawStyle style = resolve_style(scene, run.world, View{}, k_aspect);
      for (int k = 0; k < frames; ++k) {
        auto start = Clock::now();
        run.advance_to(static_cast<double>(k) / k_fps);
        physics.push_back(1e3 * seconds_since(start));
        start = Clock::now();
        const render::Image image = renderer.draw(draw_list(run.world, style));
        draw.push_back(1e3 * seconds_since(start));
        start = Clock::now();
        write_file_atomic(folder / "frame.png", render::encode_png(image));
        encode.push_back(1e3 * seconds_since(start));
        bytes += static_cast<double>(std::filesystem::file_size(folder / "frame.png"));
      }
    }
    // The loop without PNG files, then the real pipeline, in turn.
    std::vector<double> alone, end_to_end;
    for (int r = 0; r < repeats; ++r) {
      {
        scenes::Run run = scenes::make_run(scene);
        const DrawStyle style = resolve_style(scene, run.world, View{}, k_aspect);
        const auto start = Clock::now();
        for (int k = 0; k < frames; ++k) {
          run.advance_to(static_cast<double>(k) / k_fps);
          const render::Image image = renderer.draw(draw_list(run.world, style));
        }
        alone.push_back(1e3 * seconds_since(start) / frames);
      }
      {
        scenes::Run run = scenes::make_run(scene);
        std::vector<Panel> panels{{&run, ""}};
        const DrawStyle style = resolve_style(scene, run.world, View{}, k_aspect);
        render::PngWriter writer(
            [](const std::filesystem::path& path, std::span<const std::uint8_t> png) {
              write_file_atomic(path, png);
            },
            1, 3);
        const auto start = Clock::now();
        render_frames(style, panels, job, renderer, writer, nullptr);
        end_to_end.push_back(1e3 * seconds_since(start) / frames);
      }
    }
    const double a = median(alone);
    const double e = median(end_to_end);
    std::printf("| %s | %.1f | %.1f | %.1f | %.0f | %.1f | %.1f | %.2f |\n",
                std::string(scene.name).c_str(), median(physics), median(draw), median(encode),
                bytes / frames / 1024.0, a, e, e / a);
    std::fflush(stdout);
  }
  std::filesystem::remove_all(folder);
}
#endif

// The options of `cps bench`.
struct BenchOptions {
  bool quick = false;
  bool rendering = false;  // only the rendering table
};

// The tables, as Markdown on stdout; progress on stderr. quick: fewer and smaller scenes (seconds
// instead of minutes), one end-to-end rendering run per scene instead of three. rendering_only:
// only the rendering table. Returns the exit code (2 for rendering_only in a build without the
// renderer).
int run_bench(bool quick, bool rendering_only) {
#ifdef CPS_HAVE_RENDERER
  if (rendering_only) {
    render_table(quick);
    return 0;
  }
#else
  if (rendering_only) {
    std::fprintf(stderr, "cps bench: built without the renderer (CPS_BUILD_RENDERER=OFF)\n");
    return 2;
  }
#endif
  std::printf("## Physics: microseconds per step (one thread; its CPU time, median of 5 blocks)\n\n"
              "| scene | bodies | explicit (us/step) | matrix-free (us/step) | speed-up |\n"
              "|---|---|---|---|---|\n");
  std::vector<std::string> names;
  for (const scenes::Scene& s : scenes::paper_scenes()) names.emplace_back(s.name);
  for (const char* s : {"stack_40", "pyramid_100", "funnel_100", "pendulum_grid_10",
                        "pendulum_wave_1000"}) {
    names.emplace_back(s);
  }
  if (!quick) {
    for (const char* s : {"pyramid_1000", "funnel_2000", "pendulum_wave_10000"}) names.emplace_back(s);
  }
  for (const std::string& name : names) {
    const scenes::Scene& scene = *scenes::find_scene(name);
    const int steps = quick ? 12 : 36;  // 5 blocks: 3 s of a 60 Hz scene (1 s quick)
    std::fprintf(stderr, "bench: %s\n", name.c_str());
    const double e = us_per_step(scene, Assembly::explicit_matrices, steps);
    const double m = us_per_step(scene, Assembly::matrix_free, steps);
    const std::size_t bodies = scenes::make_run(scene).world.bodies().size();
    std::printf("| %s | %zu | %.1f | %.1f | %.2fx |\n", name.c_str(), bodies, e, m, e / m);
  }

  std::printf("\n## Cost growth (matrix-free): log-log slope of time per step against bodies\n\n"
              "Also against the rows per step: a larger pile has more contacts per body (fewer "
              "bodies on its edges), so part of the growth is more work per body.\n\n"
              "| family | bodies: us/step (rows/step) | slope against bodies | slope against rows |\n"
              "|---|---|---|---|\n");
  const std::vector<int> sizes = quick ? std::vector<int>{100, 300, 1000}
                                       : std::vector<int>{100, 300, 1000, 3000, 5000};
  for (const char* family : {"pyramid", "funnel"}) {
    std::vector<std::pair<double, double>> by_bodies;
    std::vector<std::pair<double, double>> by_rows;
    std::string cells;
    for (const int n : sizes) {
      const std::string name = std::string(family) + "_" + std::to_string(n);
      std::fprintf(stderr, "bench: %s\n", name.c_str());
      const scenes::Scene& scene = *scenes::find_scene(name);
      const double bodies = static_cast<double>(scenes::make_run(scene).world.bodies().size());
      const StepCost cost = step_cost(scene, Assembly::matrix_free, quick ? 3 : 6);
      by_bodies.emplace_back(bodies, cost.us);
      by_rows.emplace_back(std::max(cost.rows, 1.0), cost.us);
      char cell[96];
      std::snprintf(cell, sizeof cell, "%s%.0f: %.0f (%.0f)", cells.empty() ? "" : ", ", bodies,
                    cost.us, cost.rows);
      cells += cell;
    }
    std::printf("| %s_N | %s | %.2f | %.2f |\n", family, cells.c_str(), log_log_slope(by_bodies),
                log_log_slope(by_rows));
  }

#ifdef CPS_HAVE_RENDERER
  render_table(quick);
#endif
  return 0;
}

}  // namespace

Command add_bench(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* sub = app.add_subcommand(
      "bench", "microseconds per step (explicit and matrix-free), cost growth, ms per frame");
  sub->add_flag("--quick", o->quick, "smaller scenes and fewer steps (results in us/step, ms/frame)");
  sub->add_flag("--rendering", o->rendering,
                "only the rendering table (ms per frame at 1280x720: draw, PNG, end to end)");
  return {sub, [o] { return run_bench(o->quick, o->rendering); }};
}

}  // namespace cps::cli
