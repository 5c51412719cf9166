#pragma once
// `cps figure`: one labelled figure (PNG, PDF or SVG, see compose.h) of a scene at chosen
// times (columns) for each variant of an option (rows), like the paper's Fig. 7; and the counterparts of the paper's
// Figs. 6-10 (`cps figure paper`). The command itself is add_figure in command.h.

#include "pictures/compose.h"
#include "pictures/draw.h"
#include "options/options.h"
#include "scene.h"

#include "cps/render/renderer.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace cps::cli {

/// What one figure shows.
struct FigureSpec {
  const scenes::Scene* scene = nullptr;
  /// Simulated times of the columns (s): finite, >= 0, strictly increasing (see parse_times).
  std::vector<double> times;
  /// The rows: one run of the scene per variant (compare_variants gives them).
  std::vector<Variant> variants;
  /// The parsed --compare the variants come from (its legend heading, and the sidecar's
  /// "comparison"); no parameter for one row.
  Comparison comparison;
  /// --overlay: one row, every variant drawn in each panel as a ghost (overlay_draw_list) with
  /// a legend in the bottom-left corner, instead of a row per variant.
  bool overlay = false;
  /// Size of one panel in pixels (each in [16, 8192]); the figure is
  /// (times.size() * panel_width) x (variants.size() * panel_height).
  int panel_width = 640;
  int panel_height = 360;
  /// The camera (the same for every panel, turned by the orbit overlay), the preset that
  /// replaces the scene's own if set, and the overlays.
  View view;
  /// Labels in strips outside the panels (compose.h): a title above the grid (caption: scene),
  /// and below each panel its sub-figure letter ((a), (b), ... in reading order, row by row, on
  /// every panel of a figure of more than one panel), its time and its variant's label.
  bool label = true;
  /// The title's first part (e.g. "paper Fig. 7 counterpart"); the title is the scene alone if empty.
  std::string caption;
  /// The file format (--format).
  FigureFormat format = FigureFormat::png;
  /// The --compare option the rows come from ("" for one row); recorded in the sidecar.
  std::string compare;
  /// What the figure shows, in one sentence (recorded in the sidecar as "shows"); may be empty.
  std::string what;
};

/// Parses "t1,t2,..." (s). Throws UsageError naming the bad entry and what is allowed if an
/// entry is not a number, not finite, negative, beyond 36000 s, or not greater than the one
/// before it, or if an entry is empty or there are more than 64.
std::vector<double> parse_times(const std::string& text);

/// A figure ready to compose: the rendered panels, the page that points at them (so it is not
/// copied) and its layout.
struct ComposedFigure {
  std::vector<render::Image> panels;
  FigurePage page;
  PageLayout layout;
  ComposedFigure() = default;
  ComposedFigure(const ComposedFigure&) = delete;
  ComposedFigure& operator=(const ComposedFigure&) = delete;
  ComposedFigure(ComposedFigure&&) = default;  // the panels' buffers move with them
};

/// The sub-figure letter of panel k (0-based, reading order): "(a)" ... "(z)", "(aa)", ...
std::string subfigure_letter(std::size_t k);

/// Steps one run per variant through the times and draws every panel: row r, column c is the
/// variant r at times[c] (with spec.overlay, one row whose panel c holds every variant at
/// times[c], and the legend in a strip below). The panels have a 1-pixel dark border (inside
/// the panel, so the size is exact). Throws UsageError for a bad parameter or camera name,
/// std::runtime_error from the renderer. `renderer` must be spec.panel_width x spec.panel_height.
/// A run whose energy rose with nothing driving it gets a warning on stderr
/// (scenes::run_warnings, over [0, last time]; printed by warn, options/diagnostics.h).
ComposedFigure render_figure(const FigureSpec& spec, render::Renderer& renderer);

/// The sidecar of `png`, which records how it was made (figure_json): png with ".json" appended.
std::filesystem::path sidecar_path(const std::filesystem::path& png);

/// The sidecar's content: run_info("figure", argc, argv, parameters) (command line, engine
/// version, UTC date; see output.h) with "written_by": "cps figure", where the parameters are
/// scene, compare, comparison (comparison_json), caption, times_s, layout, grid, format,
/// panel_size_px, image_size_px (of the page, `layout`), panels_px (each panel's letter and
/// rectangle in the page), font, camera, overlays and the variants (label, overlay colour and
/// world parameters with units).
nlohmann::json figure_json(const FigureSpec& spec, const PageLayout& layout, int argc, char** argv);

/// Writes the figure's bytes (compose_page) and its sidecar (indented JSON), each to a temporary
/// of this run (AtomicFile), and renames the sidecar only after the figure: a failed write (a
/// full disk) leaves neither new file and no temporary, never a sidecar without its figure. The
/// folder must exist (begin_output creates it; the caller checked both files with plan_output
/// first). Throws std::runtime_error "cannot write PATH: REASON" on failure.
void write_figure(const std::filesystem::path& file, const std::string& bytes,
                  const nlohmann::json& sidecar);

/// A counterpart of one of the paper's result figures (Sec. 10, Figs. 6-10).
struct PaperFigure {
  std::string file;     ///< e.g. "fig7_intersecting_stack" (the format's extension is added)
  std::string caption;  ///< e.g. "paper Fig. 7"
  std::string scene;
  std::string compare;  ///< "" or a compare_variants option
  std::vector<double> times;  ///< s
  std::optional<scenes::CameraPreset> preset;  ///< replaces the scene's camera preset if set
  std::string what;     ///< one sentence: what the paper's figure shows and what to look for
};

/// The five figures `cps figure paper` writes, in the paper's order.
const std::vector<PaperFigure>& paper_figures();

}  // namespace cps::cli
