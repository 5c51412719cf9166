// The caption page of figures and frames (demos/cps/compose.h), in-process: a frame laid out by
// fit_panels is exactly the size asked, its panels and caption strips lie inside it without
// overlapping, and the panels are as large as the text allows.
#include "pictures/compose.h"

#include <catch2/catch.hpp>

#include <string>
#include <vector>

#if defined(__SANITIZE_ADDRESS__) || defined(CPS_SANITIZER_RUNTIME)
// cairo loads fontconfig to find DejaVu Sans, whose pattern cache (about 1 kB) is never freed
// before exit. The renderer's OSMesa context tells LeakSanitizer so for the cps command; this
// test does not link that file, so it says it itself (one suppression list per process).
extern "C" const char* __lsan_default_suppressions() { return "leak:libfontconfig.so\n"; }
#endif

using cps::cli::FigurePage;
using cps::cli::fit_panels;
using cps::cli::layout_page;
using cps::cli::PageLayout;

namespace {

// A frame page as cps render makes it: rows x columns panels of `caption` text (the sixth cell
// of a 2 x 3 grid empty, as for five variants), a legend of `legend` entries, text of max(10, cell height / 30) px, exactly w x h.
FigurePage frame(int rows, int columns, int w, int h, const std::string& caption, int legend) {
  FigurePage page;
  page.rows = rows;
  page.columns = columns;
  page.width = w;
  page.height = h;
  page.font_size = std::max(10.0, h / static_cast<double>(rows) / 30.0);
  for (int k = 0; k < rows * columns; ++k) page.panels.push_back({nullptr, "", k == 5 ? "" : caption});  // 2 x 3: five variants
  page.legend_heading = legend > 0 ? "push" : "";
  for (int k = 0; k < legend; ++k) page.legend.push_back({{0.1f, 0.4f, 0.7f}, "variant " + std::to_string(k)});
  const auto [pw, ph] = fit_panels(page, w, h);
  page.panel_width = pw;
  page.panel_height = ph;
  return page;
}

bool overlap(const PageLayout::Rect& a, const PageLayout::Rect& b) {
  return a.x < b.x + b.width && b.x < a.x + a.width && a.y < b.y + b.height && b.y < a.y + a.height;
}

}  // namespace

TEST_CASE("a frame's caption page is --size exactly, its strips beside its scenes, none overlapping",
          "[compose]") {
  const std::string caption = "intersecting_stack\npush = split\nsingle frame push factor (Sec. 8.1)\nt = 10.00 s";
  struct Shape {
    int rows, columns, legend;
  };
  for (const Shape s : {Shape{1, 1, 0}, Shape{1, 1, 5}, Shape{1, 2, 0}, Shape{1, 3, 0}, Shape{2, 2, 0},
                        Shape{2, 3, 0}}) {
    for (const auto& [w, h] : {std::pair{1280, 720}, std::pair{640, 270}, std::pair{900, 900}, std::pair{1920, 1080}}) {
      INFO(s.rows << " x " << s.columns << " panels, legend " << s.legend << ", frame " << w << "x" << h);
      const FigurePage page = frame(s.rows, s.columns, w, h, caption, s.legend);
      REQUIRE(page.panel_width > 16);
      REQUIRE(page.panel_height > 16);
      const PageLayout layout = layout_page(page);
      CHECK(layout.width == w);
      CHECK(layout.height == h);
      REQUIRE(layout.panels.size() == static_cast<std::size_t>(s.rows * s.columns));
      // Four caption lines of text at least: the strip holds them.
      CHECK(layout.caption_height >= 4 * 1.25 * page.font_size);
      for (std::size_t a = 0; a < layout.panels.size(); ++a) {
        const PageLayout::Rect& p = layout.panels[a];
        const PageLayout::Rect strip{p.x, p.y + p.height, p.width, layout.caption_height};
        CHECK(p.x >= 0);
        CHECK(p.y >= 0);
        CHECK(strip.x + strip.width <= w);
        CHECK(strip.y + strip.height <= h);
        for (std::size_t b = 0; b < layout.panels.size(); ++b) {
          const PageLayout::Rect& q = layout.panels[b];
          const PageLayout::Rect other{q.x, q.y + q.height, q.width, layout.caption_height};
          if (a != b) CHECK_FALSE(overlap(p, q));
          CHECK_FALSE(overlap(p, other));  // no caption strip on any scene
          if (a != b) CHECK_FALSE(overlap(strip, other));
        }
      }
      // As large as the text allows: one more pixel of panel height (or width) no longer fits.
      FigurePage taller = page;
      taller.panel_height += 1;
      CHECK_THROWS_AS(layout_page(taller), std::invalid_argument);
      FigurePage wider = page;
      wider.panel_width += 1;
      CHECK_THROWS_AS(layout_page(wider), std::invalid_argument);
    }
  }
}

TEST_CASE("fit_panels needs a font size and a grid", "[compose]") {
  FigurePage page;
  page.panels.push_back({nullptr, "", "t = 0.00 s"});
  CHECK_THROWS_AS(fit_panels(page, 640, 360), std::invalid_argument);  // no font size
  page.font_size = 12.0;
  page.rows = 0;
  CHECK_THROWS_AS(fit_panels(page, 640, 360), std::invalid_argument);
}

TEST_CASE("time captions tell frames apart and stay near their time", "[compose]") {
  using cps::cli::time_caption;
  // Frames 1/60 s apart (render --fps 60): three decimals, within a twentieth of the spacing.
  CHECK(time_caption(1.0 / 60.0, 1.0 / 60.0) == "t = 0.017 s");
  // Panels 0.5 s apart: the two decimals every caption has at least.
  CHECK(time_caption(0.5, 0.5) == "t = 0.50 s");
  // Every frame of 10 s at 600 fps (the pendulum wave's own step) prints apart from the others.
  std::vector<std::string> captions;
  for (int k = 0; k <= 6000; ++k) captions.push_back(time_caption(k / 600.0, 1.0 / 600.0));
  for (std::size_t k = 1; k < captions.size(); ++k) {
    INFO(captions[k - 1] << " / " << captions[k]);
    REQUIRE(captions[k - 1] != captions[k]);
  }
}
