// `cps render` and `cps figure` with --compare PARAM=V1,... and --overlay, run as a user runs
// them: the grid of panels, the ghosts of the overlay (pixel checks), run.json, bad input.
#include "cli_support.h"

#include "cps/render/renderer.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cli_test::fresh_dir;
using cli_test::Result;
using cli_test::slurp;

namespace {

Result run(const std::string& args, const fs::path& dir) { return cli_test::run_cps(args, dir); }

// A panel's place in a frame, [x, y, width, height] in pixels, as run.json's layout.panels_px
// gives it.
struct Rect {
  int x, y, width, height;
};

std::vector<Rect> panels_of(const nlohmann::json& run_json) {
  std::vector<Rect> rects;
  for (const nlohmann::json& r : run_json["parameters"]["layout"]["panels_px"]) {
    rects.push_back({r[0].get<int>(), r[1].get<int>(), r[2].get<int>(), r[3].get<int>()});
  }
  return rects;
}

// Mean absolute difference (0-255) of two panels of the same size in `image`.
double panel_difference(const cps::render::Image& image, const Rect& a, const Rect& b) {
  double sum = 0.0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const auto at = [&](const Rect& r) {
          return image.pixels[3 * (static_cast<std::size_t>(r.y + y) * image.width + r.x + x) + c];
        };
        sum += std::abs(static_cast<int>(at(a)) - static_cast<int>(at(b)));
      }
    }
  }
  return sum / (3.0 * a.width * a.height);
}

// Dark pixels (red channel below 128: text ink on the white strip) in rows [y0, y1) and columns
// [x0, x1).
int ink_in(const cps::render::Image& image, int x0, int x1, int y0, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) n += image.pixels[3 * (static_cast<std::size_t>(y) * image.width + x)] < 128;
  }
  return n;
}

// Hue (degrees) and saturation of an RGB8 pixel.
std::pair<double, double> hue_saturation(const std::uint8_t* p) {
  const double r = p[0] / 255.0, g = p[1] / 255.0, b = p[2] / 255.0;
  const double mx = std::max({r, g, b}), mn = std::min({r, g, b}), d = mx - mn;
  if (d <= 0.0) return {0.0, 0.0};
  double h = mx == r ? 60.0 * std::fmod((g - b) / d, 6.0) : mx == g ? 60.0 * ((b - r) / d + 2.0)
                                                                     : 60.0 * ((r - g) / d + 4.0);
  if (h < 0.0) h += 360.0;
  return {h, d / mx};
}

// Pixels in rows [y0, y1) whose hue is within tol degrees of `hue` with saturation above 0.25
// (the sky, 0.10, and the grey ground, 0.02, are below it).
int pixels_of_hue(const cps::render::Image& image, double hue, double tol, int y0, int y1,
                  double* mean_y = nullptr) {
  int n = 0;
  double sum_y = 0.0;
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const auto [h, s] = hue_saturation(&image.pixels[3 * (static_cast<std::size_t>(y) * image.width + x)]);
      double d = std::abs(h - hue);
      d = std::min(d, 360.0 - d);
      if (s > 0.25 && d < tol) {
        ++n;
        sum_y += y;
      }
    }
  }
  if (mean_y != nullptr) *mean_y = n > 0 ? sum_y / n : 0.0;
  return n;
}

// The rows (first, last) of `cell` that hold a saturated pixel (its largest channel at least 60
// above its smallest: a palette-coloured body; the sky, the grey ground and its shadows, and
// the black text never are), or (-1, -2) when none does.
std::pair<int, int> saturated_rows(const cps::render::Image& image, const Rect& cell) {
  int first = -1;
  int last = -2;
  for (int y = cell.y; y < cell.y + cell.height; ++y) {
    for (int x = cell.x; x < cell.x + cell.width; ++x) {
      const std::uint8_t* p = &image.pixels[3 * (static_cast<std::size_t>(y) * image.width + x)];
      if (std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}) >= 60) {
        if (first < 0) first = y;
        last = y;
        break;
      }
    }
  }
  return {first, last};
}

