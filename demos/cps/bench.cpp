#include "bench.h"

#include "scene.h"

#ifdef CPS_HAVE_RENDERER
#include "draw.h"

#include "cps/render/renderer.h"
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace cps::cli {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Microseconds per step of `scene` with this assembly: the world is first advanced 1 s into
// the scene (untimed, so contacts have formed), then stepped in 3 timed blocks of `steps`;
// the median block counts.
double us_per_step(const scenes::Scene& scene, Assembly assembly, int steps) {
  scenes::Run run = scenes::make_run(scene);
  WorldDef def = run.world.def();
  def.assembly = assembly;
  run.world.set_def(def);
  while (run.world.time() < 1.0) run.world.step();
  std::vector<double> blocks;
  for (int b = 0; b < 3; ++b) {
    const auto start = Clock::now();
    for (int k = 0; k < steps; ++k) run.world.step();
    blocks.push_back(1e6 * seconds_since(start) / steps);
  }
  return median(blocks);
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

}  // namespace

int run_bench(bool quick) {
  std::printf("## Physics: microseconds per step (one thread)\n\n"
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
    const int steps = quick ? 20 : 60;
    std::fprintf(stderr, "bench: %s\n", name.c_str());
    const double e = us_per_step(scene, Assembly::explicit_matrices, steps);
    const double m = us_per_step(scene, Assembly::matrix_free, steps);
    const std::size_t bodies = scenes::make_run(scene).world.bodies().size();
    std::printf("| %s | %zu | %.1f | %.1f | %.2fx |\n", name.c_str(), bodies, e, m, e / m);
  }

  std::printf("\n## Cost growth (matrix-free): log-log slope of time per step against bodies\n\n"
              "| family | bodies: us/step | slope |\n|---|---|---|\n");
  const std::vector<int> sizes = quick ? std::vector<int>{100, 300, 1000}
                                       : std::vector<int>{100, 300, 1000, 3000, 5000};
  for (const char* family : {"pyramid", "funnel"}) {
    std::vector<std::pair<double, double>> points;
    std::string cells;
    for (const int n : sizes) {
      const std::string name = std::string(family) + "_" + std::to_string(n);
      std::fprintf(stderr, "bench: %s\n", name.c_str());
      const scenes::Scene& scene = *scenes::find_scene(name);
      const double bodies = static_cast<double>(scenes::make_run(scene).world.bodies().size());
      const double t = us_per_step(scene, Assembly::matrix_free, quick ? 5 : 10);
      points.emplace_back(bodies, t);
      char cell[64];
      std::snprintf(cell, sizeof cell, "%s%.0f: %.0f", cells.empty() ? "" : ", ", bodies, t);
      cells += cell;
    }
    std::printf("| %s_N | %s | %.2f |\n", family, cells.c_str(), log_log_slope(points));
  }

#ifdef CPS_HAVE_RENDERER
  std::printf("\n## Rendering at 1280x720: milliseconds per frame (median of 10)\n\n"
              "| scene | draw | PNG encode and write | end to end |\n|---|---|---|---|\n");
  render::Renderer renderer(1280, 720);
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "cps_bench_frames";
  std::filesystem::create_directories(folder);
  for (const scenes::Scene& scene : scenes::paper_scenes()) {
    std::fprintf(stderr, "bench: rendering %s\n", std::string(scene.name).c_str());
    scenes::Run run = scenes::make_run(scene);
    DrawStyle style{frame_world(run.world, 1280.0f / 720.0f), static_cast<float>(scene.plane_opacity)};
    if (scene.camera) style.camera = camera_from_preset(*scene.camera);
    run.advance_to(1.0);
    std::vector<double> draw, encode, total;
    for (int k = 0; k < 10; ++k) {
      const auto start = Clock::now();
      const render::Image image = renderer.draw(draw_list(run.world, style));
      const double d = seconds_since(start);
      const auto start_png = Clock::now();
      render::write_png(folder / "frame.png", image);
      encode.push_back(1e3 * seconds_since(start_png));
      draw.push_back(1e3 * d);
      total.push_back(1e3 * seconds_since(start));
    }
    std::printf("| %s | %.1f | %.1f | %.1f |\n", std::string(scene.name).c_str(), median(draw),
                median(encode), median(total));
  }
  std::filesystem::remove_all(folder);
#endif
  return 0;
}

}  // namespace cps::cli
