#include "commands/render.h"

#include "command.h"
#include "pictures/draw.h"
#include "options/options.h"
#include "output/output.h"
#include "pictures/overlay.h"
#include "pictures/video.h"
#include "options/view_options.h"

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

// A panel's caption in a frame: its label (if any), then the time t (s) on a line of its own.
std::string frame_caption(const std::string& label, double t) {
  return (label.empty() ? std::string() : label + "\n") + time_caption(t);
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
  for (std::size_t p = 0; p < panels; ++p) {
    page.panels.push_back({nullptr, "", frame_caption(labels.empty() ? std::string() : labels[p], t)});
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
  std::vector<render::Image> pictures(job.overlay ? 1 : panels.size());
  for (long long k = 0; k < frames; ++k) {
    const double t = frame_time(job, k);
    for (Panel& panel : panels) panel.run->advance_to(t);
    if (job.overlay) {
      pictures[0] = renderer.draw(overlay_draw_list(worlds, style));
    } else {
      for (std::size_t p = 0; p < panels.size(); ++p) {
        pictures[p] = renderer.draw(draw_list(panels[p].run->world, style));
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
        page.panels[p].text = frame_caption(labels[p], worlds[p]->time());
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
  std::string backend = "osmesa";
  std::string video;
  View view;  // --camera, --contacts, --rods, --orbit
  bool label = false;
};

// Everything is checked (scenes, size, variants, camera, output folders) before anything is
// written.
int run_render(const RenderOptions& o, int argc, char** argv) {
  namespace fs = std::filesystem;
  const PixelSize size = parse_size(o.size);
  const std::vector<const scenes::Scene*> selected = select_scenes(o.scene);
  const Comparison comparison = parse_comparison(o.compare, o.overrides);
  const std::vector<Variant> variants = comparison_variants(comparison, o.overrides);
  if (o.overlay && o.compare.empty()) {
    throw UsageError("--overlay draws the variants of --compare in one view; give --compare too "
                     "(e.g. --compare push --overlay)");
  }
  // The variants' panels in a grid of rows x columns that fills --size (one panel for
  // --overlay); each panel at least 16x16 pixels.
  const Grid grid = o.overlay ? Grid{1, 1}
                              : grid_layout(variants.size(), static_cast<double>(size.width) / size.height);
  const int panel_width = size.width / grid.columns;
  const int panel_height = size.height / grid.rows;
  if (panel_width < 16 || panel_height < 16) {
    throw UsageError("--size " + o.size + ": --compare " + o.compare + " lays " +
                     std::to_string(variants.size()) + " panels out as " +
                     std::to_string(grid.rows) + " x " + std::to_string(grid.columns) + ", each " +
                     std::to_string(panel_width) + "x" + std::to_string(panel_height) +
                     " pixels; a panel needs at least 16x16: give a larger --size");
  }
  struct Job {
    const scenes::Scene* scene;
    std::vector<scenes::Run> runs;
    std::vector<std::string> labels;  // per variant: its caption's label
    std::pair<int, int> scene_px;     // the scene's size in each panel (frame_layout)
    nlohmann::json panels_px = nlohmann::json::array();  // each panel's [x, y, width, height] in a frame
    DrawStyle style;                  // the same camera for the whole sequence
  };
  std::vector<Job> jobs;
  for (const scenes::Scene* s : selected) {
    Job job{s, {}, {}, {}, nlohmann::json::array(), {}};
    for (const Variant& v : variants) {
      job.runs.push_back(make_run_or_usage_error(*s, v.overrides));
      // --overlay: the legend names the variants; the label, the scene (with --label).
      std::string label = o.overlay ? "" : v.label;
      if (o.label) label = std::string(s->name) + (label.empty() ? "" : "\n" + label);
      job.labels.push_back(label);
    }
    jobs.push_back(std::move(job));
  }
  // --video: ffmpeg is looked for before rendering; without it the frames are still
  // rendered and kept, and the command ends with an error saying how to finish the video.
  std::optional<fs::path> ffmpeg;
  std::vector<VideoJob> videos_left;
  if (!o.video.empty()) {
    ffmpeg = find_on_path("ffmpeg");
    if (!ffmpeg) {
      std::fprintf(stderr,
                   "cps: warning: --video %s: ffmpeg is not on PATH; the frames will be "
                   "rendered and kept, but no video made (install it: apt-get install ffmpeg)\n",
                   o.video.c_str());
    }
  }
  // Every output folder is checked (foreign files, see output.h) before any is written.
  std::vector<RenderJob> specs;
  std::vector<OutputPlan> plans;
  for (Job& job : jobs) {
    RenderJob spec;
    spec.seconds = o.seconds.value_or(job.scene->default_seconds);
    spec.fps = o.fps;
    spec.speed = o.speed;
    spec.folder = fs::path(o.out) /
                  (std::string(job.scene->name) + comparison_suffix(comparison, o.overlay));
    spec.columns = grid.columns;
    spec.frame_width = panel_width * grid.columns;
    spec.frame_height = panel_height * grid.rows;
    spec.overlay = o.overlay;
    if (o.overlay) {
      spec.legend_heading = legend_heading(comparison);
      spec.legend = overlay_legend(variants);
    }
    // The work is bounded before anything is drawn or written: steps, frames and pixels.
    for (const scenes::Run& run : job.runs) {
      check_steps(std::string(job.scene->name), spec.seconds, run.world.def().dt);
    }
    const long long frames = frame_count(spec);
    if (static_cast<double>(frames) > kMaxFrames) {
      throw UsageError(std::string(job.scene->name) + ": " + std::to_string(frames) +
                       " frames (--seconds x --fps / --speed) is more than the " +
                       std::to_string(static_cast<long long>(kMaxFrames)) +
                       " frames a render may write; give fewer --seconds or a lower --fps");
    }
    const double pixel_bytes = static_cast<double>(frames) * size.width * size.height * 3.0;
    if (pixel_bytes > kMaxPixelBytes) {
      throw UsageError(std::string(job.scene->name) + ": " + std::to_string(frames) + " frames of " +
                       o.size + " pixels is " + std::to_string(static_cast<long long>(pixel_bytes / 1073741824.0)) +
                       " GiB of pixels, more than the 64 GiB a render may draw; give fewer frames "
                       "or a smaller --size");
    }
    // The caption strips (labels, time, legend) lie outside the scene: what they leave of each
    // panel is where the scene is drawn.
    const PageLayout frame = frame_layout(spec, job.labels);
    job.scene_px = {frame.panels.front().width, frame.panels.front().height};
    for (std::size_t k = 0; k < (o.overlay ? 1 : variants.size()); ++k) {  // not a grid's empty cells
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
    std::vector<const World*> worlds;
    for (const scenes::Run& run : job.runs) worlds.push_back(&run.world);
    job.style = resolve_style(*job.scene, worlds, o.view,
                              static_cast<float>(job.scene_px.first) / static_cast<float>(job.scene_px.second),
                              spec.seconds);
    std::vector<std::string> files;
    files.reserve(static_cast<std::size_t>(frames));
    for (long long k = 0; k < frames; ++k) files.push_back(frame_name(k));
    plans.push_back(plan_output(spec.folder, std::move(files), o.force));
    specs.push_back(spec);
  }
  // --video: the videos go to OUT/, beside the frames folders, which holds other files too
  // (other scenes' videos, whatever the user keeps there): only the videos are checked.
  std::optional<OutputPlan> video_plan;
  nlohmann::json video_info;
  if (!o.video.empty()) {
    std::vector<std::string> names;
    nlohmann::json folders = nlohmann::json::array();
    for (const RenderJob& spec : specs) {
      names.push_back(spec.folder.filename().string() + "." + o.video);
      folders.push_back(spec.folder.filename().string());
    }
    video_plan = plan_output(fs::path(o.out), names, o.force, FolderUse::shared);
    video_info = run_info("render", argc, argv,
                          {{"video", o.video}, {"fps", o.fps}, {"frames_folders", folders}});
  }
  // One renderer at the scene's size; another only when a scene's captions leave it another
  // size (--label with scene names of more lines).
  std::optional<render::Renderer> renderer;
  // Encoding overlaps drawing: one encoder thread keeps up with llvmpipe (see cps bench). Each
  // frame is written atomically under the output rule (output.h).
  render::PngWriter writer(
      [](const fs::path& path, std::span<const std::uint8_t> bytes) { write_file_atomic(path, bytes); },
      1, 3);
  if (video_plan && ffmpeg) begin_output(*video_plan, video_info);
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    Job& job = jobs[j];
    const RenderJob& spec = specs[j];
    if (!renderer || renderer->width() != job.scene_px.first || renderer->height() != job.scene_px.second) {
      renderer.reset();
      renderer.emplace(job.scene_px.first, job.scene_px.second, *render::parse_backend(o.backend));
      std::fprintf(stderr, "render: %s\n", renderer->context_description().c_str());
    }
    std::vector<Panel> panels;
    nlohmann::json world = nlohmann::json::array();
    for (std::size_t v = 0; v < variants.size(); ++v) {
      panels.push_back({&job.runs[v], job.labels[v]});
      world.push_back({{"label", variants[v].label},
                       {"overlay_colour_srgb", o.overlay ? nlohmann::json(overlay_colour(v))
                                                         : nlohmann::json(nullptr)},
                       {"overrides", overrides_json(variants[v].overrides)},
                       {"parameters", parameters_json(job.runs[v].world.def())}});
    }
    nlohmann::json spacing_notes = nlohmann::json::array();
    for (const scenes::Run& run : job.runs) {
      const std::string note = frame_spacing_note(spec, run.world.def().dt);
      if (note.empty()) continue;
      std::fprintf(stderr, "cps: note: %s: %s\n", job.scene->name.data(), note.c_str());
      spacing_notes.push_back(note);
    }
    const Overlays& overlays = o.view.overlays;
    const nlohmann::json info = run_info(
        "render", argc, argv,
        {{"scene", job.scene->name},
         {"seconds", spec.seconds},
         {"fps", spec.fps},
         {"speed", spec.speed},
         {"frame_spacing_s", spec.speed / spec.fps},
         {"frame_times", spacing_notes.empty() ? nlohmann::json("exact multiples of the physics step")
                                               : nlohmann::json(spacing_notes)},
         {"frames", frame_count(spec)},
         {"size", {{"width", size.width}, {"height", size.height}}},
         {"compare", comparison_json(comparison, o.overlay)},
         {"layout", o.overlay ? nlohmann::json{{"overlay", true},
                                               {"frame_px", {spec.frame_width, spec.frame_height}},
                                               {"panels_px", job.panels_px}}
                              : nlohmann::json{{"rows", grid.rows},
                                               {"columns", grid.columns},
                                               {"frame_px", {spec.frame_width, spec.frame_height}},
                                               {"panels_px", job.panels_px}}},
         {"backend", o.backend},
         {"camera", o.view.camera},
         {"camera_resolved", camera_json(job.style.camera)},
         {"eye_m", o.view.eye ? nlohmann::json{o.view.eye->x(), o.view.eye->y(), o.view.eye->z()}
                              : nlohmann::json(nullptr)},
         {"target_m", o.view.target ? nlohmann::json{o.view.target->x(), o.view.target->y(), o.view.target->z()}
                                    : nlohmann::json(nullptr)},
         {"fov_y_deg", o.view.fov_y_deg ? nlohmann::json(*o.view.fov_y_deg) : nlohmann::json(nullptr)},
         {"orbit_deg_per_s", overlays.orbit_deg_per_s},
         {"contacts", overlays.contacts},
         {"rods", overlays.rods},
         {"label", o.label},
         {"overrides", overrides_json(o.overrides)},
         {"world", world}});
    begin_output(plans[j], info);
    Progress progress("render " + spec.folder.filename().string(), frame_count(spec), "frames");
    const long long frames = render_frames(job.style, panels, spec, *renderer, writer, &progress);
    end_output(plans[j], info);
    const std::string folder = spec.folder.filename().string();
    std::printf("%s: %lld frames in %s\n", folder.c_str(), frames, spec.folder.c_str());
    if (!o.video.empty()) {
      VideoJob video;
      video.format = *parse_video_format(o.video);
      video.frames_folder = spec.folder;
      video.frames = static_cast<int>(frames);  // at most kMaxFrames
      video.fps = o.fps;
      video.width = spec.frame_width;
      video.height = spec.frame_height;
      video.output = fs::path(o.out) / (folder + "." + o.video);
      if (!ffmpeg) {
        videos_left.push_back(video);
        continue;
      }
      encode_video(*ffmpeg, video);
      std::printf("%s: video %s (%ju bytes)\n", folder.c_str(), video.output.c_str(),
                  static_cast<std::uintmax_t>(fs::file_size(video.output)));
    }
  }
  if (video_plan && ffmpeg) end_output(*video_plan, video_info);
  if (!videos_left.empty()) {
    std::string how;
    for (const VideoJob& v : videos_left) {
      how += "\n  " + shell_command(ffmpeg_arguments("ffmpeg", v, v.output));
    }
    throw VideoError("--video " + o.video +
                     ": ffmpeg is not on PATH, so no video was made; install it "
                     "(apt-get install ffmpeg). The frames are kept; to assemble them "
                     "without rendering again, run:" + how);
  }
  return 0;
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
                  "frames per second of video, in (0, 1000]; frames are --speed / --fps "
                  "simulated seconds apart (so with --speed 1, frames per simulated second)")
      ->capture_default_str()
      ->check(decimal_in(0.0, kMaxFps, true, "frames/s"));
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
                  "PARAM=V1,V2,...: render 2 to 6 values of a world parameter (" + comparable_list() +
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
  add_world_options(*sub, o->overrides);
  sub->add_option("--backend", o->backend,
                  "OpenGL context: osmesa (libOSMesa, CPU) or egl (headless EGL: GPU if any, "
                  "else llvmpipe)")
      ->capture_default_str()
      ->check(CLI::IsMember({"osmesa", "egl"}));
  sub->add_option("--video", o->video,
                  "after the frames, assemble them with ffmpeg into OUT/SCENE.mp4 (H.264) or "
                  "OUT/SCENE.gif")
      ->check(CLI::IsMember({"mp4", "gif"}));
  add_view_options(*sub, o->view, o->label, /*label_default=*/false);
  return {sub, [o, argc, argv] { return run_render(*o, argc, argv); }};
}

}  // namespace cps::cli
