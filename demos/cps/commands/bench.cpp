// `cps bench`: microseconds per physics step (explicit and matrix-free side by side) and where a
// step goes by stage, the cost of warm starting, the cost growth with body count, and
// milliseconds per rendered frame.
#include "command.h"
#include "options/diagnostics.h"
#include "options/options.h"
#include "output/output.h"
#include "report/timing.h"  // thread_cpu_seconds: a one-thread world steps on this thread
#include "scene.h"

#ifdef CPS_HAVE_RENDERER
#include "output/atomic_file.h"
#include "pictures/draw.h"
#include "commands/render.h"

#include "cps/render/renderer.h"
#endif

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <time.h>
#include <unistd.h>

namespace cps::cli {
namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Time and work per step of a scene over a window: microseconds (thread CPU time), constraint
// rows and contact points per step.
struct StepCost {
  double us = 0.0;        ///< median repeat's microseconds per step
  double rows = 0.0;      ///< rows per step in the window (contact, friction, distance)
  double contacts = 0.0;  ///< contact points per step in the window
  StageTimes stages;      ///< s per step by stage, from one more repeat with stage timing on
};

// The stages of StageTimes with their names in the tables and the JSON keys.
constexpr std::pair<const char*, double StageTimes::*> kStages[] = {
    {"collide", &StageTimes::collide}, {"rows", &StageTimes::rows},
    {"prepare", &StageTimes::prepare}, {"solve", &StageTimes::solve},
    {"relax", &StageTimes::relax},     {"integrate", &StageTimes::integrate},
    {"store", &StageTimes::store},     {"other", &StageTimes::other}};

// The world (the scene with `overrides`) is advanced, untimed, to one step before `start_s`
// (to 0 when the window starts the run); a copy of it is then stepped through the window once
// untimed and `repeats` times timed, each from a fresh copy of the same state, so every repeat
// times the same window. A copy's step buffers start empty (World's copy constructor), so each
// copy takes the step before the window untimed: that step allocates them (each with room for
// twice what it needs) and touches their pages, so the clock does not time their first
// allocation (Box3D's benchmark likewise times from its second step); a later step of the window
// may still grow one past that room. The median repeat's time per step counts: this thread's CPU
// time, or the wall-clock time when the world steps on more than one thread (WorldDef::threads).
// One more repeat, not in the median, runs with the engine's stage timing on
// (World::set_stage_timing) for the stages' shares of a step. start_s >= 0 (s); steps >= 1;
// repeats >= 1. warm_start, if set, replaces the scene's warm starting factor (dimensionless,
// [0, 1]) from the start.
StepCost step_cost(const scenes::Scene& scene, const scenes::Overrides& overrides,
                   Assembly assembly, double start_s, int steps, int repeats,
                   std::optional<double> warm_start = std::nullopt) {
  scenes::Run run = scenes::make_run(scene, overrides);
  WorldDef def = run.world.def();
  def.assembly = assembly;
  // The explicit column assembles J in double whatever --row-precision says (it packs no rows).
  if (assembly == Assembly::explicit_matrices) def.row_precision = RowPrecision::double_precision;
  if (warm_start) def.warm_start = *warm_start;
  run.world.set_def(def);
  while (scenes::short_of(run.world, start_s - def.dt)) run.world.step();
  const bool lead = scenes::short_of(run.world, start_s);  // one step short of the window
  const auto copy_at_start = [&] {
    World world = run.world;
    if (lead) world.step();
    return world;
  };
  StepCost cost;
  std::vector<double> times;
  const bool wall = def.threads > 1;
  const auto now = [wall] {
    return wall ? std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count()
                : thread_cpu_seconds();
  };
  for (int r = 0; r <= repeats; ++r) {
    World world = copy_at_start();
    const StepCounters before = world.counters();
    const double start = now();
    for (int k = 0; k < steps; ++k) world.step();
    const double us = 1e6 * (now() - start) / steps;
    if (r == 0) {  // the untimed warm-up repeat; the window's work is the same in every repeat
      cost.rows = static_cast<double>(world.counters().rows - before.rows) / steps;
      cost.contacts = static_cast<double>(world.counters().contacts - before.contacts) / steps;
      continue;
    }
    times.push_back(us);
  }
  cost.us = median(times);
  World world = copy_at_start();
  world.set_stage_timing(true);
  for (int k = 0; k < steps; ++k) world.step();
  cost.stages = world.stage_times();
  for (const auto& [name, stage] : kStages) cost.stages.*stage /= steps;
  return cost;
}

// Steps in a scene's bench window (at least 1); quick: the first third of it.
int window_steps(const scenes::Scene& scene, bool quick) {
  const double dt = scene.world_def().dt;
  const double seconds = quick ? scene.bench.seconds / 3.0 : scene.bench.seconds;
  return std::max(1, static_cast<int>(std::lround(seconds / dt)));
}

// Timed repeats of a window of `steps` steps (see physics_table): at least 5, and enough that
// the timed steps add up to 3 s of a 60 Hz scene (1 s quick).
int window_repeats(int steps, bool quick) {
  const int timed_steps = quick ? 60 : 180;
  return std::max(5, (timed_steps + steps - 1) / steps);
}

// Refuses (UsageError, check_work) a scene of the physics table (with `overrides`) whose stepping
// would pass max_work (body-iterations): for each of the two assemblies, the steps to the
// window's start, then the step before it and the window once untimed, `repeats` times timed and
// once by stage (step_cost).
void check_bench_work(const scenes::Scene& scene, const scenes::Overrides& overrides, bool quick,
                      double max_work) {
  const scenes::Run run = make_run_or_usage_error(scene, overrides);
  const WorldDef& def = run.world.def();
  const int steps = window_steps(scene, quick);
  const double per_assembly =
      std::round(scene.bench.start_s / def.dt) + (window_repeats(steps, quick) + 2.0) * (steps + 1.0);
  check_work("its steps (both assemblies, to the window, then from the step before it through it "
             "once untimed, at each timed repeat and once by stage)", run.world.bodies().size(), def,
             2.0 * per_assembly * def.dt, max_work, "time a shorter or smaller scene, or raise --max-work");
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
//  - Where the draw goes: the stages of Renderer::draw with stage timing on, median per stage.
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
// Returns one JSON object per scene (the keys name the units); prints the Markdown table when
// `markdown` is set.
nlohmann::json render_table(bool quick, bool markdown) {
  constexpr int k_width = 1280;
  constexpr int k_height = 720;
  constexpr double k_fps = 30.0;
  constexpr double k_seconds = 1.0;
  constexpr float k_aspect = static_cast<float>(k_width) / k_height;
  const int repeats = quick ? 1 : 3;
  if (markdown) {
    std::printf("\n## Rendering at %dx%d: milliseconds per frame (first %.0f s at %.0f fps; stages "
              "one at a time: median over the frames; physics + draw (no PNG) and end to end "
              "(PNG written on a second thread): total / frames, median of %d run%s)\n\n"
              "| scene | physics | draw | PNG encode + write | PNG KiB | physics + draw | "
              "end to end | end to end / (physics + draw) |\n|---|---|---|---|---|---|---|---|\n",
                k_width, k_height, k_seconds, k_fps, repeats, repeats > 1 ? "s" : "");
  }
  nlohmann::json rows = nlohmann::json::array();
  std::string breakdown;  // Markdown rows of the stage table
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
    notes() << "bench: rendering " << scene.name << "\n";
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
    // Where a frame's draw goes: the same frames with stage timing on (glFinish after each
    // stage), median per stage.
    std::vector<std::vector<double>> stage(8);
    {
      scenes::Run run = scenes::make_run(scene);
      const DrawStyle style = resolve_style(scene, run.world, View{}, k_aspect);
      renderer.set_stage_timing(true);
      for (int k = 0; k < frames; ++k) {
        run.advance_to(static_cast<double>(k) / k_fps);
        renderer.draw(draw_list(run.world, style));
        const render::StageTimes t = renderer.last_stage_times();
        const double v[8] = {t.plan,   t.upload,  t.shadow,  t.bodies,
                             t.planes, t.overlay, t.resolve, t.read_back};
        for (std::size_t i = 0; i < stage.size(); ++i) stage[i].push_back(v[i]);
      }
      renderer.set_stage_timing(false);
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
    rows.push_back({{"scene", scene.name},
                    {"width_px", k_width},
                    {"height_px", k_height},
                    {"frames", frames},
                    {"physics_ms", median(physics)},
                    {"draw_ms", median(draw)},
                    {"png_ms", median(encode)},
                    {"png_kib", bytes / frames / 1024.0},
                    {"physics_and_draw_ms", a},
                    {"end_to_end_ms", e},
                    {"stages_ms",
                     {{"plan", median(stage[0])},
                      {"upload", median(stage[1])},
                      {"shadow", median(stage[2])},
                      {"bodies", median(stage[3])},
                      {"planes", median(stage[4])},
                      {"lines_translucent_ghosts", median(stage[5])},
                      {"resolve", median(stage[6])},
                      {"read_back", median(stage[7])}}}});
    if (markdown) {
      std::printf("| %s | %.1f | %.1f | %.1f | %.0f | %.1f | %.1f | %.2f |\n",
                  std::string(scene.name).c_str(), median(physics), median(draw), median(encode),
                  bytes / frames / 1024.0, a, e, e / a);
      breakdown += "| " + std::string(scene.name);
      for (const std::vector<double>& v : stage) {
        char cell[32];
        std::snprintf(cell, sizeof cell, " | %.1f", median(v));
        breakdown += cell;
      }
      breakdown += " |\n";
      std::fflush(stdout);
    }
  }
  if (markdown) {
    std::printf("\nWhere the draw goes (ms per frame, median over the frames, each stage ended by "
                "glFinish: %s)\n\n| scene | plan | upload | shadow | bodies | planes | lines, "
                "translucent, ghosts | resolve | read-back |\n|---|---|---|---|---|---|---|---|---|\n%s",
                renderer.context_description().c_str(), breakdown.c_str());
  }
  std::filesystem::remove_all(folder);
  return rows;
}
#endif

// The stage times of a step (s per step) as JSON, in us per step.
nlohmann::json stages_json(const StageTimes& t) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [name, stage] : kStages) j[name] = 1e6 * (t.*stage);
  return j;
}

