#pragma once
// The page of a `cps figure`: rendered panels laid out in a grid, each with a caption strip
// below it (sub-figure letter, time, variant), a title strip above the grid and, for --overlay,
// a legend strip below it, all composed with cairo. The same drawing code writes a PNG (a cairo
// image surface whose pixels go through cps's own PNG writer, render::encode_png), a PDF
// (cairo_pdf_surface) or an SVG (cairo_svg_surface); in PDF and SVG the panels are embedded
// images of the rendered pixels and every label is vector text in DejaVu Sans, so a figure goes
// into LaTeX as it is. Text never covers a panel: the strips lie outside the panels.
//
// Units: one pixel of a panel is one point (1/72 in) of the PDF or SVG page.

#include "cps/render/renderer.h"

#include <array>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cps::cli {

/// The file format of a figure (--format).
enum class FigureFormat { png, pdf, svg };

/// Parses --format: "png", "pdf" or "svg". Throws UsageError "--format X: allowed are png, pdf,
/// svg" otherwise.
FigureFormat parse_figure_format(std::string_view text);

/// The file name extension of `format`, with the dot (".png", ".pdf", ".svg").
std::string_view figure_extension(FigureFormat format);

/// A panel's time as its caption says it: "t = 1.25 s" (t in s), with the fewest decimals, at
/// least 2 and at most 9, whose last place is at most a tenth of `spacing` (s, > 0: the time
/// between frames or panels), so that neighbours print apart and near their value (frames 1/60 s
/// apart: "t = 0.017 s", "t = 0.033 s"). No errors.
std::string time_caption(double t, double spacing = 0.01);

/// One panel of a figure page: the rendered scene and its caption.
struct PagePanel {
  /// panel_width x panel_height pixels (RGB8); null: an empty cell, left white (a grid the
  /// panels do not fill), or a page laid out before its panels are drawn.
  const render::Image* image = nullptr;
  std::string letter;                    ///< sub-figure letter, e.g. "(a)"; none if empty
  std::string text;                      ///< caption after the letter; lines split at '\n'
};

/// One entry of an overlay's legend: a colour swatch (sRGB, each in [0, 1]) and its text.
struct PageLegendEntry {
  std::array<float, 3> srgb{};
  std::string text;
};

/// What a figure page holds. panels.size() == rows * columns, in reading order (row by row).
struct FigurePage {
  int rows = 1;
  int columns = 1;
  int panel_width = 640;   ///< px, > 0
  int panel_height = 360;  ///< px, > 0
  std::vector<PagePanel> panels;
  /// With labels: the title strip above the grid (if not empty), the caption strips below the
  /// panels and the white gutters between panels. Without labels the panels abut as one grid
  /// and only a legend (if any) is added below.
  bool labels = true;
  std::string title;
  std::string legend_heading;
  std::vector<PageLegendEntry> legend;  ///< empty: no legend strip
  /// Font size of every label (px = pt); 0: max(10, panel_height / 24). A video frame gives its
  /// own (from the frame's height), so that its text does not depend on the panels it sizes.
  double font_size = 0.0;
  /// The page's size in pixels; 0: what the layout needs. A video frame gives --size: the grid
  /// keeps its place at the top left and the spare pixels (fewer than a panel per row or column,
  /// see fit_panels) stay white at the right and bottom. Must not be smaller than the layout
  /// needs (layout_page throws).
  int width = 0;
  int height = 0;
};

/// Where each part of a composed page lies, in pixels (points in PDF and SVG) from the top left.
struct PageLayout {
  int width = 0;
  int height = 0;
  /// Font size of every label (px = pt): max(10, panel_height / 24), so a 640x360 panel's
  /// captions are 15 px tall, about 1/24 of the panel, and never below 10 pt.
  double font_size = 10.0;
  struct Rect {
    int x = 0;
    int y = 0;
    int width = 0;
    int height = 0;
  };
  std::vector<Rect> panels;  ///< one per panel, in reading order; exactly the panel's pixels
  /// Height (px) of every caption strip, right below its panel; 0 without labels. A caption's
  /// text is clipped to its strip.
  int caption_height = 0;
};

/// The layout of `page` (text measured with cairo in DejaVu Sans): the caption strips all have
/// the height of the longest caption after wrapping to the panel width, so the grid is regular.
/// Throws std::invalid_argument if panels.size() != rows * columns, a panel's image (if set) is
/// not panel_width x panel_height, or page.width / page.height is set and smaller than needed.
PageLayout layout_page(const FigurePage& page);

/// The largest panel size {width, height} (px) with which `page` is at most width x height
/// pixels: the gutters, the title, the caption strips (their text wrapped to that panel width
/// and measured as layout_page does) and the legend take what they need, and the panels share
/// the rest equally. The page's panel size and images are not read; its font size must be set
/// (page.font_size > 0), since the default font follows the panel height. Either value may be
/// <= 0 when the text leaves no room: the caller refuses that. Throws std::invalid_argument if
/// page.font_size <= 0 or rows or columns < 1.
std::pair<int, int> fit_panels(const FigurePage& page, int width, int height);

/// Composes `page` as a file of `format` (the bytes to write) laid out as layout_page says.
/// PNG: the page's pixels encoded by render::encode_png (RGB8, white background). PDF, SVG:
/// one page of layout.width x layout.height points, the panels as embedded images, the text as
/// text. Throws std::runtime_error if cairo fails.
std::string compose_page(const FigurePage& page, FigureFormat format, const PageLayout& layout);

/// Opens cairo (libcairo.so.2, or the file CPS_CAIRO_LIBRARY names, with dlopen) if it is not
/// open yet: the functions above open it when they first need it; a command calls this before it
/// writes anything, so that a machine without cairo gets the error before any output. Throws
/// std::runtime_error naming the library when it cannot be opened or lacks a function.
void open_cairo();

/// The page's pixels as composed for PNG (for tests and for the PNG path of compose_page).
render::Image compose_page_pixels(const FigurePage& page, const PageLayout& layout);

}  // namespace cps::cli
