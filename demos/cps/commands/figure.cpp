#include "commands/figure.h"

#include "command.h"
#include "output/atomic_file.h"
#include "output/output.h"
#include "pictures/overlay.h"
#include "options/view_options.h"
#include "energy_rise.h"
#include "options/diagnostics.h"

#include "cps/render/image_ops.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <system_error>

namespace cps::cli {
namespace fs = std::filesystem;

std::vector<double> parse_times(const std::string& text) {
  constexpr std::size_t kMaxTimes = 64;
  constexpr double kMaxTime = kMaxSeconds;
  std::vector<double> times;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    std::string entry = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    entry.erase(0, entry.find_first_not_of(" \t"));
    entry.erase(entry.find_last_not_of(" \t") + 1);
    const std::string quoted = "'" + entry + "'";
    if (entry.empty()) {
      throw UsageError("--times " + text + ": an empty entry; give times in seconds separated by "
                       "commas, e.g. --times 0,0.5,2");
    }
    const std::optional<double> parsed = parse_decimal(entry, /*allow_fraction=*/true);
    if (!parsed) {
      throw UsageError("--times: " + quoted + " is not a decimal number or fraction; give times "
                       "in seconds, e.g. --times 0,0.5,2 or 0,1/60,1/30");
    }
    const double t = *parsed;
    if (!std::isfinite(t)) {
      throw UsageError("--times: " + quoted + " is not finite; times are finite seconds >= 0");
    }
    if (t < 0.0) throw UsageError("--times: " + quoted + " is negative; times are seconds >= 0");
    if (t > kMaxTime) {
      throw UsageError("--times: " + quoted + " is beyond " + std::to_string(static_cast<int>(kMaxTime)) +
                       " s of simulated time; give shorter times");
    }
    if (!times.empty() && !(t > times.back())) {
      char before[64];
      std::snprintf(before, sizeof before, "%g", times.back());
      throw UsageError("--times: " + quoted + " is not greater than the time before it (" +
                       before + " s); list the times in increasing order");
    }
    times.push_back(t);
    if (times.size() > kMaxTimes) {
      throw UsageError("--times: more than " + std::to_string(kMaxTimes) + " times; give fewer");
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return times;
}

namespace {

// A 1-pixel dark frame along the edges of the image, so neighbouring panels stay apart.
void draw_border(render::Image& image) {
  const auto set = [&image](int x, int y) {
    const std::size_t i = 3u * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                                static_cast<std::size_t>(x));
    image.pixels[i] = image.pixels[i + 1] = image.pixels[i + 2] = 40;
  };
  for (int x = 0; x < image.width; ++x) {
    set(x, 0);
    set(x, image.height - 1);
  }
  for (int y = 0; y < image.height; ++y) {
    set(0, y);
    set(image.width - 1, y);
  }
}

}  // namespace

std::string subfigure_letter(std::size_t k) {
  std::string letters;
  std::size_t n = k;
  do {
    letters.insert(letters.begin(), static_cast<char>('a' + n % 26));
    n = n / 26;
  } while (n-- > 0);
  return "(" + letters + ")";
}

namespace {

// The smallest gap (s) between two of the figure's times, for the decimals of their captions;
// 0.1 s (two decimals) for one time.
double time_spacing(const std::vector<double>& times) {
  double spacing = 0.1;
  for (std::size_t k = 1; k < times.size(); ++k) {
    spacing = k == 1 ? times[1] - times[0] : std::min(spacing, times[k] - times[k - 1]);
  }
  return spacing;
}

}  // namespace

ComposedFigure render_figure(const FigureSpec& spec, render::Renderer& renderer) {
  const scenes::Scene& scene = *spec.scene;
  std::vector<scenes::Run> runs;
  std::vector<std::shared_ptr<const scenes::EnergyRiseTracker>> energy;  // per variant
  for (const Variant& v : spec.variants) {
    runs.push_back(make_run_or_usage_error(scene, v.overrides));
    energy.push_back(scenes::watch_energy_rise(runs.back()));
  }

  const float aspect = static_cast<float>(renderer.width()) / static_cast<float>(renderer.height());
  std::vector<const World*> worlds;
  for (const scenes::Run& run : runs) worlds.push_back(&run.world);
  View view = scene_view(scene, spec.view);
  view.one_picture = spec.overlay;
  const DrawStyle style = resolve_style(scene, worlds, view, aspect, spec.times.back());

  ComposedFigure out;
  FigurePage& page = out.page;
  page.columns = static_cast<int>(spec.times.size());
  page.rows = spec.overlay ? 1 : static_cast<int>(runs.size());
  page.panel_width = renderer.width();
  page.panel_height = renderer.height();
  page.labels = spec.label;
  page.title = spec.caption.empty() ? std::string(scenes::output_name(scene))
                                    : spec.caption + ": " + std::string(scenes::output_name(scene));
  std::vector<std::string> texts;
  // Reading order: row by row, each row left to right in time.
  if (spec.overlay) {
    for (std::size_t c = 0; c < spec.times.size(); ++c) {
      for (scenes::Run& run : runs) run.advance_to(spec.times[c]);
      render::Image panel = renderer.draw(overlay_draw_list(worlds, style));
      draw_border(panel);
      out.panels.push_back(std::move(panel));
      texts.push_back(time_caption(runs.front().world.time(), time_spacing(spec.times)));
    }
    // The legend even without labels: without it the colours mean nothing. It has a strip of
    // its own below the panels.
    page.legend_heading = legend_heading(spec.comparison);
    page.legend = overlay_legend(spec.variants);
  } else {
    for (std::size_t r = 0; r < runs.size(); ++r) {
      for (std::size_t c = 0; c < spec.times.size(); ++c) {
        runs[r].advance_to(spec.times[c]);
        render::Image panel = renderer.draw(draw_list(runs[r].world, style, r));
        draw_border(panel);
        out.panels.push_back(std::move(panel));
        std::string text = time_caption(runs[r].world.time(), time_spacing(spec.times));
        if (!spec.variants[r].label.empty()) text += "\n" + spec.variants[r].label;
        texts.push_back(text);
      }
    }
  }
  for (std::size_t r = 0; r < runs.size(); ++r) {
    for (const scenes::RunWarning& w :
         scenes::run_warnings(scene.name, spec.variants[r].label, runs[r], *energy[r])) {
      warn(w.kind, w.text, w.brief, w.docs);
    }
  }
  const bool lettered = out.panels.size() > 1;
  for (std::size_t k = 0; k < out.panels.size(); ++k) {
    page.panels.push_back({&out.panels[k], lettered ? subfigure_letter(k) : std::string(), texts[k]});
  }
  out.layout = layout_page(page);
  return out;
}

fs::path sidecar_path(const fs::path& png) {
  fs::path p = png;
  p += ".json";
  return p;
}

nlohmann::json figure_json(const FigureSpec& spec, const PageLayout& layout, int argc, char** argv) {
  nlohmann::json variants = nlohmann::json::array();
  for (std::size_t k = 0; k < spec.variants.size(); ++k) {
    const Variant& v = spec.variants[k];
    variants.push_back({{"label", v.label},
                        {"overlay_colour_srgb", spec.overlay ? nlohmann::json(overlay_colour(k))
                                                             : nlohmann::json(nullptr)},
                        {"parameters", parameters_json(scenes::world_def_with(*spec.scene, v.overrides))}});
  }
  const int columns = static_cast<int>(spec.times.size());
  const int rows = spec.overlay ? 1 : static_cast<int>(spec.variants.size());
  const std::optional<scenes::CameraPreset>& preset = spec.view.preset;
  // Where each panel's scene pixels lie in the page (x, y, width, height), in reading order,
  // with its sub-figure letter.
  nlohmann::json panels = nlohmann::json::array();
  for (std::size_t k = 0; k < layout.panels.size(); ++k) {
    const PageLayout::Rect& r = layout.panels[k];
    panels.push_back({{"letter", layout.panels.size() > 1 ? subfigure_letter(k) : std::string()},
                      {"rect", {r.x, r.y, r.width, r.height}}});
  }
  const nlohmann::json parameters = {
          {"scene", spec.scene->name},
          {"compare", spec.compare},
          {"comparison", comparison_json(spec.comparison, spec.overlay)},
          {"caption", spec.caption},
          {"shows", spec.what},
          {"times_s", spec.times},
          {"layout", spec.overlay ? "one row, every variant as a ghost in each panel, columns = times"
                                  : "rows = variants, columns = times"},
          {"panel_size_px", {spec.panel_width, spec.panel_height}},
          {"grid", {{"rows", rows}, {"columns", columns}}},
          {"format", std::string(figure_extension(spec.format).substr(1))},
          {"image_size_px", {layout.width, layout.height}},
          {"panels_px", panels},
          {"font", {{"family", "DejaVu Sans"}, {"size_px", layout.font_size},
                    {"rule", "max(10, panel height / 24) px; 1 px = 1 pt in PDF and SVG"}}},
          {"camera", scene_view(*spec.scene, spec.view).camera},
          {"camera_preset",
           preset ? nlohmann::json{{"eye_m", {preset->eye.x(), preset->eye.y(), preset->eye.z()}},
                                   {"target_m", {preset->target.x(), preset->target.y(), preset->target.z()}},
                                   {"fov_y_deg", preset->fov_y_deg}}
                  : nlohmann::json("the scene's")},
          {"eye_m", spec.view.eye ? nlohmann::json{spec.view.eye->x(), spec.view.eye->y(), spec.view.eye->z()}
                                  : nlohmann::json(nullptr)},
          {"target_m", spec.view.target ? nlohmann::json{spec.view.target->x(), spec.view.target->y(), spec.view.target->z()}
                                        : nlohmann::json(nullptr)},
          {"fov_y_deg", spec.view.fov_y_deg ? nlohmann::json(*spec.view.fov_y_deg) : nlohmann::json(nullptr)},
          {"overlays",
           {{"contacts", spec.view.overlays.contacts},
            {"velocities", spec.view.overlays.velocities},
            {"forces", spec.view.overlays.forces},
            {"rods", spec.view.overlays.rods},
            {"orbit_deg_per_s", spec.view.overlays.orbit_deg_per_s},
            {"label", spec.label}}},
          {"variants", variants}};
  nlohmann::json sidecar = run_info("figure", argc, argv, parameters);
  sidecar["written_by"] = "cps figure";
  return sidecar;
}

void write_figure(const fs::path& file, const std::string& bytes, const nlohmann::json& sidecar) {
  // Both written out and closed (hand_over) before either is renamed, the figure first: no
  // sidecar without its figure.
  AtomicFile figure(file);
  figure.write(bytes);
  figure.hand_over();
  AtomicFile record(sidecar_path(file));
  record.write(sidecar.dump(2) + "\n");
  record.hand_over();
  figure.commit();
  record.commit();
}

const std::vector<PaperFigure>& paper_figures() {
  static const std::vector<PaperFigure> figures = {
      {"fig6_stack", "paper Fig. 6", "stack", "", {0.0, 1.0, 10.0, 85.0}, std::nullopt,
       "the stack test: five cubes dropped 0.6 m apart land and stand; the paper's stack falls "
       "after about 85 s, so the last column is t = 85 s"},
      // The paper's two: the original push factor and the single frame push factor (a bare
      // "push" compares every push method of the engine).
      {"fig7_intersecting_stack", "paper Fig. 7", "intersecting_stack", "push=baumgarte,split",
       {0.0, 0.5, 1.0},
       // The --camera fit framing of the original push factor's run over the figure's 1 s
       // (rounded; the single frame run stays inside it): the cubes it throws up stay in view
       // in every panel (from the earlier (15, 17, 36) the top cube left the 1 s panel).
       scenes::CameraPreset{Vec3(22.5, 25.0, 49.0), Vec3(0.6, 17.3, 0.3), 45.0},
       "the paper's (a) intersecting start is our (a) and (d); its (b), the original push factor "
       "at 0.5 s, is our (b): the cubes fly apart; its (c), the single frame push factor at 0.5 s, "
       "is our (e): the cubes stop once the overlap is gone"},
      {"fig8_funnel", "paper Fig. 8", "funnel", "", {0.0, 0.6, 1.5, 10.0}, std::nullopt,
       "20 balls poured into a funnel of 4 planes come to rest"},
      {"fig9_pendulum_grid", "paper Fig. 9", "pendulum_grid", "", {0.0, 2.0, 10.0},
       std::nullopt, "a 5 x 5 grid of pendulums holds the shapes resting on top"},
      {"fig10_pendulum_wave", "paper Fig. 10", "pendulum_wave", "",
       {0.0, 5.0, 15.0, 30.0, 60.0},
       // From above (tilted 3 degrees): the pendulums swing in the y-z plane, so the wave shows as the
       // line of balls snaking across the picture. Close enough that the 2.45 m line spans about
       // 85 % of a 16:9 panel's width (it spanned 64 % from 2.6 m); the swing (about +-0.1 m in
       // z) is what sets the band's height.
       scenes::CameraPreset{Vec3(1.225, 2.7, 0.1), Vec3(1.225, 0.75, 0.0), 45.0},
       "50 pendulums of varied length: the wave-like procession, realigned after the 60 s cycle"},
  };
  return figures;
}

namespace {

// The options of `cps figure`.
struct FigureOptions {
  std::string scene;
  std::string times;  // "t1,t2,..." (s)
  std::string compare;
  bool overlay = false;
  std::string size = "640x360";
  std::string out;
  std::string format;  // "" : from --out's extension, else png
  bool force = false;
  scenes::Overrides overrides;
  View view;  // --camera, --contacts, --rods, --orbit
  bool label = true;
  std::string backend = "auto";
  double max_work = kDefaultMaxWork;  // body-iterations a run
};

// A figure as planned: what it shows and the file it goes to (its sidecar beside it).
struct PlannedFigure {
  FigureSpec spec;
  fs::path png;
};

// A figure run as planned: the panel size, the figures (five for 'paper', else one), their
// folder's plan (plan_output) and its run.json; everything checked, nothing written.
struct FigurePlan {
  PixelSize size;
  std::vector<PlannedFigure> figures;
  OutputPlan output;
  nlohmann::json info;
};

// What every figure of the run shares: the panel size, view, labels and format (png unless
// --format says; a scene's figure may take it from --out's extension).
FigureSpec base_spec(const FigureOptions& o, const PixelSize& size, std::optional<FigureFormat> format,
                     const scenes::Scene* scene) {
  FigureSpec spec;
  spec.scene = scene;
  spec.panel_width = size.width;
  spec.panel_height = size.height;
  spec.view = o.view;
  spec.label = o.label;
  spec.format = format.value_or(FigureFormat::png);
  return spec;
}

// `cps figure paper`: the paper_figures, each with its own times, comparison and camera preset,
// into --out (default out/figures) as FILE.EXT. Throws UsageError if --times, --compare or
// --overlay is given.
std::vector<PlannedFigure> plan_paper_figures(const FigureOptions& o, const PixelSize& size,
                                              std::optional<FigureFormat> format) {
  if (!o.times.empty() || !o.compare.empty() || o.overlay) {
    throw UsageError("cps figure paper chooses its own --times, --compare and --overlay for "
                     "each figure; drop them, or name a scene (e.g. cps figure "
                     "intersecting_stack --times 0,0.5 --compare push)");
  }
  const fs::path folder = o.out.empty() ? fs::path("out/figures") : fs::path(o.out);
  std::vector<PlannedFigure> figures;
  for (const PaperFigure& f : paper_figures()) {
    FigureSpec spec = base_spec(o, size, format, select_scenes(f.scene).front());
    spec.times = f.times;
    spec.compare = f.compare;
    spec.comparison = parse_comparison(f.compare, o.overrides);
    spec.variants = comparison_variants(spec.comparison, o.overrides);
    spec.caption = f.caption + " counterpart";
    spec.view.preset = f.preset;
    spec.what = f.what;
    figures.push_back({spec, folder / (f.file + std::string(figure_extension(spec.format)))});
  }
  return figures;
}

// The file of a scene's figure. --out names the file, or the folder the figure goes into under
// its own name, NAME[-compare-...][-overlay].EXT (NAME: the scene's output_name, never a scene
// file's path as typed), as render's --out is a folder: a folder when it ends in '/', is one
// already or has no extension. Without --out: out/figures. Sets spec.format: --format, else the
// format a file's extension names (.pdf, .svg), else png. Throws UsageError if a file's extension
// is not the format's.
fs::path figure_file(const FigureOptions& o, std::optional<FigureFormat> format, FigureSpec& spec) {
  const fs::path out(o.out);
  std::error_code ec;
  const bool folder = o.out.empty() || o.out.back() == '/' || fs::is_directory(out, ec) ||
                      !out.has_extension();
  if (!format && !folder) {
    // No --format: the format --out's extension names.
    const std::string ext = out.extension().string();
    if (ext == ".pdf") format = FigureFormat::pdf;
    if (ext == ".svg") format = FigureFormat::svg;
  }
  spec.format = format.value_or(FigureFormat::png);
  const std::string ext(figure_extension(spec.format));
  const fs::path file =
      folder ? (o.out.empty() ? fs::path("out/figures") : out) /
                   (std::string(scenes::output_name(*spec.scene)) +
                    comparison_suffix(spec.comparison, o.overlay) + ext)
             : out;
  if (file.extension() != ext) {
    throw UsageError("--out " + file.string() + ": the figure is a " + ext.substr(1) +
                     " file (--format " + ext.substr(1) + "); give a name ending in " + ext +
                     (format ? "" : ", or --format pdf or svg for a name ending in .pdf or .svg"));
  }
  return file;
}

// `cps figure SCENE`: one figure of --times, a row per --compare variant (one with --overlay).
// Throws UsageError for a bad scene, 'all' or 'stress', no --times, --overlay without --compare,
// or a bad --times, --compare or --out.
PlannedFigure plan_scene_figure(const FigureOptions& o, const PixelSize& size,
                                std::optional<FigureFormat> format) {
  const std::vector<const scenes::Scene*> chosen = select_scenes(o.scene);
  if (o.scene == "all" || o.scene == "stress") {
    throw UsageError("figure takes one scene or 'paper', not '" + o.scene + "'");
  }
  if (o.times.empty()) {
    throw UsageError("--times is required: the simulated times (s) of the columns, e.g. "
                     "--times 0,0.5,2");
  }
  if (o.overlay && o.compare.empty()) {
    throw UsageError("--overlay draws the variants of --compare in one view; give --compare "
                     "too (e.g. --compare push --overlay)");
  }
  FigureSpec spec = base_spec(o, size, format, chosen.front());
  spec.times = parse_times(o.times);
  spec.compare = o.compare;
  spec.comparison = parse_comparison(o.compare, o.overrides);
  spec.variants = comparison_variants(spec.comparison, o.overrides);
  spec.overlay = o.overlay;
  fs::path file = figure_file(o, format, spec);
  return {spec, file};
}

// Bounds a figure's work before anything is written: each variant's physics steps to the last
// time (check_steps) and solver work (check_work, max_work in body-iterations), its view (an --eye on the target; "fit" frames as built here, so this costs
// no pre-run), and the panels' grid at most 16384 pixels a side (the caption strips add a few
// lines of text per row). Throws UsageError.
void check_figure_work(const PlannedFigure& p, const PixelSize& size, double max_work) {
  for (const Variant& v : p.spec.variants) {
    const scenes::Run run = make_run_or_usage_error(*p.spec.scene, v.overrides);
    check_steps(std::string(p.spec.scene->name), p.spec.times.back(), run.world.def().dt);
    check_work(std::string(p.spec.scene->name), run.world.bodies().size(), run.world.def(),
               p.spec.times.back(), max_work, lower_run_options(run.world.def(), "an earlier last --times"));
    resolve_style(*p.spec.scene, run.world, p.spec.view,
                  static_cast<float>(size.width) / static_cast<float>(size.height));
  }
  const long long w = static_cast<long long>(p.spec.times.size()) * size.width;
  const long long h = static_cast<long long>(p.spec.overlay ? 1 : p.spec.variants.size()) * size.height;
  if (w > 16384 || h > 16384) {
    throw UsageError("the figure would be " + std::to_string(w) + "x" + std::to_string(h) +
                     " pixels (more than 16384 on a side); give fewer --times or a "
                     "smaller --size");
  }
}

// Everything is checked (scene, times, size, variants, output files) before anything is
// rendered or written. Throws UsageError.
FigurePlan plan_figure(const FigureOptions& o, int argc, char** argv) {
  FigurePlan plan;
  plan.size = parse_size(o.size);
  std::optional<FigureFormat> format;
  if (!o.format.empty()) format = parse_figure_format(o.format);
  if (o.scene == "paper") {
    plan.figures = plan_paper_figures(o, plan.size, format);
  } else {
    plan.figures.push_back(plan_scene_figure(o, plan.size, format));
  }
  for (const PlannedFigure& p : plan.figures) check_figure_work(p, plan.size, o.max_work);
  // The figures' folder collects figures of many runs (output.h, FolderUse::shared): each PNG
  // and its sidecar are checked before anything is rendered.
  const fs::path folder = plan.figures.front().png.parent_path();
  std::vector<std::string> files;
  std::map<std::string, std::string> scenes;
  nlohmann::json names = nlohmann::json::array();
  for (const PlannedFigure& p : plan.figures) {
    files.push_back(p.png.filename().string());
    files.push_back(sidecar_path(p.png).filename().string());
    names.push_back(p.png.filename().string());
    scenes.emplace(files.end()[-2], scene_source(p.spec.scene->name));
    scenes.emplace(files.back(), scene_source(p.spec.scene->name));
  }
  plan.output = plan_output({.folder = folder,
                             .files = files,
                             .command = "figure",
                             .use = FolderUse::shared,
                             .scenes = std::move(scenes),
                             .force = o.force});
  plan.info = run_info("figure", argc, argv, {{"scene", o.scene}, {"figures", names}});
  return plan;
}

// Renders and writes each planned figure and its sidecar, printing its size. Throws
// std::runtime_error from the renderer or a write.
int execute_figure(const FigureOptions& o, const FigurePlan& plan, int argc, char** argv) {
  render::Renderer renderer(plan.size.width, plan.size.height, *render::parse_backend(o.backend));
  open_cairo();  // before any output: the page's captions and its PDF or SVG need it
  nlohmann::json info = plan.info;
  info["parameters"]["renderer"] = {{"backend", render::backend_name(renderer.backend())},
                                    {"context", renderer.context_description()}};
  begin_output(plan.output, info);
  for (const PlannedFigure& p : plan.figures) {
    const ComposedFigure figure = render_figure(p.spec, renderer);
    write_figure(p.png, compose_page(figure.page, p.spec.format, figure.layout),
                 figure_json(p.spec, figure.layout, argc, argv));
    std::printf("%s: %dx%d %s, %zu times x %zu variants (%s)\n", p.png.c_str(), figure.layout.width,
                figure.layout.height, p.spec.format == FigureFormat::png ? "pixels" : "points",
                p.spec.times.size(), p.spec.variants.size(), sidecar_path(p.png).filename().c_str());
  }
  end_output(plan.output, info);
  return 0;
}

int run_figure(const FigureOptions& o, int argc, char** argv) {
  const FigurePlan plan = plan_figure(o, argc, argv);
  return execute_figure(o, plan, argc, argv);
}

}  // namespace

Command add_figure(CLI::App& app, int argc, char** argv) {
  auto o = std::make_shared<FigureOptions>();
  CLI::App* sub = app.add_subcommand(
      "figure",
      "one labelled figure (PNG, PDF or SVG) of a scene: a panel per time (columns) and per "
      "variant (rows), each with a caption strip below it; "
      "'cps figure paper' writes the counterparts of the paper's Figs. 6-10");
  sub->add_option("scene", o->scene, "scene name (see 'cps list'), the path of a scene file (.json), or 'paper'")->required();
  add_seed_option(*sub, o->scene);
  sub->add_option("--times", o->times,
                  "simulated times of the columns (s), comma separated, finite, >= 0, "
                  "increasing, decimals or fractions, e.g. 0,0.5,2 or 0,1/60,1/30; required "
                  "except for 'paper'");
  sub->add_option("--compare", o->compare,
                  "PARAM=V1,V2,...: one row per value, 2 to 8 values of a world parameter (" +
                      comparable_list() + "), each checked as its own option is; a choice alone "
                      "(e.g. push) compares all its values (default: one row, the scene's "
                      "settings)")
      ->check(kNotEmpty);
  sub->add_flag("--overlay", o->overlay,
                "with --compare: one row, every variant drawn in each panel as a translucent "
                "ghost in its own colour, with a legend");
  sub->add_option("--size", o->size, "size of ONE panel, WxH in pixels, each in [16, 8192]")
      ->capture_default_str();
  sub->add_option("--out", o->out,
                  "output file, or a folder (ending in '/', an existing folder or a name without "
                  "an extension) that gets SCENE[-compare-PARAM[-VALUES]][-overlay].png (.pdf or "
                  ".svg as --format says); default out/figures/; for "
                  "'paper', "
                  "the folder (default out/figures); a FILE.json sidecar records the run, and the "
                  "folder's run.json lists the files cps wrote there")
      ->check(kNotEmpty);
  sub->add_option("--format", o->format,
                  "png (pixels), pdf or svg (the panels as embedded images, every label, "
                  "sub-figure letter and caption as text in DejaVu Sans: ready for LaTeX); "
                  "default: from --out's extension (.png, .pdf, .svg), else png")
      ->check(CLI::IsMember({"png", "pdf", "svg"}));
  sub->add_flag("--force", o->force,
                "replace the PNG, its sidecar or the folder's run.json although no earlier cps "
                "run wrote them (run.json lists the files cps wrote there); any other file in "
                "the folder is never touched");
  sub->add_option("--backend", o->backend,
                  "OpenGL context: osmesa (libOSMesa, CPU), egl (headless EGL: GPU if any, "
                  "else llvmpipe), or auto (osmesa where libOSMesa loads, else egl)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "osmesa", "egl"}));
  add_max_work_option(*sub, o->max_work);
  add_world_options(*sub, o->overrides);
  add_view_options(*sub, o->view, o->label, /*label_default=*/true);
  add_diagnostic_flags(*sub);
  return {sub, [o, argc, argv] { return run_figure(*o, argc, argv); }};
}

}  // namespace cps::cli