// The Markdown heading of a stage table, for runs of `assembly` (its words).
std::string stage_table_heading(const std::string& assembly) {
  std::string h = "Where a step goes (" + assembly +
                  ": us per step by stage, wall clock, one more repeat of the window with the "
                  "engine's stage timing on; the shares are of that repeat's total)\n\n| scene";
  for (const auto& [name, stage] : kStages) h += std::string(" | ") + name;
  h += " | total |\n|---";
  for (std::size_t k = 0; k <= std::size(kStages); ++k) h += "|---";
  return h + "|\n";
}

// One row of a stage table: us per step and share of the total per stage.
std::string stage_row(const std::string& scene, const StageTimes& t) {
  const double total = t.total();
  std::string row = "| " + scene;
  for (const auto& [name, stage] : kStages) {
    char cell[48];
    std::snprintf(cell, sizeof cell, " | %.1f (%.0f %%)", 1e6 * (t.*stage),
                  total > 0.0 ? 100.0 * (t.*stage) / total : 0.0);
    row += cell;
  }
  char cell[32];
  std::snprintf(cell, sizeof cell, " | %.1f |\n", 1e6 * total);
  return row + cell;
}

// The options of `cps bench`.
struct BenchOptions {
  bool quick = false;
  bool rendering = false;  // only the rendering table
  bool json = false;       // one JSON document on stdout instead of Markdown tables
  std::vector<std::string> scenes;  // only these scenes, physics table only (empty: every table)
  double max_work = kDefaultMaxWork;  // body-iterations a --scene may step
  scenes::Overrides overrides;      // world parameters of the --scene or --growth runs
  std::string growth;               // a scaled family: only its cost growth (empty: not asked)
  std::string sizes;                // --growth's sizes, comma-separated (empty: default_growth_sizes)
};

