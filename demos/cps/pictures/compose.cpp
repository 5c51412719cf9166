#include "pictures/compose.h"

#include "shared_library.h"
#include "usage_error.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <span>
#include <stdexcept>

namespace cps::cli {
namespace {

// cairo (libcairo.so.2, Debian's libcairo2) is opened with dlopen when a page is first measured or
// drawn, not linked: the commands that draw no page, and the Python module, then start without
// loading it and the libraries it pulls in (fontconfig, freetype, pixman, X11's; the time this
// saves a start: docs/benchmarks.md). Its functions are called through this table.
struct CairoLib {
  decltype(&::cairo_clip) clip;
  decltype(&::cairo_create) create;
  decltype(&::cairo_destroy) destroy;
  decltype(&::cairo_fill) fill;
  decltype(&::cairo_font_extents) font_extents;
  decltype(&::cairo_image_surface_create) image_surface_create;
  decltype(&::cairo_image_surface_get_data) image_surface_get_data;
  decltype(&::cairo_image_surface_get_stride) image_surface_get_stride;
  decltype(&::cairo_move_to) move_to;
  decltype(&::cairo_paint) paint;
  decltype(&::cairo_pdf_surface_create_for_stream) pdf_surface_create_for_stream;
  decltype(&::cairo_pdf_surface_set_metadata) pdf_surface_set_metadata;
  decltype(&::cairo_rectangle) rectangle;
  decltype(&::cairo_restore) restore;
  decltype(&::cairo_save) save;
  decltype(&::cairo_select_font_face) select_font_face;
  decltype(&::cairo_set_font_size) set_font_size;
  decltype(&::cairo_set_source_rgb) set_source_rgb;
  decltype(&::cairo_set_source_surface) set_source_surface;
  decltype(&::cairo_show_text) show_text;
  decltype(&::cairo_status) status;
  decltype(&::cairo_status_to_string) status_to_string;
  decltype(&::cairo_surface_destroy) surface_destroy;
  decltype(&::cairo_surface_finish) surface_finish;
  decltype(&::cairo_surface_flush) surface_flush;
  decltype(&::cairo_surface_mark_dirty) surface_mark_dirty;
  decltype(&::cairo_surface_status) surface_status;
  decltype(&::cairo_svg_surface_create_for_stream) svg_surface_create_for_stream;
  decltype(&::cairo_text_extents) text_extents;