constexpr double kBlueHue = 205.0;    // overlay_colour(0), #1f77b4
constexpr double kOrangeHue = 28.0;   // overlay_colour(1), #ff7f0e

}  // namespace

TEST_CASE("the intersecting stack's column fills a quarter of each panel of a 2-way comparison",
          "[cli][compare][views]") {
  // The scene's default framing (fit:frame) at 640x360 with captions: at t = 0 the column of
  // five cubes is at least 90 px tall (a quarter of the 360 px panel) in both panels; the fixed
  // view that holds the Baumgarte run's 55 m flight draws it about 45 px tall.
  const fs::path dir = fresh_dir("cps_compare_column");
  const Result r = run("render intersecting_stack --compare push=baumgarte,split --label "
                       "--seconds 1 --fps 1 --size 640x360 --out out",
                       dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const fs::path folder = dir / "out" / "intersecting_stack-compare-push-baumgarte_split";
  const cps::render::Image first = cps::render::read_png(folder / "frame_000000.png");
  const std::vector<Rect> at = panels_of(nlohmann::json::parse(slurp(folder / "run.json")));
  REQUIRE(at.size() == 2);
  for (const Rect& cell : at) {
    const auto [top, bottom] = saturated_rows(first, cell);
    INFO("column from row " << top << " to " << bottom);
    CHECK(bottom - top + 1 >= 90);
  }
  // run.json records the moving camera: each panel's at the first and the last frame, the
  // split run's (the column at rest) nearer than the Baumgarte run's (cubes in flight) at 1 s.
  const nlohmann::json c = nlohmann::json::parse(slurp(folder / "run.json"))["parameters"];
  CHECK(c["camera"] == "fit:frame");
  REQUIRE(c["camera_resolved"]["moves"] == true);
  const auto distance = [&](int panel) {
    const nlohmann::json& cam = c["camera_resolved"]["last_frame_by_panel"][panel];
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double d = cam["eye_m"][a].get<double>() - cam["target_m"][a].get<double>();
      d2 += d * d;
    }
    return std::sqrt(d2);
  };
  CHECK(distance(1) < 0.5 * distance(0));
}