// The physics table's scenes: the paper's, then scaled ones (larger ones unless quick).
std::vector<std::string> physics_scenes(bool quick) {
  std::vector<std::string> names;
  for (const scenes::Scene& s : scenes::paper_scenes()) names.emplace_back(s.name);
  for (const char* s : {"stack_40", "pyramid_100", "funnel_100", "pendulum_grid_10",
                        "pendulum_wave_1000"}) {
    names.emplace_back(s);
  }
  if (!quick) {
    for (const char* s : {"pyramid_1000", "funnel_2000", "pendulum_wave_10000"}) names.emplace_back(s);
  }
  return names;
}

// The physics table: each scene of `names` (with `overrides`) over its bench window
// (Scene::bench), explicit and matrix-free.
nlohmann::json physics_table(const std::vector<std::string>& names,
                             const scenes::Overrides& overrides, bool quick, bool markdown) {
  // At least 5 repeats, and enough that the timed steps add up to 3 s of a 60 Hz scene (1 s
  // quick): a short window (the intersecting stack's 6 steps) is repeated more often.
  const int timed_steps = quick ? 60 : 180;
  const ParameterValue* threads_set = overrides.find("threads");
  const int threads = threads_set != nullptr && std::holds_alternative<int>(*threads_set)
                          ? std::get<int>(*threads_set)
                          : 1;
  if (markdown) {
    const std::string clock = threads > 1 ? std::to_string(threads) + " threads; wall-clock time"
                                          : std::string("one thread; its CPU time");
    std::printf("## Physics: microseconds per step (%s; median of the "
                "repeats of the scene's window, each from a copy of the state a step before it, that "
                "step untimed: at least 5 repeats and %d steps)\n\n"
                "| scene | bodies | window (s) | repeats | contacts/step | rows/step | explicit "
                "(us/step) | matrix-free (us/step) | speed-up |\n"
                "|---|---|---|---|---|---|---|---|---|\n",
                clock.c_str(), timed_steps);
  }
  nlohmann::json rows = nlohmann::json::array();
  std::string stage_rows;  // the stage table's Markdown rows
  for (const std::string& name : names) {
    const scenes::Scene& scene = *scenes::find_scene(name);
    const int steps = window_steps(scene, quick);
    const double dt = scene.world_def().dt;
    const double start = scene.bench.start_s;
    const int repeats = window_repeats(steps, quick);
    notes() << "bench: " << name << "\n";
    const StepCost e = step_cost(scene, overrides, Assembly::explicit_matrices, start, steps, repeats);
    const StepCost m = step_cost(scene, overrides, Assembly::matrix_free, start, steps, repeats);
    const std::size_t bodies = scenes::make_run(scene).world.bodies().size();
    const double end = start + steps * dt;
    rows.push_back({{"scene", name},
                    {"bodies", bodies},
                    {"window_start_s", start},
                    {"window_end_s", end},
                    {"window_reason", scene.bench.reason},
                    {"steps", steps},
                    {"repeats", repeats},
                    {"threads", scenes::world_def_with(scene, overrides).threads},
                    {"clock", scenes::world_def_with(scene, overrides).threads > 1 ? "wall" : "thread_cpu"},
                    {"contacts_per_step", m.contacts},
                    {"rows_per_step", m.rows},
                    {"explicit_us_per_step", e.us},
                    {"matrix_free_us_per_step", m.us},
                    {"matrix_free_stages_us_per_step", stages_json(m.stages)}});
    stage_rows += stage_row(name, m.stages);
    if (markdown) {
      std::printf("| %s | %zu | %.2f-%.2f | %d | %.1f | %.1f | %.1f | %.1f | %.2fx |\n",
                  name.c_str(), bodies, start, end, repeats, m.contacts, m.rows, e.us, m.us,
                  e.us / m.us);
      std::fflush(stdout);
    }
  }
  if (markdown) {
    std::printf("\n%s", stage_table_heading("matrix-free").c_str());
    std::printf("%s", stage_rows.c_str());
    std::printf("\nWindows:\n\n");
    for (const std::string& name : names) {
      const std::string_view reason = scenes::find_scene(name)->bench.reason;
      std::printf("- %s: %.*s\n", name.c_str(), static_cast<int>(reason.size()), reason.data());
    }
  }
  return rows;
}