  CairoLib() {
    const std::string what = "cairo";
    const std::string hint = " (Debian: libcairo2; it draws the figure page)";
    const analysis::detail::SharedLibrary lib =
        analysis::detail::open_shared_library("CPS_CAIRO_LIBRARY", "libcairo.so.2", what, hint);
    const auto load = [&](const char* name, auto& f) {
      analysis::detail::resolve_symbol(lib, name, what, hint, f);
    };
    load("cairo_clip", clip);
    load("cairo_create", create);
    load("cairo_destroy", destroy);
    load("cairo_fill", fill);
    load("cairo_font_extents", font_extents);
    load("cairo_image_surface_create", image_surface_create);
    load("cairo_image_surface_get_data", image_surface_get_data);
    load("cairo_image_surface_get_stride", image_surface_get_stride);
    load("cairo_move_to", move_to);
    load("cairo_paint", paint);
    load("cairo_pdf_surface_create_for_stream", pdf_surface_create_for_stream);
    load("cairo_pdf_surface_set_metadata", pdf_surface_set_metadata);
    load("cairo_rectangle", rectangle);
    load("cairo_restore", restore);
    load("cairo_save", save);
    load("cairo_select_font_face", select_font_face);
    load("cairo_set_font_size", set_font_size);
    load("cairo_set_source_rgb", set_source_rgb);
    load("cairo_set_source_surface", set_source_surface);
    load("cairo_show_text", show_text);
    load("cairo_status", status);
    load("cairo_status_to_string", status_to_string);
    load("cairo_surface_destroy", surface_destroy);
    load("cairo_surface_finish", surface_finish);
    load("cairo_surface_flush", surface_flush);
    load("cairo_surface_mark_dirty", surface_mark_dirty);
    load("cairo_surface_status", surface_status);
    load("cairo_svg_surface_create_for_stream", svg_surface_create_for_stream);
    load("cairo_text_extents", text_extents);
  }
};

// The table, opened on the first call (thread-safe; a failed open throws and is tried again on
// the next call): libcairo.so.2, or the file CPS_CAIRO_LIBRARY names. Throws std::runtime_error
// naming the library if it cannot be opened or lacks one of the functions.
const CairoLib& cairo() {
  static const CairoLib lib;
  return lib;
}

constexpr const char* kFont = "DejaVu Sans";
// Text colour (sRGB): near black, as a journal's captions.
constexpr double kInk = 0.08;

struct Metrics {
  double font = 10.0;    // font size (px = pt)
  double line = 12.5;    // baseline to baseline (px)
  int pad = 4;           // above and below the text of a strip (px)
  int gutter = 0;        // between panels and around the page (px)
};

Metrics metrics_of(const FigurePage& page) {
  Metrics m;
  m.font = page.font_size > 0.0 ? page.font_size : std::max(10.0, page.panel_height / 24.0);
  m.line = 1.25 * m.font;
  m.pad = static_cast<int>(std::lround(0.35 * m.font));
  m.gutter = page.labels ? static_cast<int>(std::lround(0.6 * m.font)) : 0;
  return m;
}

using CairoPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;
using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;

void set_font(cairo_t* cr, double size, bool bold) {
  cairo().select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo().set_font_size(cr, size);
}

double advance(cairo_t* cr, const std::string& text) {
  cairo_text_extents_t e;
  cairo().text_extents(cr, text.c_str(), &e);
  return e.x_advance;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t nl = text.find('\n', start);
    lines.push_back(text.substr(start, nl == std::string::npos ? std::string::npos : nl - start));
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
  return lines;
}

// `line` broken at spaces into lines no wider than `width` (px) in the current font, the first
// of them `first_indent` px shorter; a word wider than the width stays whole (and is clipped).
std::vector<std::string> wrap(cairo_t* cr, const std::string& line, double width, double first_indent) {
  std::vector<std::string> out;
  std::string current;
  std::size_t start = 0;
  while (start < line.size()) {
    std::size_t space = line.find(' ', start);
    if (space == std::string::npos) space = line.size();
    const std::string word = line.substr(start, space - start);
    start = space + 1;
    const std::string candidate = current.empty() ? word : current + " " + word;
    const double limit = width - (out.empty() ? first_indent : 0.0);
    if (!current.empty() && advance(cr, candidate) > limit) {
      out.push_back(current);
      current = word;
    } else {
      current = candidate;
    }
  }
  out.push_back(current);
  return out;
}

// A panel's caption as drawn: the letter (bold) leads the first line.
struct CaptionLines {
  std::string letter;
  double letter_advance = 0.0;
  std::vector<std::string> lines;
};

CaptionLines caption_lines(cairo_t* cr, const PagePanel& panel, const Metrics& m, double width) {
  CaptionLines c;
  c.letter = panel.letter;
  if (!c.letter.empty()) {
    set_font(cr, m.font, true);
    c.letter_advance = advance(cr, c.letter + " ");
  }
  set_font(cr, m.font, false);
  bool first = true;
  for (const std::string& line : split_lines(panel.text)) {
    for (const std::string& part : wrap(cr, line, width, first ? c.letter_advance : 0.0)) {
      c.lines.push_back(part);
    }
    first = false;
  }
  return c;
}

CairoPtr measuring_context(SurfacePtr& surface) {
  surface = SurfacePtr(cairo().image_surface_create(CAIRO_FORMAT_ARGB32, 1, 1),
                       cairo().surface_destroy);
  return CairoPtr(cairo().create(surface.get()), cairo().destroy);
}

// The height of every caption strip: the longest caption of `page` wrapped to panels `width`
// px wide, in lines (at least one), and its padding; 0 without labels.
int caption_height(cairo_t* cr, const FigurePage& page, const Metrics& m, int width) {
  if (!page.labels) return 0;
  std::size_t lines = 1;
  for (const PagePanel& p : page.panels) {
    lines = std::max(lines, caption_lines(cr, p, m, width - 2.0 * m.pad).lines.size());
  }
  return static_cast<int>(std::ceil(static_cast<double>(lines) * m.line + 2 * m.pad));
}

int title_height(cairo_t* cr, const FigurePage& page, const Metrics& m, double width) {
  if (!page.labels || page.title.empty()) return 0;
  set_font(cr, m.font, true);
  const std::size_t n = wrap(cr, page.title, width, 0.0).size();
  return static_cast<int>(std::ceil(static_cast<double>(n) * m.line + 2 * m.pad));
}

int legend_height(const FigurePage& page, const Metrics& m) {
  if (page.legend.empty()) return 0;
  return static_cast<int>(std::ceil(static_cast<double>(page.legend.size() + 1) * m.line + 2 * m.pad));
}

// Draws `text` with its first baseline at y (px).
void show(cairo_t* cr, double x, double y, const std::string& text) {
  cairo().move_to(cr, x, y);
  cairo().show_text(cr, text.c_str());
}

// The one drawing routine of every format.
void draw_page(cairo_t* cr, const FigurePage& page, const PageLayout& layout) {
  const Metrics m = metrics_of(page);
  cairo().set_source_rgb(cr, 1.0, 1.0, 1.0);
  cairo().paint(cr);
  set_font(cr, m.font, false);
  cairo_font_extents_t fe;
  cairo().font_extents(cr, &fe);
  const double ascent = fe.ascent;
  const double text_width = page.panel_width - 2.0 * m.pad;

  // The panels, pixel for pixel.
  for (std::size_t k = 0; k < page.panels.size(); ++k) {
    if (page.panels[k].image == nullptr) continue;  // an empty cell stays white
    const render::Image& im = *page.panels[k].image;
    SurfacePtr img(cairo().image_surface_create(CAIRO_FORMAT_RGB24, im.width, im.height),
                   cairo().surface_destroy);
    cairo().surface_flush(img.get());
    unsigned char* data = cairo().image_surface_get_data(img.get());
    const int stride = cairo().image_surface_get_stride(img.get());
    for (int y = 0; y < im.height; ++y) {
      auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
      for (int x = 0; x < im.width; ++x) {
        const std::size_t i = 3u * (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) +
                                    static_cast<std::size_t>(x));
        row[x] = (std::uint32_t{im.pixels[i]} << 16) | (std::uint32_t{im.pixels[i + 1]} << 8) |
                 std::uint32_t{im.pixels[i + 2]};
      }
    }
    cairo().surface_mark_dirty(img.get());
    const PageLayout::Rect& r = layout.panels[k];
    cairo().save(cr);
    cairo().set_source_surface(cr, img.get(), r.x, r.y);
    cairo().rectangle(cr, r.x, r.y, r.width, r.height);
    cairo().fill(cr);
    cairo().restore(cr);
  }
  if (cairo().status(cr) != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(std::string("cairo: ") + cairo().status_to_string(cairo().status(cr)));
  }