TEST_CASE("captions take at most a quarter of a small panel: 8 methods at 640x360 keep 65 % of "
          "each cell for the picture",
          "[cli][compare]") {
  // 4 x 2 cells of 160 x 180 px at 10 px text: the scene's name once as the frame's title, each
  // caption its variant and time (two lines, about 30 px); with every label's description and
  // the scene's name in each caption (five lines and more) the pictures kept about half.
  const fs::path dir = fresh_dir("cps_compare_captions");
  const Result r = run("render intersecting_stack --compare push --label --seconds 0.1 --fps 10 "
                       "--size 640x360 --out out",
                       dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const fs::path folder = dir / "out" / "intersecting_stack-compare-push";
  const std::vector<Rect> at = panels_of(nlohmann::json::parse(slurp(folder / "run.json")));
  REQUIRE(at.size() == 8);
  for (const Rect& cell : at) CHECK(cell.height >= 0.65 * 180);
}

TEST_CASE("cps render --compare with three values of beta lays out 3 labelled panels that differ",
          "[cli][compare]") {
  const fs::path dir = fresh_dir("cps_compare_grid");
  const Result r = run("render intersecting_stack --compare beta=0.05,0.2,0.5 --seconds 1 --fps 1 "
                       "--size 480x240 --out out",
                       dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const fs::path folder = dir / "out" / "intersecting_stack-compare-beta-0.05_0.2_0.5";
  const cps::render::Image last = cps::render::read_png(folder / "frame_000001.png");
  CHECK(last.width == 480);  // 1 x 3 cells of 160 x 240: --size exactly
  CHECK(last.height == 240);
  const nlohmann::json manifest = nlohmann::json::parse(slurp(folder / "run.json"));
  const std::vector<Rect> at = panels_of(manifest);
  REQUIRE(at.size() == 3);
  for (const Rect& cell : at) {
    // Each scene in its cell, with a caption strip below it that holds its label and time.
    CHECK(cell.width > 100);
    CHECK(cell.width <= 160);
    CHECK(cell.height > 100);
    CHECK(cell.y + cell.height < 240 - 24);
    CHECK(ink_in(last, cell.x, cell.x + cell.width, cell.y + cell.height, 240) > 50);
  }
  // At t = 1 s: beta = 0.05 still pushes the cubes apart slowly, 0.5 has thrown them out; a few
  // grey levels on average is a different picture (the same picture differs by 0).
  for (const auto& [a, b] : {std::pair{0, 1}, std::pair{0, 2}, std::pair{1, 2}}) {
    INFO("panels " << a << " and " << b);
    CHECK(panel_difference(last, at[static_cast<std::size_t>(a)], at[static_cast<std::size_t>(b)]) > 1.0);
  }
  const nlohmann::json& p = manifest["parameters"];
  CHECK(p["compare"]["parameter"] == "beta");
  CHECK(p["compare"]["values"] == nlohmann::json({0.05, 0.2, 0.5}));
  CHECK(p["layout"]["rows"] == 1);
  CHECK(p["layout"]["columns"] == 3);
  REQUIRE(p["world"].size() == 3);
  CHECK(p["world"][2]["parameters"]["beta"] == 0.5);
  CHECK(p["world"][0]["label"].get<std::string>().find("beta = 0.05") != std::string::npos);

  // Another list of the same parameter goes to its own folder; the first stays whole.
  REQUIRE(run("render intersecting_stack --compare beta=0.05,0.2,0.5,0.8 --seconds 0.1 --fps 1 "
              "--size 480x240 --out out",
              dir)
              .exit_code == 0);
  CHECK(fs::exists(folder / "frame_000001.png"));
  const cps::render::Image four = cps::render::read_png(
      dir / "out" / "intersecting_stack-compare-beta-0.05_0.2_0.5_0.8" / "frame_000000.png");
  CHECK(four.width == 480);  // 2 x 2 panels of 240 x 120
  CHECK(four.height == 240);
}

TEST_CASE("cps render --overlay draws every variant in one view in its colour, with a legend",
          "[cli][compare]") {
  const fs::path dir = fresh_dir("cps_compare_overlay");
  const Result r = run("render intersecting_stack --compare push=baumgarte,split --overlay --seconds 0.5 --fps 2 "
                       "--size 480x360 --out out",
                       dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const fs::path folder = dir / "out" / "intersecting_stack-compare-push-baumgarte_split-overlay";
  const cps::render::Image frame = cps::render::read_png(folder / "frame_000001.png");
  CHECK(frame.width == 480);  // one view of --size
  CHECK(frame.height == 360);
  const nlohmann::json manifest = nlohmann::json::parse(slurp(folder / "run.json"));
  const std::vector<Rect> at = panels_of(manifest);
  REQUIRE(at.size() == 1);
  const Rect scene = at.front();
  // The scene, then below it the caption strip (the time) and the legend strip.
  CHECK(scene.height > 200);
  CHECK(scene.y + scene.height < 360 - 40);
  // In the scene: at 0.5 s the baumgarte cubes have flown up (blue ghosts) while the split ones
  // stand (orange ghosts). Hue within 15 degrees; each ghost cube covers hundreds of pixels, so
  // 100 is a safe floor.
  double blue_y = 0.0;
  double orange_y = 0.0;
  const int blue = pixels_of_hue(frame, kBlueHue, 15.0, scene.y, scene.y + scene.height, &blue_y);
  const int orange = pixels_of_hue(frame, kOrangeHue, 15.0, scene.y, scene.y + scene.height, &orange_y);
  CHECK(blue > 100);
  CHECK(orange > 100);
  // Each colour is one variant: the blue (baumgarte) cubes are higher up the picture than the
  // orange (split) stack, by more than a cube's height on average (at this size a cube is
  // about 15 pixels). Bodies in their own palette colours would mix both hues in both stacks.
  CHECK(blue_y < orange_y - 10.0);
  // The legend's swatches: both colours below the scene, and the strips hold text.
  CHECK(pixels_of_hue(frame, kBlueHue, 5.0, scene.y + scene.height, 360) > 20);
  CHECK(pixels_of_hue(frame, kOrangeHue, 5.0, scene.y + scene.height, 360) > 20);
  CHECK(ink_in(frame, 0, 480, scene.y + scene.height, 360) > 100);
  CHECK(manifest["parameters"]["compare"]["layout"] == "overlay");
  CHECK(manifest["parameters"]["compare"]["values"] == nlohmann::json({"baumgarte", "split"}));

  // cps figure --overlay: one row, one panel per time, each with both colours. The camera is
  // the scene's earlier, closer preset (its default now holds the cubes' whole 4 s flight, so
  // the split stack would sit below the rows counted here).
  const Result f = run("figure intersecting_stack --overlay --compare push=baumgarte,split "
                       "--times 0.5,1 --size 200x150 --eye 18,16,40 --target 0,10,0 --out f.png",
                       dir);
  INFO(f.err);
  REQUIRE(f.exit_code == 0);
  const cps::render::Image fig = cps::render::read_png(dir / "f.png");
  const nlohmann::json side = nlohmann::json::parse(slurp(dir / "f.png.json"));
  CHECK(side["parameters"]["comparison"]["layout"] == "overlay");
  CHECK(side["parameters"]["image_size_px"] == nlohmann::json({fig.width, fig.height}));
  // One row: the variants share each panel (the caption strips and the legend lie outside it).
  const nlohmann::json& panels = side["parameters"]["panels_px"];
  REQUIRE(panels.size() == 2);
  CHECK(panels[0]["rect"][1] == panels[1]["rect"][1]);
  const int top = panels[0]["rect"][1];
  CHECK(pixels_of_hue(fig, kBlueHue, 15.0, top + 40, top + 150 - 45) > 50);
  CHECK(pixels_of_hue(fig, kOrangeHue, 15.0, top + 40, top + 150 - 45) > 50);
  // The legend's swatches in their strip below the panels.
  CHECK(pixels_of_hue(fig, kBlueHue, 5.0, top + 150, fig.height) > 20);
  CHECK(pixels_of_hue(fig, kOrangeHue, 5.0, top + 150, fig.height) > 20);
}

TEST_CASE("a bad --compare or --overlay exits 2 naming the problem and writes nothing",
          "[cli][compare]") {
  const fs::path dir = fresh_dir("cps_compare_bad");
  struct Case {
    std::string args;
    std::string says;
  };
  const Case cases[] = {
      {"render stack --compare nosuch=1,2", "'nosuch'"},
      {"render stack --compare beta=0.1,2", "--beta 2"},
      {"render stack --compare beta=0.1", "1 value"},
      {"render stack --compare beta=0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9", "more than 8"},
      {"render stack --compare beta=0.2,0.20", "same value"},
      {"render stack --compare beta=0.1,0.2 --beta 0.3", "--beta is given too"},
      {"render stack --compare push --push split", "--push is given too"},
      {"render stack --compare solver --push avbd", "push avbd does not read --solver"},
      {"figure stack --times 0 --compare friction-model --push xpbd", "does not read --friction-model"},
      {"render stack --overlay", "--overlay"},
      {"render stack --compare beta=0.1,0.2,0.3,0.4 --size 30x30", "16x16"},
      {"figure stack --times 0 --compare iterations=1,0", "--iterations 0"},
      {"figure stack --times 0 --overlay", "--overlay"},
      {"figure paper --overlay", "--overlay"},
  };
  for (const Case& c : cases) {
    INFO(c.args);
    const bool render = c.args.rfind("render", 0) == 0;
    const Result r = run(c.args + (render ? " --seconds 0.1 --fps 10 --out out" : " --out out/x.png"), dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
    CHECK(!fs::exists(dir / "out"));
  }
}