// The cost of warm starting (matrix-free, each scene over its bench window from the same state
// at its start, at the scene's sweeps): cold (factor 0, the paper), the matching alone (factor
// 1e-100: the contacts are matched, the cache kept and every guess computed, but the guesses are
// 1e-100 of a lambda, so the run does the physics of the cold run to round-off; 1e-300 would
// make subnormal numbers, which are slow), and warm started at 0.8 (its own physics: other
// contacts, other rows).
nlohmann::json warm_start_table(const std::vector<std::string>& names, bool quick, bool markdown) {
  const int timed_steps = quick ? 60 : 180;
  if (markdown) {
    std::printf("\n## Warm starting: microseconds per step (matrix-free; the scene's window and "
                "sweeps; cold = factor 0, the paper; matching = factor 1e-100, the same physics "
                "with the cache kept and every guess computed)\n\n"
                "| scene | cold (us/step) | matching (us/step) | cost of matching | warm 0.8 "
                "(us/step) | rows/step cold | rows/step warm 0.8 |\n"
                "|---|---|---|---|---|---|---|\n");
  }
  nlohmann::json rows = nlohmann::json::array();
  for (const std::string& name : names) {
    const scenes::Scene& scene = *scenes::find_scene(name);
    const int steps = window_steps(scene, quick);
    const int repeats = std::max(5, (timed_steps + steps - 1) / steps);
    const double start = scene.bench.start_s;
    notes() << "bench: " << name << " warm starting\n";
    const StepCost cold = step_cost(scene, {}, Assembly::matrix_free, start, steps, repeats, 0.0);
    const StepCost match = step_cost(scene, {}, Assembly::matrix_free, start, steps, repeats, 1e-100);
    const StepCost warm = step_cost(scene, {}, Assembly::matrix_free, start, steps, repeats, 0.8);
    const double cost = match.us / cold.us - 1.0;
    rows.push_back({{"scene", name},
                    {"cold_us_per_step", cold.us},
                    {"matching_us_per_step", match.us},
                    {"matching_cost_fraction", cost},
                    {"warm_0.8_us_per_step", warm.us},
                    {"rows_per_step_cold", cold.rows},
                    {"rows_per_step_warm_0.8", warm.rows}});
    if (markdown) {
      std::printf("| %s | %.1f | %.1f | %+.1f %% | %.1f | %.1f | %.1f |\n", name.c_str(), cold.us,
                  match.us, 100.0 * cost, warm.us, cold.rows, warm.rows);
      std::fflush(stdout);
    }
  }
  return rows;
}