  cairo().set_source_rgb(cr, kInk, kInk, kInk);
  if (page.labels) {
    // Title strip above the grid.
    if (!page.title.empty()) {
      set_font(cr, m.font, true);
      double y = m.gutter + m.pad + ascent;
      for (const std::string& line : wrap(cr, page.title, layout.width - 2.0 * m.gutter, 0.0)) {
        show(cr, m.gutter, y, line);
        y += m.line;
      }
    }
    // A caption strip below each panel, clipped to the panel's width.
    for (std::size_t k = 0; k < page.panels.size(); ++k) {
      const PageLayout::Rect& r = layout.panels[k];
      const CaptionLines c = caption_lines(cr, page.panels[k], m, text_width);
      cairo().save(cr);
      cairo().rectangle(cr, r.x, r.y + r.height, r.width, layout.caption_height);
      cairo().clip(cr);
      double y = r.y + r.height + m.pad + ascent;
      const double x = r.x + m.pad;
      if (!c.letter.empty()) {
        set_font(cr, m.font, true);
        show(cr, x, y, c.letter);
      }
      set_font(cr, m.font, false);
      for (std::size_t i = 0; i < c.lines.size(); ++i) {
        show(cr, i == 0 ? x + c.letter_advance : x, y, c.lines[i]);
        y += m.line;
      }
      cairo().restore(cr);
    }
  }
  // The legend strip below the grid: heading, then a swatch and the text per entry.
  if (!page.legend.empty()) {
    const int top = layout.height - legend_height(page, m) - m.gutter;
    double y = top + m.pad + ascent;
    const double x = m.gutter + m.pad;
    set_font(cr, m.font, true);
    show(cr, x, y, page.legend_heading);
    set_font(cr, m.font, false);
    for (const PageLegendEntry& e : page.legend) {
      y += m.line;
      cairo().set_source_rgb(cr, e.srgb[0], e.srgb[1], e.srgb[2]);
      cairo().rectangle(cr, x, y - 0.8 * m.font, 0.8 * m.font, 0.8 * m.font);
      cairo().fill(cr);
      cairo().set_source_rgb(cr, kInk, kInk, kInk);
      show(cr, x + 1.3 * m.font, y, e.text);
    }
  }
  if (cairo().status(cr) != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(std::string("cairo: ") + cairo().status_to_string(cairo().status(cr)));
  }
}

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

std::string time_caption(double t, double spacing) {
  // Rounding to d decimals is monotone with a step of 10^-d, so times 10^-d apart already print
  // differently; one decimal more keeps each within a twentieth of the spacing of its value
  // (1/60 s prints 0.017, not 0.02).
  int decimals = 2;
  while (decimals < 9 && std::pow(10.0, -decimals) > 0.1 * spacing * (1.0 + 1e-9)) ++decimals;
  char text[64];
  std::snprintf(text, sizeof text, "t = %.*f s", decimals, t);
  return text;
}

FigureFormat parse_figure_format(std::string_view text) {
  if (text == "png") return FigureFormat::png;
  if (text == "pdf") return FigureFormat::pdf;
  if (text == "svg") return FigureFormat::svg;
  throw UsageError("--format " + std::string(text) + ": allowed are png, pdf, svg");
}

std::string_view figure_extension(FigureFormat format) {
  switch (format) {
    case FigureFormat::png: return ".png";
    case FigureFormat::pdf: return ".pdf";
    case FigureFormat::svg: return ".svg";
  }
  return ".png";
}

PageLayout layout_page(const FigurePage& page) {
  if (page.rows < 1 || page.columns < 1 ||
      page.panels.size() != static_cast<std::size_t>(page.rows) * static_cast<std::size_t>(page.columns)) {
    throw std::invalid_argument("layout_page: " + std::to_string(page.panels.size()) + " panels for " +
                                std::to_string(page.rows) + " x " + std::to_string(page.columns));
  }
  for (const PagePanel& p : page.panels) {
    if (p.image != nullptr && (p.image->width != page.panel_width || p.image->height != page.panel_height)) {
      throw std::invalid_argument("layout_page: a panel is not " + std::to_string(page.panel_width) +
                                  "x" + std::to_string(page.panel_height));
    }
  }
  const Metrics m = metrics_of(page);
  SurfacePtr surface(nullptr, cairo().surface_destroy);
  CairoPtr cr = measuring_context(surface);
  PageLayout layout;
  layout.font_size = m.font;
  layout.width = page.columns * page.panel_width + (page.columns - 1) * m.gutter + 2 * m.gutter;
  const int caption = caption_height(cr.get(), page, m, page.panel_width);
  layout.caption_height = caption;
  const int title = title_height(cr.get(), page, m, layout.width - 2.0 * m.gutter);
  for (int r = 0; r < page.rows; ++r) {
    for (int c = 0; c < page.columns; ++c) {
      layout.panels.push_back({m.gutter + c * (page.panel_width + m.gutter),
                               m.gutter + title + r * (page.panel_height + caption + m.gutter),
                               page.panel_width, page.panel_height});
    }
  }
  layout.height = m.gutter + title + page.rows * (page.panel_height + caption) +
                  (page.rows - 1) * m.gutter + legend_height(page, m) + m.gutter;
  if ((page.width > 0 && page.width < layout.width) || (page.height > 0 && page.height < layout.height)) {
    throw std::invalid_argument("layout_page: the page needs " + std::to_string(layout.width) + "x" +
                                std::to_string(layout.height) + " pixels, more than the " +
                                std::to_string(page.width) + "x" + std::to_string(page.height) + " given");
  }
  if (page.width > 0) layout.width = page.width;
  if (page.height > 0) layout.height = page.height;
  return layout;
}

std::pair<int, int> fit_panels(const FigurePage& page, int width, int height) {
  if (page.font_size <= 0.0 || page.rows < 1 || page.columns < 1) {
    throw std::invalid_argument("fit_panels: needs a font size (" + std::to_string(page.font_size) +
                                ") and rows and columns >= 1");
  }
  const Metrics m = metrics_of(page);
  SurfacePtr surface(nullptr, cairo().surface_destroy);
  CairoPtr cr = measuring_context(surface);
  // layout_page's sums, solved for the panel size.
  const int panel_width = (width - (page.columns + 1) * m.gutter) / page.columns;
  const int caption = caption_height(cr.get(), page, m, panel_width);
  const int natural_width = page.columns * panel_width + (page.columns + 1) * m.gutter;
  const int title = title_height(cr.get(), page, m, natural_width - 2.0 * m.gutter);
  const int panel_height =
      (height - (page.rows + 1) * m.gutter - title - legend_height(page, m) - page.rows * caption) / page.rows;
  return {panel_width, panel_height};
}

void open_cairo() { cairo(); }

render::Image compose_page_pixels(const FigurePage& page, const PageLayout& layout) {
  SurfacePtr surface(cairo().image_surface_create(CAIRO_FORMAT_RGB24, layout.width, layout.height),
                     cairo().surface_destroy);
  {
    CairoPtr cr(cairo().create(surface.get()), cairo().destroy);
    draw_page(cr.get(), page, layout);
  }
  cairo().surface_flush(surface.get());
  if (cairo().surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(std::string("cairo: ") +
                             cairo().status_to_string(cairo().surface_status(surface.get())));
  }
  render::Image out;
  out.width = layout.width;
  out.height = layout.height;
  out.pixels.resize(3u * static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height));
  const unsigned char* data = cairo().image_surface_get_data(surface.get());
  const int stride = cairo().image_surface_get_stride(surface.get());
  for (int y = 0; y < out.height; ++y) {
    const auto* row = reinterpret_cast<const std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
    for (int x = 0; x < out.width; ++x) {
      const std::size_t i = 3u * (static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) +
                                  static_cast<std::size_t>(x));
      out.pixels[i] = static_cast<std::uint8_t>(row[x] >> 16);
      out.pixels[i + 1] = static_cast<std::uint8_t>(row[x] >> 8);
      out.pixels[i + 2] = static_cast<std::uint8_t>(row[x]);
    }
  }
  return out;
}

std::string compose_page(const FigurePage& page, FigureFormat format, const PageLayout& layout) {
  if (format == FigureFormat::png) {
    const std::span<const std::uint8_t> png = render::encode_png(compose_page_pixels(page, layout));
    return std::string(reinterpret_cast<const char*>(png.data()), png.size());
  }
  std::string bytes;
  SurfacePtr surface(format == FigureFormat::pdf
                         ? cairo().pdf_surface_create_for_stream(append, &bytes, layout.width,
                                                                 layout.height)
                         : cairo().svg_surface_create_for_stream(append, &bytes, layout.width,
                                                                 layout.height),
                     cairo().surface_destroy);
  if (format == FigureFormat::pdf) {
    cairo().pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_CREATOR, "cps figure");
    if (!page.title.empty()) {
      cairo().pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_TITLE, page.title.c_str());
    }
  }
  {
    CairoPtr cr(cairo().create(surface.get()), cairo().destroy);
    draw_page(cr.get(), page, layout);
  }
  cairo().surface_finish(surface.get());
  if (cairo().surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(std::string("cairo: ") +
                             cairo().status_to_string(cairo().surface_status(surface.get())));
  }
  return bytes;
}

}  // namespace cps::cli
