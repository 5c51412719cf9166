#include "commands/render.h"

#include "command.h"
#include "pictures/draw.h"
#include "options/options.h"
#include "output/output.h"
#include "pictures/overlay.h"
#include "pictures/video.h"
#include "options/view_options.h"
#include "energy_rise.h"
#include "options/diagnostics.h"

#include "cps/render/image_ops.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

namespace cps::cli {

long long frame_count(const RenderJob& job) {
  const double frames = std::floor(job.seconds * job.fps / job.speed + 1e-9) + 1.0;
  // Saturates instead of overflowing: the render command refuses anything past kMaxFrames.
  return frames < 9.0e18 ? static_cast<long long>(frames) : 9'000'000'000'000'000'000LL;
}

double frame_time(const RenderJob& job, long long k) {
  return static_cast<double>(k) * job.speed / job.fps;
}

std::string frame_spacing_note(const RenderJob& job, double dt) {
  const double spacing = job.speed / job.fps;
  const double steps = spacing / dt;
  if (std::abs(steps - std::round(steps)) <= 1e-9 * std::max(1.0, steps) && steps >= 0.5) {
    return {};
  }
  char text[320];
  std::snprintf(text, sizeof text,
                "frames are %g s apart (--speed %g / --fps %g), %.4g physics steps of %g s: each "
                "frame shows the step nearest its time%s",
                spacing, job.speed, job.fps, steps, dt,
                steps < 1.0 ? ", so some frames repeat the one before" : "");
  return text;
}

std::string frame_name(long long k) {
  char name[40];
  std::snprintf(name, sizeof name, "frame_%06lld.png", k);
  return name;
}

namespace {

// A panel's caption in a frame: its label (if any), then the time t (s) on a line of its own,
// with the decimals that tell frames `spacing` s apart.
std::string frame_caption(const std::string& label, double t, double spacing) {
  return (label.empty() ? std::string() : label + "\n") + time_caption(t, spacing);
}

}  // namespace

std::string caption_for_cell(const std::string& label, double cell_width, double cell_height,
                             double font) {
  if (label.empty()) return label;
  const double per_line = std::max(1.0, std::floor(cell_width / (0.55 * font)));  // glyphs
  double lines = 1.0;  // the time below
  for (std::size_t start = 0; start <= label.size();) {
    const std::size_t nl = std::min(label.find('\n', start), label.size());
    lines += std::max(1.0, std::ceil(static_cast<double>(nl - start) / per_line));
    start = nl + 1;
  }
  if (lines * 1.25 * font <= 0.25 * cell_height) return label;
  return label.substr(0, label.find('\n'));
}

namespace {

// `labels` fitted to the cells of `page` (its grid, size and font: frame_page's) by
// caption_for_cell; when one is cut to its first line, all are, so the panels read alike.
std::vector<std::string> fitted_labels(const FigurePage& page, const std::vector<std::string>& labels) {
  const double cell_width = static_cast<double>(page.width) / page.columns;
  const double cell_height = static_cast<double>(page.height) / page.rows;
  bool cut = false;
  for (const std::string& label : labels) {
    cut = cut || caption_for_cell(label, cell_width, cell_height, page.font_size) != label;
  }
  std::vector<std::string> out;
  for (const std::string& label : labels) out.push_back(cut ? label.substr(0, label.find('\n')) : label);
  return out;
}

}  // namespace

bool frame_has_captions(const RenderJob& job, const std::vector<std::string>& labels) {
  if (job.frame_width <= 0 || job.frame_height <= 0) return false;
  if (job.overlay) return true;
  for (const std::string& label : labels) {
    if (!label.empty()) return true;
  }
  return false;
}

FigurePage frame_page(const RenderJob& job, const std::vector<std::string>& labels, double t) {
  if (job.frame_width <= 0 || job.frame_height <= 0) {
    throw std::invalid_argument("frame_page: a frame of " + std::to_string(job.frame_width) + "x" +
                                std::to_string(job.frame_height) + " pixels");
  }
  FigurePage page;
  const std::size_t panels = job.overlay ? 1 : labels.size();
  page.columns = job.overlay ? 1 : std::max(1, std::min(job.columns > 0 ? job.columns : static_cast<int>(panels),
                                                         static_cast<int>(panels)));
  page.rows = static_cast<int>((panels + static_cast<std::size_t>(page.columns) - 1) /
                               static_cast<std::size_t>(page.columns));
  page.font_size = std::max(10.0, job.frame_height / static_cast<double>(page.rows) / 30.0);
  page.width = job.frame_width;
  page.height = job.frame_height;
  page.title = job.title;
  const std::vector<std::string> fitted = fitted_labels(page, labels);
  for (std::size_t p = 0; p < panels; ++p) {
    page.panels.push_back({nullptr, "", frame_caption(labels.empty() ? std::string() : fitted[p], t,
                                                          job.speed / job.fps)});
  }
  // A last row that the variants do not fill: its empty cells have no caption.
  for (std::size_t p = panels; p < static_cast<std::size_t>(page.rows * page.columns); ++p) {
    page.panels.push_back({nullptr, "", ""});
  }
  if (job.overlay) {
    page.legend_heading = job.legend_heading;
    page.legend = job.legend;
  }
  const auto [w, h] = fit_panels(page, job.frame_width, job.frame_height);
  page.panel_width = w;
  page.panel_height = h;
  return page;
}

PageLayout frame_layout(const RenderJob& job, const std::vector<std::string>& labels) {
  if (frame_has_captions(job, labels)) {
    return layout_page(frame_page(job, labels, frame_time(job, frame_count(job) - 1)));
  }
  const int n = job.overlay ? 1 : static_cast<int>(std::max<std::size_t>(1, labels.size()));
  const int columns = std::min(job.columns > 0 ? job.columns : n, n);
  const int rows = (n + columns - 1) / columns;
  PageLayout layout;
  const int width = job.frame_width / columns;
  const int height = job.frame_height / rows;
  layout.width = width * columns;
  layout.height = height * rows;
  for (int k = 0; k < n; ++k) layout.panels.push_back({(k % columns) * width, (k / columns) * height, width, height});
  return layout;
}

long long render_frames(const DrawStyle& style, std::vector<Panel>& panels, const RenderJob& job,
                        render::Renderer& renderer, render::PngWriter& writer, Progress* progress) {
  const long long frames = frame_count(job);
  std::vector<std::string> labels;
  std::vector<const World*> worlds;
  for (const Panel& panel : panels) {
    labels.push_back(panel.label);
    worlds.push_back(&panel.run->world);
  }
  const bool captions = frame_has_captions(job, labels);
  // The layout is fixed for the whole sequence, measured with the last frame's time (the
  // widest), so the strips never move.
  std::optional<FigurePage> base;
  std::optional<PageLayout> layout;
  if (captions) {
    base = frame_page(job, labels, frame_time(job, frames - 1));
    if (base->panel_width != renderer.width() || base->panel_height != renderer.height()) {
      throw std::invalid_argument("render_frames: the renderer is " + std::to_string(renderer.width()) + "x" +
                                  std::to_string(renderer.height()) + ", the captions leave " +
                                  std::to_string(base->panel_width) + "x" + std::to_string(base->panel_height));
    }
    layout = layout_page(*base);
  }
  // Each label as the captions fit it to its cell (caption_for_cell), for every frame.
  const std::vector<std::string> fitted = captions ? fitted_labels(*base, labels) : labels;
  std::vector<render::Image> pictures(job.overlay ? 1 : panels.size());
  for (long long k = 0; k < frames; ++k) {
    const double t = frame_time(job, k);
    for (Panel& panel : panels) panel.run->advance_to(t);
    if (job.overlay) {
      pictures[0] = renderer.draw(overlay_draw_list(worlds, style));
    } else {
      for (std::size_t p = 0; p < panels.size(); ++p) {
        pictures[p] = renderer.draw(draw_list(panels[p].run->world, style, p));
      }
    }
    if (!captions) {
      writer.write(job.folder / frame_name(k),
                   pictures.size() == 1
                       ? std::move(pictures.front())
                       : render::grid(pictures, job.columns > 0 ? job.columns : static_cast<int>(pictures.size())));
    } else {
      // Each caption says its own world's time (the variants' steps may differ).
      FigurePage page = *base;
      for (std::size_t p = 0; p < pictures.size(); ++p) {
        page.panels[p].image = &pictures[p];
        page.panels[p].text = frame_caption(fitted[p], worlds[p]->time(), job.speed / job.fps);
      }
      writer.write(job.folder / frame_name(k), compose_page_pixels(page, *layout));
    }
    if (progress != nullptr) progress->update(k + 1);
  }
  writer.finish();
  if (progress != nullptr) progress->finish();
  return frames;
}

namespace {

namespace fs = std::filesystem;

// The options of `cps render`.
struct RenderOptions {
  std::string scene;
  std::optional<double> seconds;  // s; default: the scene's
  double fps = 30.0;
  std::string size = "1280x720";
  double speed = 1.0;  // simulated seconds per second of video
  std::string out = "out";
  std::string compare;
  bool overlay = false;
  bool force = false;
  scenes::Overrides overrides;
  std::string backend = "auto";
  std::string video;
  View view;  // --camera, --contacts, --rods, --orbit
  bool label = false;
  double max_work = kDefaultMaxWork;  // body-iterations a run
};

// One scene of a render as planned: a run and a caption label per variant, its frames, where
// its panels lie in a frame, its camera and its frames folder, checked.
struct SceneRender {
  const scenes::Scene* scene = nullptr;
  std::vector<scenes::Run> runs;
  std::vector<std::shared_ptr<const scenes::EnergyRiseTracker>> energy;  // per variant
  std::vector<std::string> labels;  // per variant: its caption's label
  RenderJob spec;                   // seconds, fps, speed, folder, grid, frame size, legend
  std::pair<int, int> scene_px;     // the scene's size in each panel (frame_layout)
  nlohmann::json panels_px = nlohmann::json::array();  // each panel's [x, y, width, height] in a frame
  DrawStyle style;                  // the same camera for the whole sequence
  OutputPlan output;                // the frames folder
};

// A render as planned: every option, scene, variant, work bound and output checked, nothing
// written. With --video, ffmpeg (none if not on PATH) and the videos' plan in OUT/ with its
// run.json.
struct RenderPlan {
  PixelSize size;
  Comparison comparison;
  std::vector<Variant> variants;
  Grid grid;  // the variants' panels in a frame ({1, 1} with --overlay)
  std::vector<SceneRender> scenes;
  std::optional<fs::path> ffmpeg;
  std::optional<OutputPlan> video_output;
  nlohmann::json video_info;
};

// The variants' panels in a grid of rows x columns that fills --size (one panel for
// --overlay). Throws UsageError if a panel would be smaller than 16x16 pixels.
Grid plan_grid(const RenderOptions& o, const PixelSize& size, std::size_t variants) {
  const Grid grid = o.overlay ? Grid{1, 1}
                              : grid_layout(variants, static_cast<double>(size.width) / size.height);
  const int panel_width = size.width / grid.columns;
  const int panel_height = size.height / grid.rows;
  if (panel_width < 16 || panel_height < 16) {
    throw UsageError("--size " + o.size + ": --compare " + o.compare + " lays " +
                     std::to_string(variants) + " panels out as " +
                     std::to_string(grid.rows) + " x " + std::to_string(grid.columns) + ", each " +
                     std::to_string(panel_width) + "x" + std::to_string(panel_height) +
                     " pixels; a panel needs at least 16x16: give a larger --size");
  }
  return grid;
}

// A scene's runs, one per variant, and their caption labels. Throws UsageError for parameters
// the world refuses.
SceneRender scene_runs(const RenderOptions& o, const scenes::Scene& scene,
                       const std::vector<Variant>& variants) {
  SceneRender job;
  job.scene = &scene;
  for (const Variant& v : variants) {
    job.runs.push_back(make_run_or_usage_error(scene, v.overrides));
    job.energy.push_back(scenes::watch_energy_rise(job.runs.back()));
    // --overlay: the legend names the variants; the label, the scene (with --label). Several
    // panels: the scene's name is the frame's title (plan_scene), not on every panel.
    std::string label = o.overlay ? "" : v.label;
    if (o.label && (variants.size() == 1 || o.overlay)) {
      label = std::string(scenes::output_name(scene)) + (label.empty() ? "" : "\n" + label);
    }
    job.labels.push_back(label);
  }
  return job;
}

// --video: ffmpeg is looked for before rendering; without it a warning on stderr says that the
// frames are still rendered and kept (the command then ends with an error saying how to finish
// the video). None without --video.
std::optional<fs::path> look_for_ffmpeg(const RenderOptions& o) {
  if (o.video.empty()) return std::nullopt;
  std::optional<fs::path> ffmpeg = find_on_path("ffmpeg");
  if (!ffmpeg) {
    warn("ffmpeg",
         "--video " + o.video + ": ffmpeg is not on PATH; the frames will be rendered and kept, "
         "but no video made (install it: apt-get install ffmpeg)",
         "--video " + o.video + ": ffmpeg is not on PATH, no video made", "docs/commands.md#render");
  }
  return ffmpeg;
}

// The frames of one scene: its duration (s), fps, speed, folder OUT/SCENE[-compare-...], and
// the plan's grid filling as much of --size as divides among its cells.
RenderJob frames_spec(const RenderOptions& o, const RenderPlan& plan, const scenes::Scene& scene) {
  RenderJob spec;
  spec.seconds = o.seconds.value_or(scene.default_seconds);
  spec.fps = o.fps;
  spec.speed = o.speed;
  spec.folder = fs::path(o.out) / (std::string(scenes::output_name(scene)) +
                                   comparison_suffix(plan.comparison, o.overlay));
  spec.columns = plan.grid.columns;
  spec.frame_width = plan.size.width / plan.grid.columns * plan.grid.columns;
  spec.frame_height = plan.size.height / plan.grid.rows * plan.grid.rows;
  spec.overlay = o.overlay;
  if (o.overlay) {
    spec.legend_heading = legend_heading(plan.comparison);
    spec.legend = overlay_legend(plan.variants);
  }
  return spec;
}

// The work is bounded before anything is drawn or written: each run's physics steps
// (check_steps) and solver work (check_work, --max-work), the frames (kMaxFrames) and the pixels drawn (kMaxPixelBytes, 3 bytes a pixel
// of --size). Throws UsageError.
void check_render_work(const RenderOptions& o, const PixelSize& size, const SceneRender& job) {
  const std::string name(job.scene->name);
  for (const scenes::Run& run : job.runs) {
    check_steps(name, job.spec.seconds, run.world.def().dt);
    check_work(name, run.world.bodies().size(), run.world.def(), job.spec.seconds, o.max_work,
               lower_run_options(run.world.def()));
  }
  const long long frames = frame_count(job.spec);
  if (static_cast<double>(frames) > kMaxFrames) {
    throw UsageError(name + ": " + std::to_string(frames) +
                     " frames (--seconds x --fps / --speed) is more than the " +
                     std::to_string(static_cast<long long>(kMaxFrames)) +
                     " frames a render may write; give fewer --seconds or a lower --fps");
  }
  const double pixel_bytes = static_cast<double>(frames) * size.width * size.height * 3.0;
  if (pixel_bytes > kMaxPixelBytes) {
    throw UsageError(name + ": " + std::to_string(frames) + " frames of " + o.size + " pixels is " +
                     std::to_string(static_cast<long long>(pixel_bytes / 1073741824.0)) +
                     " GiB of pixels, more than the 64 GiB a render may draw; give fewer frames "
                     "or a smaller --size");
  }
}

// Sets job.scene_px and job.panels_px (the first `panels`, not a grid's empty cells) from
// frame_layout: the caption strips (labels, time, legend) lie outside the scene, and what they
// leave of each panel is where the scene is drawn. Throws UsageError if that is less than 16x16.
void place_panels(const RenderOptions& o, std::size_t panels, SceneRender& job) {
  const PageLayout frame = frame_layout(job.spec, job.labels);
  job.scene_px = {frame.panels.front().width, frame.panels.front().height};
  for (std::size_t k = 0; k < panels; ++k) {
    const PageLayout::Rect& r = frame.panels[k];
    job.panels_px.push_back({r.x, r.y, r.width, r.height});
  }
  if (job.scene_px.first < 16 || job.scene_px.second < 16) {
    throw UsageError("--size " + o.size + ": the caption strips below the scene (its label, the time" +
                     std::string(o.overlay ? " and the legend" : "") + ") leave it " +
                     std::to_string(std::max(0, job.scene_px.first)) + "x" +
                     std::to_string(std::max(0, job.scene_px.second)) +
                     " pixels of each panel; a scene needs at least 16x16: give a larger --size" +
                     std::string(o.label ? " or leave out --label" : ""));
  }
}

// run.json's camera_resolved: the camera of every frame, or for a camera that moves or differs
// by panel (fit:panel, fit:frame, track:BODY) each panel's at the first and the last frame.
nlohmann::json resolved_camera_json(const DrawStyle& style, std::size_t panels, double last_t) {
  if (style.paths.empty()) return camera_json(style.camera);
  nlohmann::json first = nlohmann::json::array();
  nlohmann::json last = nlohmann::json::array();
  for (std::size_t p = 0; p < std::max<std::size_t>(1, std::min(panels, style.paths.size())); ++p) {
    first.push_back(camera_json(camera_at(style, p, 0.0)));
    last.push_back(camera_json(camera_at(style, p, last_t)));
  }
  return {{"moves", true}, {"first_frame_by_panel", first}, {"last_frame_by_panel", last}};
}

// Plans one scene's frames: what they are, the work bound, the panels, the camera (resolve_style
// at the scene's aspect) and the frames folder (plan_output: its foreign files). Throws
// UsageError.
void plan_scene(const RenderOptions& o, const RenderPlan& plan, SceneRender& job) {
  job.spec = frames_spec(o, plan, *job.scene);
  if (o.label && !o.overlay && plan.variants.size() > 1) job.spec.title = std::string(scenes::output_name(*job.scene));
  check_render_work(o, plan.size, job);
  place_panels(o, o.overlay ? 1 : plan.variants.size(), job);
  std::vector<const World*> worlds;
  for (const scenes::Run& run : job.runs) worlds.push_back(&run.world);
  View view = scene_view(*job.scene, o.view);
  view.one_picture = o.overlay;
  job.style = resolve_style(*job.scene, worlds, view,
                            static_cast<float>(job.scene_px.first) / static_cast<float>(job.scene_px.second),
                            job.spec.seconds);
  const long long frames = frame_count(job.spec);
  std::vector<std::string> files;
  files.reserve(static_cast<std::size_t>(frames));
  std::map<std::string, std::string> scenes;
  for (long long k = 0; k < frames; ++k) {
    files.push_back(frame_name(k));
    scenes.emplace(files.back(), scene_source(job.scene->name));
  }
  job.output = plan_output({.folder = job.spec.folder,
                            .files = std::move(files),
                            .command = "render",
                            .use = FolderUse::exclusive,
                            .scenes = std::move(scenes),
                            .force = o.force});
}

// --video: the videos go to OUT/, beside the frames folders, which holds other files too (other
// scenes' videos, whatever the user keeps there): only the videos are checked (FolderUse::shared).
void plan_videos(const RenderOptions& o, int argc, char** argv, RenderPlan& plan) {
  if (o.video.empty()) return;
  std::vector<std::string> names;
  std::map<std::string, std::string> scenes;
  nlohmann::json folders = nlohmann::json::array();
  for (const SceneRender& job : plan.scenes) {
    names.push_back(job.spec.folder.filename().string() + "." + o.video);
    scenes.emplace(names.back(), scene_source(job.scene->name));
    folders.push_back(job.spec.folder.filename().string());
  }
  plan.video_output = plan_output({.folder = fs::path(o.out),
                                   .files = names,
                                   .command = "render",
                                   .use = FolderUse::shared,
                                   .scenes = std::move(scenes),
                                   .force = o.force});
  plan.video_info = run_info("render", argc, argv,
                             {{"video", o.video}, {"fps", o.fps}, {"frames_folders", folders}});
}

// Everything is checked (scenes, size, variants, camera, work, output folders) before anything
// is written; only the warning of look_for_ffmpeg is printed. Throws UsageError.
RenderPlan plan_render(const RenderOptions& o, int argc, char** argv) {
  RenderPlan plan;
  plan.size = parse_size(o.size);
  const std::vector<const scenes::Scene*> selected = select_scenes(o.scene);
  plan.comparison = parse_comparison(o.compare, o.overrides);
  plan.variants = comparison_variants(plan.comparison, o.overrides);
  if (o.overlay && o.compare.empty()) {
    throw UsageError("--overlay draws the variants of --compare in one view; give --compare too "
                     "(e.g. --compare push --overlay)");
  }
  plan.grid = plan_grid(o, plan.size, plan.variants.size());
  for (const scenes::Scene* s : selected) plan.scenes.push_back(scene_runs(o, *s, plan.variants));
  plan.ffmpeg = look_for_ffmpeg(o);
  // Every output folder is checked (foreign files, see output.h) before any is written.
  for (SceneRender& job : plan.scenes) plan_scene(o, plan, job);
  plan_videos(o, argc, argv, plan);
  return plan;
}

// run.json's "world" of a scene's frames: per variant its label, overlay colour (--overlay, else
// null), overrides and world parameters.
nlohmann::json variants_json(const RenderOptions& o, const RenderPlan& plan, const SceneRender& job) {
  nlohmann::json world = nlohmann::json::array();
  for (std::size_t v = 0; v < plan.variants.size(); ++v) {
    world.push_back({{"label", plan.variants[v].label},
                     {"overlay_colour_srgb", o.overlay ? nlohmann::json(overlay_colour(v))
                                                       : nlohmann::json(nullptr)},
                     {"overrides", overrides_json(plan.variants[v].overrides)},
                     {"parameters", parameters_json(job.runs[v].world.def())}});
  }
  return world;
}

// The frame spacing notes of a scene's runs (frame_spacing_note; none when the frames fall on
// physics steps), each also printed on stderr.
nlohmann::json spacing_notes(const SceneRender& job) {
  nlohmann::json notes = nlohmann::json::array();
  for (const scenes::Run& run : job.runs) {
    const std::string note = frame_spacing_note(job.spec, run.world.def().dt);
    if (note.empty()) continue;
    cli::note("cps: note: " + std::string(job.scene->name) + ": " + note);
    notes.push_back(note);
  }
  return notes;
}

// The run.json of a scene's frames folder (run_info): the frames, size, comparison, layout in
// pixels, view and overlays, and the variants' worlds.
nlohmann::json frames_info(const RenderOptions& o, const RenderPlan& plan, const SceneRender& job,
                           const nlohmann::json& notes, int argc, char** argv) {
  const RenderJob& spec = job.spec;
  const Overlays& overlays = o.view.overlays;
  nlohmann::json layout = {{"frame_px", {spec.frame_width, spec.frame_height}}, {"panels_px", job.panels_px}};
  if (o.overlay) {
    layout["overlay"] = true;
  } else {
    layout["rows"] = plan.grid.rows;
    layout["columns"] = plan.grid.columns;
  }
  return run_info(
      "render", argc, argv,
      {{"scene", job.scene->name},
       {"seconds", spec.seconds},
       {"fps", spec.fps},
       {"speed", spec.speed},
       {"frame_spacing_s", spec.speed / spec.fps},
       {"frame_times", notes.empty() ? nlohmann::json("exact multiples of the physics step") : notes},
       {"frames", frame_count(spec)},
       {"size", {{"width", plan.size.width}, {"height", plan.size.height}}},
       {"compare", comparison_json(plan.comparison, o.overlay)},
       {"layout", layout},
       {"backend", o.backend},
       {"camera", scene_view(*job.scene, o.view).camera},
       {"camera_resolved", resolved_camera_json(job.style, job.runs.size(), frame_time(spec, frame_count(spec) - 1))},
       {"eye_m", o.view.eye ? nlohmann::json{o.view.eye->x(), o.view.eye->y(), o.view.eye->z()}
                            : nlohmann::json(nullptr)},
       {"target_m", o.view.target ? nlohmann::json{o.view.target->x(), o.view.target->y(), o.view.target->z()}
                                  : nlohmann::json(nullptr)},
       {"fov_y_deg", o.view.fov_y_deg ? nlohmann::json(*o.view.fov_y_deg) : nlohmann::json(nullptr)},
       {"orbit_deg_per_s", overlays.orbit_deg_per_s},
       {"contacts", overlays.contacts},
       {"velocities", overlays.velocities},
       {"forces", overlays.forces},
       {"rods", overlays.rods},
       {"label", o.label},
       {"overrides", overrides_json(o.overrides)},
       {"world", variants_json(o, plan, job)}});
}

// Makes `renderer` job's scene size on --backend unless it is already (one renderer serves
// every scene whose captions leave the same size), and names its context on stderr.
void fit_renderer(std::optional<render::Renderer>& renderer, const SceneRender& job,
                  const std::string& backend) {
  if (renderer && renderer->width() == job.scene_px.first && renderer->height() == job.scene_px.second) {
    return;
  }
  renderer.reset();
  renderer.emplace(job.scene_px.first, job.scene_px.second, *render::parse_backend(backend));
  cli::note("render: " + renderer->context_description());
}

// Steps and draws a scene's frames into its folder (begin_output, render_frames, end_output)
// and prints how many. Returns the number of frames.
long long write_frames(const RenderOptions& o, const RenderPlan& plan, SceneRender& job,
                       render::Renderer& renderer, render::PngWriter& writer, int argc, char** argv) {
  std::vector<Panel> panels;
  for (std::size_t v = 0; v < plan.variants.size(); ++v) panels.push_back({&job.runs[v], job.labels[v]});
  const nlohmann::json notes = spacing_notes(job);
  nlohmann::json info = frames_info(o, plan, job, notes, argc, argv);
  info["parameters"]["renderer"] = {{"backend", render::backend_name(renderer.backend())},
                                    {"context", renderer.context_description()}};
  begin_output(job.output, info);
  Progress progress("render " + job.spec.folder.filename().string(), frame_count(job.spec), "frames");
  const long long frames = render_frames(job.style, panels, job.spec, renderer, writer, &progress);
  end_output(job.output, info);
  for (std::size_t v = 0; v < job.runs.size(); ++v) {
    for (const scenes::RunWarning& w :
         scenes::run_warnings(job.scene->name, plan.variants[v].label, job.runs[v], *job.energy[v])) {
      warn(w.kind, w.text, w.brief, w.docs);
    }
  }
  std::printf("%s: %lld frames in %s\n", job.spec.folder.filename().c_str(), frames, job.spec.folder.c_str());
  return frames;
}

// --video: a scene's frames (at most kMaxFrames) assembled as OUT/FOLDER.FORMAT at --fps.
VideoJob video_of(const RenderOptions& o, const RenderJob& spec, long long frames) {
  VideoJob video;
  video.format = *parse_video_format(o.video);
  video.frames_folder = spec.folder;
  video.frames = static_cast<int>(frames);
  video.fps = o.fps;
  video.width = spec.frame_width;
  video.height = spec.frame_height;
  video.output = fs::path(o.out) / (spec.folder.filename().string() + "." + o.video);
  return video;
}

// Throws VideoError (the frames are kept) with the ffmpeg command line of each video left.
[[noreturn]] void refuse_videos_left(const RenderOptions& o, const std::vector<VideoJob>& videos) {
  std::string how;
  for (const VideoJob& v : videos) how += "\n  " + shell_command(ffmpeg_arguments("ffmpeg", v, v.output));
  throw VideoError("--video " + o.video +
                   ": ffmpeg is not on PATH, so no video was made; install it "
                   "(apt-get install ffmpeg). The frames are kept; to assemble them "
                   "without rendering again, run:" + how);
}

// Renders the plan: each scene's frames, then its video (--video, when ffmpeg is there). Throws
// VideoError after every scene's frames if ffmpeg is not, std::runtime_error on failure.
int execute_render(const RenderOptions& o, RenderPlan& plan, int argc, char** argv) {
  // One renderer at the scene's size; another only when a scene's captions leave it another
  // size (--label with scene names of more lines).
  std::optional<render::Renderer> renderer;
  // Encoding overlaps drawing: one encoder thread keeps up with llvmpipe (see cps bench). Each
  // frame is written atomically under the output rule (output.h).
  render::PngWriter writer(
      [](const fs::path& path, std::span<const std::uint8_t> bytes) { write_file_atomic(path, bytes); },
      1, 3);
  const bool videos = plan.video_output && plan.ffmpeg;
  if (videos) begin_output(*plan.video_output, plan.video_info);
  std::vector<VideoJob> videos_left;
  for (SceneRender& job : plan.scenes) {
    fit_renderer(renderer, job, o.backend);
    const long long frames = write_frames(o, plan, job, *renderer, writer, argc, argv);
    if (o.video.empty()) continue;
    const VideoJob video = video_of(o, job.spec, frames);
    if (!plan.ffmpeg) {
      videos_left.push_back(video);
      continue;
    }
    encode_video(*plan.ffmpeg, video);
    std::printf("%s: video %s (%ju bytes)\n", job.spec.folder.filename().c_str(), video.output.c_str(),
                static_cast<std::uintmax_t>(fs::file_size(video.output)));
  }
  if (videos) end_output(*plan.video_output, plan.video_info);
  if (!videos_left.empty()) refuse_videos_left(o, videos_left);
  return 0;
}

int run_render(const RenderOptions& o, int argc, char** argv) {
  RenderPlan plan = plan_render(o, argc, argv);
  return execute_render(o, plan, argc, argv);
}

}  // namespace

Command add_render(CLI::App& app, int argc, char** argv) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* sub = app.add_subcommand("render", "render scenes into PNG frame sequences");
  sub->add_option("scene", o->scene, "scene name, the path of a scene file (.json), or 'all'")->required();
  add_seed_option(*sub, o->scene);
  add_seconds_option(*sub, o->seconds,
                     "at most 1e7 physics steps, 1e5 frames and 64 GiB of pixels a render");
  sub->add_option("--fps", o->fps,
                  "frames per second of video, in [1e-5, 1000]; frames are --speed / --fps "
                  "simulated seconds apart (so with --speed 1, frames per simulated second)")
      ->capture_default_str()
      ->check(decimal_in(1.0 / kMaxSeconds, kMaxFps, false, "frames/s"));
  sub->add_option("--speed", o->speed,
                  "simulated seconds per second of video, in (0, 100] (0.25: slow motion, 4: "
                  "fast); frame k shows the physics step nearest to k x speed / fps s, and the "
                  "label the simulated time")
      ->capture_default_str()
      ->check(decimal_in(0.0, 100.0, true, "s/s"));
  sub->add_option("--size", o->size, "frame size WxH in pixels, each in [16, 8192]")->capture_default_str();
  sub->add_option("--out", o->out, "output folder; frames go to OUT/SCENE/")
      ->capture_default_str()
      ->check(kNotEmpty);
  sub->add_option("--compare", o->compare,
                  "PARAM=V1,V2,...: render 2 to 8 values of a world parameter (" + comparable_list() +
                      "), each checked as its own option is, in a grid of labelled panels that "
                      "fills --size (2: 1x2 or 2x1 by aspect, 3: 1x3, 4: 2x2, 5-6: 2x3), into "
                      "OUT/SCENE-compare-PARAM-V1_V2_.../; a choice alone (e.g. push) compares "
                      "all its values, into OUT/SCENE-compare-PARAM/")
      ->check(kNotEmpty);
  sub->add_flag("--overlay", o->overlay,
                "with --compare: draw every variant in ONE view of --size as a translucent ghost "
                "in its own colour, with a legend, into OUT/SCENE-compare-...-overlay/");
  sub->add_flag("--force", o->force,
                "write into an output folder that holds files no earlier cps run wrote there: "
                "those files are kept, never removed or changed, except that a file with exactly "
                "the name of one cps writes (a frame, run.json, OUT/SCENE.mp4) is replaced");
  add_max_work_option(*sub, o->max_work);
  add_world_options(*sub, o->overrides);
  sub->add_option("--backend", o->backend,
                  "OpenGL context: osmesa (libOSMesa, CPU), egl (headless EGL: GPU if any, "
                  "else llvmpipe), or auto (osmesa where libOSMesa loads, else egl)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "osmesa", "egl"}));
  sub->add_option("--video", o->video,
                  "after the frames, assemble them with ffmpeg into OUT/SCENE.mp4 (H.264) or "
                  "OUT/SCENE.gif")
      ->check(CLI::IsMember({"mp4", "gif"}));
  add_view_options(*sub, o->view, o->label, /*label_default=*/false);
  add_diagnostic_flags(*sub);
  return {sub, [o, argc, argv] { return run_render(*o, argc, argv); }};
}

}  // namespace cps::cli