// One scene of a cost-growth series: its bodies and its cost over the window.
struct GrowthPoint {
  const scenes::Scene* source = nullptr;
  std::string scene;
  double bodies = 0.0;  // as the scene is built, static ones included
  StepCost cost;        // filled by measure_growth
};

// The sizes of the cost-growth table when none are given.
std::vector<int> default_growth_sizes(bool quick) {
  return quick ? std::vector<int>{100, 300, 1000} : std::vector<int>{100, 300, 1000, 3000, 5000};
}

// A growth point's window: 3 steps (quick) or 6 from the scene's bench start, 5 timed repeats.
constexpr int kGrowthRepeats = 5;
int growth_steps(bool quick) { return quick ? 3 : 6; }

// The points of the scaled scenes family_N, one per size (sizes sorted, without repeats), each
// checked against max_work (body-iterations: the steps to the window, the window untimed, timed
// kGrowthRepeats times and once with stage timing); their costs not yet measured. Throws
// UsageError for an unknown family (listing the families), fewer than two sizes, a size the
// family does not take (its range) or a run past max_work.
std::vector<GrowthPoint> growth_points(const std::string& family, const std::vector<int>& sizes,
                                       const scenes::Overrides& overrides, bool quick, double max_work) {
  std::string families;
  bool known = false;
  for (const std::string_view f : scenes::scaled_families()) {
    families += (families.empty() ? "" : ", ") + std::string(f);
    known = known || f.starts_with(family + "_N ");
  }
  if (!known) throw UsageError("--growth " + family + ": not a scaled scene family; allowed: " + families);
  if (sizes.size() < 2) throw UsageError("--sizes: a slope needs at least two different sizes");
  std::vector<GrowthPoint> out;
  for (const int n : sizes) {
    const scenes::Scene* found = scenes::find_scene(family + "_" + std::to_string(n));
    if (found == nullptr) {
      std::string why = "not a size of the family";
      try {
        (void)scenes::scaled_scene(family, n);
      } catch (const std::invalid_argument& e) {
        why = e.what();
      }
      throw UsageError("--sizes " + std::to_string(n) + ": " + why);
    }
    const scenes::Scene& scene = *found;
    const scenes::Run run = make_run_or_usage_error(scene, overrides);
    out.push_back({found, std::string(scene.name), static_cast<double>(run.world.bodies().size()), {}});
    const WorldDef& def = run.world.def();
    const double steps =
        std::round(scene.bench.start_s / def.dt) + (kGrowthRepeats + 2.0) * (growth_steps(quick) + 1.0);
    check_work("the steps of " + std::string(scene.name) +
                   " (to its window, then from the step before it through it once untimed, " +
                   std::to_string(kGrowthRepeats) + " times timed and once by stage)",
               run.world.bodies().size(), def, steps * def.dt, max_work,
               "give smaller --sizes, or raise --max-work");
  }
  return out;
}

// Each point's cost over its scene's window (step_cost; the assembly its world parameters give).
void measure_growth(std::vector<GrowthPoint>& points, const scenes::Overrides& overrides, bool quick) {
  for (GrowthPoint& p : points) {
    notes() << "bench: " << p.scene << "\n";
    const scenes::Scene& scene = *p.source;
    const Assembly assembly = scenes::world_def_with(scene, overrides).assembly;
    p.cost = step_cost(scene, overrides, assembly, scene.bench.start_s, growth_steps(quick), kGrowthRepeats);
  }
}

// Log-log slope of y(point) against bodies; NaN when y is not > 0 at every point (a stage the
// method does not run) or fewer than two different body counts.
template <class Y>
double growth_slope(const std::vector<GrowthPoint>& points, Y&& y) {
  std::vector<std::pair<double, double>> xy;
  for (const GrowthPoint& p : points) {
    const double v = y(p);
    if (!(v > 0.0)) return std::nan("");
    xy.emplace_back(p.bodies, v);
  }
  return log_log_slope(xy);
}

// A stage's slope is given where it takes at least this share of every point's stage-timed step
// (dimensionless): below it the stage's time is a few timer reads, and its slope noise.
constexpr double kSlopeShare = 0.01;

// The slopes of a series: the step's against bodies and against rows, the rows' against bodies,
// and each stage's against bodies (null where growth_slope is NaN or the stage is below
// kSlopeShare of a point's step).
nlohmann::json growth_slopes(const std::vector<GrowthPoint>& points) {
  const auto or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  std::vector<std::pair<double, double>> by_rows;
  for (const GrowthPoint& p : points) by_rows.emplace_back(std::max(p.cost.rows, 1.0), p.cost.us);
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, stage] : kStages) {
    stages[name] = or_null(growth_slope(points, [stage](const GrowthPoint& p) {
      const double t = p.cost.stages.*stage;
      return t >= kSlopeShare * p.cost.stages.total() ? t : 0.0;
    }));
  }
  return {{"slope_against_bodies", or_null(growth_slope(points, [](const GrowthPoint& p) { return p.cost.us; }))},
          {"slope_against_rows", or_null(log_log_slope(by_rows))},
          {"rows_slope_against_bodies", or_null(growth_slope(points, [](const GrowthPoint& p) { return p.cost.rows; }))},
          {"stage_slopes_against_bodies", stages}};
}

// The JSON of one point: bodies, rows, us per step (thread CPU, or wall on threads) and per
// body, and the stages' us per step (wall, from the stage-timed repeat).
nlohmann::json growth_point_json(const GrowthPoint& p) {
  return {{"scene", p.scene},
          {"bodies", p.bodies},
          {"rows_per_step", p.cost.rows},
          {"us_per_step", p.cost.us},
          {"us_per_body", p.cost.us / p.bodies},
          {"stages_us_per_step", stages_json(p.cost.stages)}};
}

// A slope as a table cell: two decimals, or "-" where there is none.
std::string slope_cell(const nlohmann::json& v) {
  if (v.is_null()) return "-";
  char cell[32];
  std::snprintf(cell, sizeof cell, "%.2f", v.get<double>());
  return cell;
}

// The cost growth table (matrix-free, each family at its own settings): log-log slopes of time
// per step against bodies and rows.
nlohmann::json growth_table(bool quick, bool markdown) {
  if (markdown) {
    std::printf("\n## Cost growth (matrix-free): log-log slope of time per step against bodies\n\n"
                "Also against the rows per step: a larger pile has more contacts per body (fewer "
                "bodies on its edges), so part of the growth is more work per body.\n\n"
                "| family | bodies: us/step (rows/step) | slope against bodies | slope against rows "
                "|\n|---|---|---|---|\n");
  }
  nlohmann::json families = nlohmann::json::array();
  for (const char* family : {"pyramid", "funnel"}) {
    std::vector<GrowthPoint> points = growth_points(family, default_growth_sizes(quick), {}, quick, kMaxMaxWork);
    measure_growth(points, {}, quick);
    nlohmann::json series = nlohmann::json::array();
    std::string cells;
    for (const GrowthPoint& p : points) {
      series.push_back({{"scene", p.scene},
                        {"bodies", p.bodies},
                        {"rows_per_step", p.cost.rows},
                        {"matrix_free_us_per_step", p.cost.us}});
      char cell[96];
      std::snprintf(cell, sizeof cell, "%s%.0f: %.0f (%.0f)", cells.empty() ? "" : ", ", p.bodies, p.cost.us,
                    p.cost.rows);
      cells += cell;
    }
    const nlohmann::json slopes = growth_slopes(points);
    families.push_back({{"family", std::string(family) + "_N"},
                        {"points", series},
                        {"slope_against_bodies", slopes["slope_against_bodies"]},
                        {"slope_against_rows", slopes["slope_against_rows"]}});
    if (markdown) {
      std::printf("| %s_N | %s | %s | %s |\n", family, cells.c_str(),
                  slope_cell(slopes["slope_against_bodies"]).c_str(), slope_cell(slopes["slope_against_rows"]).c_str());
    }
  }
  return families;
}

// `cps bench --growth FAMILY`: the points of growth_points measured with the world parameters given,
// point by point and stage by stage, in us per body, with every slope (growth_slopes).
nlohmann::json growth_series_table(const std::string& family, std::vector<GrowthPoint> points,
                                   const scenes::Overrides& overrides, bool quick, bool markdown) {
  measure_growth(points, overrides, quick);
  const WorldDef def = scenes::world_def_with(*points.front().source, overrides);
  nlohmann::json parameters = nlohmann::json::object();
  for (const auto& [parameter, value] : overrides.values) parameters[std::string(parameter->name)] = parameter->format(value);
  nlohmann::json out = {{"family", family + "_N"},
                        {"parameters", parameters},
                        {"assembly", def.assembly == Assembly::explicit_matrices ? "explicit" : "matrix-free"},
                        {"threads", def.threads},
                        {"clock", def.threads > 1 ? "wall" : "thread_cpu"},
                        {"steps", growth_steps(quick)},
                        {"repeats", kGrowthRepeats},
                        {"points", nlohmann::json::array()}};
  for (const GrowthPoint& p : points) out["points"].push_back(growth_point_json(p));
  const nlohmann::json slopes = growth_slopes(points);
  out.update(slopes);
  if (!markdown) return out;
  std::string given;
  for (const auto& [parameter, value] : overrides.values) {
    given += " --" + std::string(parameter->flag) + " " + parameter->format(value);
  }
  std::printf("## Cost growth of %s_N (%s; %s)\n\n"
              "us per step: the median of %d repeats of %d steps from each scene's bench start (%s); "
              "the stages: one more repeat with the engine's stage timing on (wall clock), in us "
              "per step per body; a stage's slope where it takes at least %.0f %% of every step.\n\n"
              "| scene | bodies | rows/step | us/step | us/body",
              family.c_str(), out["assembly"].get<std::string>().c_str(),
              given.empty() ? "each scene's own parameters" : ("given:" + given).c_str(), kGrowthRepeats,
              growth_steps(quick), def.threads > 1 ? "wall clock" : "this thread's CPU time", 100.0 * kSlopeShare);
  for (const auto& [name, stage] : kStages) std::printf(" | %s", name);
  std::printf(" |\n|---|---|---|---|---");
  for (std::size_t k = 0; k < std::size(kStages); ++k) std::printf("|---");
  std::printf("|\n");
  for (const GrowthPoint& p : points) {
    std::printf("| %s | %.0f | %.0f | %.0f | %.3f", p.scene.c_str(), p.bodies, p.cost.rows, p.cost.us,
                p.cost.us / p.bodies);
    for (const auto& [name, stage] : kStages) std::printf(" | %.3f", 1e6 * (p.cost.stages.*stage) / p.bodies);
    std::printf(" |\n");
  }
  std::printf("| slope against bodies | | %s | %s | |", slope_cell(slopes["rows_slope_against_bodies"]).c_str(),
              slope_cell(slopes["slope_against_bodies"]).c_str());
  for (const auto& [name, stage] : kStages) {
    std::printf(" %s |", slope_cell(slopes["stage_slopes_against_bodies"][name]).c_str());
  }
  std::printf("\n\nSlope of us/step against rows/step: %s.\n", slope_cell(slopes["slope_against_rows"]).c_str());
  return out;
}

// The tables, as Markdown (or one JSON document) on stdout; progress on stderr. quick: fewer
// and smaller scenes and a third of each window (seconds instead of minutes), one end-to-end
// rendering run per scene instead of three. rendering_only: only the rendering table. Returns
// the exit code (2 for rendering_only in a build without the renderer).
int run_bench(const BenchOptions& o) {
#ifndef CPS_HAVE_RENDERER
  if (o.rendering) {
    std::fprintf(stderr, "cps bench: built without the renderer (CPS_BUILD_RENDERER=OFF)\n");
    return 2;
  }
#endif
  if (o.rendering && !o.scenes.empty()) {
    throw UsageError("--scene and --rendering exclude each other: --scene times the physics of "
                     "the named scenes, --rendering only the rendering table");
  }
  if (!o.growth.empty() && (!o.scenes.empty() || o.rendering)) {
    throw UsageError("--growth times one scaled family's series alone; leave out --scene and --rendering");
  }
  if (o.growth.empty() && !o.sizes.empty()) {
    throw UsageError("--sizes gives the sizes of --growth's series; give --growth FAMILY with it");
  }
  if (!o.overrides.values.empty() && o.scenes.empty() && o.growth.empty()) {
    throw UsageError("world parameters (--" + std::string(o.overrides.values.front().first->flag) +
                     " and the like) apply to the scenes of --scene or --growth; the full tables "
                     "run each scene at its own settings");
  }
  if (!o.growth.empty()) {
    std::vector<int> sizes = default_growth_sizes(o.quick);
    if (!o.sizes.empty()) {
      sizes.clear();
      for (const long long n : parse_counts(o.sizes, 1, 1000000, "--sizes", "a size")) sizes.push_back(static_cast<int>(n));
    }
    std::vector<GrowthPoint> points = growth_points(o.growth, sizes, o.overrides, o.quick, o.max_work);
    nlohmann::json out = {{"engine_version", engine_version()}, {"quick", o.quick}};
    out["growth_series"] = growth_series_table(o.growth, std::move(points), o.overrides, o.quick, !o.json);
    if (o.json) std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  if (o.overrides.find("assembly") != nullptr) {
    throw UsageError("--assembly: cps bench times every scene under both assemblies (explicit "
                     "and matrix-free columns); leave it out");
  }
  std::vector<std::string> names;
  for (const std::string& name : o.scenes) {
    try {
      for (const scenes::Scene* scene : select_scenes(name)) {
        check_bench_work(*scene, o.overrides, o.quick, o.max_work);
        names.emplace_back(scene->name);
      }
    } catch (const UsageError& e) {
      throw UsageError(std::string("--scene ") + name + ": " + e.what());
    }
  }
  const bool markdown = !o.json;
  nlohmann::json out = {{"engine_version", engine_version()}, {"quick", o.quick}};
  if (!names.empty()) {
    out["physics"] = physics_table(names, o.overrides, o.quick, markdown);
  } else {
    if (!o.rendering) {
      out["physics"] = physics_table(physics_scenes(o.quick), {}, o.quick, markdown);
      out["warm_start"] = warm_start_table({"stack", "funnel"}, o.quick, markdown);
      out["growth"] = growth_table(o.quick, markdown);
    }
#ifdef CPS_HAVE_RENDERER
    out["rendering"] = render_table(o.quick, markdown);
#endif
  }
  if (o.json) std::printf("%s\n", out.dump(2).c_str());
  return 0;
}

}  // namespace

Command add_bench(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* sub = app.add_subcommand(
      "bench", "microseconds per step (explicit and matrix-free) and by stage, the cost of warm "
             "starting, cost growth, ms per frame");
  sub->add_flag("--quick", o->quick, "smaller scenes and fewer steps (results in us/step, ms/frame)");
  sub->add_flag("--rendering", o->rendering,
                "only the rendering table (ms per frame at 1280x720: draw, PNG, end to end)");
  sub->add_flag("--json", o->json,
                "print one JSON document (physics, growth, rendering; keys carry their units) "
                "instead of the Markdown tables");
  sub->add_option("--scene", o->scenes,
                  "time only these scenes (a name, a scaled scene such as funnel_500, 'all' or 'stress'; "
                  "repeatable): the physics table alone, each scene over its window")
      ->check(kNotEmpty);
  sub->add_option("--growth", o->growth,
                  "time only the cost growth of one scaled scene family (pyramid, funnel, stack, "
                  "pendulum_wave or pendulum_grid: FAMILY_N for each of --sizes) at the world "
                  "parameters given: us per step and per body, by stage, and the log-log slopes "
                  "against bodies and rows")
      ->check(kNotEmpty);
  sub->add_option("--sizes", o->sizes,
                  "the sizes N of --growth's scenes, comma-separated, at least two different, each "
                  "in the family's range; default 100,300,1000,3000,5000 (with --quick 100,300,1000)")
      ->check(kNotEmpty);
  add_seed_option(*sub, o->scenes);
  add_max_work_option(*sub, o->max_work);
  add_world_options(*sub, o->overrides);
  add_diagnostic_flags(*sub);
  return {sub, [o] { return run_bench(*o); }};
}

}  // namespace cps::cli
