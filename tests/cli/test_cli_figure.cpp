// cps figure, cps simulate --trace and every command's --help, run as a user runs them:
// picture sizes, refusals that keep foreign files intact, and a trace that obeys free fall.
#include "cli_support.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#ifdef CPS_HAVE_RENDERER
#include "cps/render/renderer.h"
#endif

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using cli_test::Result;
using cli_test::run_cps;
using cli_test::slurp;

Result cps_run(const std::string& args, const fs::path& dir) { return run_cps(args, dir); }

fs::path fresh_dir(const std::string& name) { return cli_test::fresh_dir("cps_cli_figure_test_" + name); }

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

#ifdef CPS_HAVE_RENDERER
// Width and height of a PNG from its IHDR chunk (bytes 16..23, big endian); {0, 0} if the file
// is not a PNG.
std::pair<int, int> png_size(const fs::path& p) {
  const std::string bytes = slurp(p);
  if (bytes.size() < 24 || bytes.compare(1, 3, "PNG") != 0 || bytes.compare(12, 4, "IHDR") != 0) {
    return {0, 0};
  }
  const auto be32 = [&bytes](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return static_cast<int>(v);
  };
  return {be32(16), be32(20)};
}

// The page size the figure's sidecar records ({0, 0} without a sidecar).
std::pair<int, int> sidecar_size(const fs::path& figure) {
  const fs::path side = figure.string() + ".json";
  if (!fs::exists(side)) return {0, 0};
  const nlohmann::json size = nlohmann::json::parse(slurp(side))["parameters"]["image_size_px"];
  return {size[0].get<int>(), size[1].get<int>()};
}

// The text of a PDF as pdftotext (poppler-utils) reads it; "" if it cannot.
std::string pdf_text(const fs::path& pdf) {
  const fs::path txt = pdf.string() + ".txt";
  const std::string command = "pdftotext -q '" + pdf.string() + "' '" + txt.string() + "'";
  if (std::system(command.c_str()) != 0) return "";
  return slurp(txt);
}

// The panels' rectangles (x, y, width, height) and letters the sidecar of `figure` records.
struct PanelRect {
  int x, y, w, h;
  std::string letter;
};
std::vector<PanelRect> sidecar_panels(const fs::path& figure) {
  std::vector<PanelRect> out;
  const nlohmann::json side = nlohmann::json::parse(slurp(figure.string() + ".json"));
  for (const auto& p : side["parameters"]["panels_px"]) {
    out.push_back({p["rect"][0], p["rect"][1], p["rect"][2], p["rect"][3], p["letter"]});
  }
  return out;
}

// (a), (b), ... in reading order: row by row (y increasing), each row left to right.
void check_reading_order(const std::vector<PanelRect>& panels) {
  for (std::size_t k = 0; k < panels.size(); ++k) {
    INFO("panel " << k);
    CHECK(panels[k].letter == std::string("(") + static_cast<char>('a' + k) + ")");
    if (k == 0) continue;
    const PanelRect& a = panels[k - 1];
    const PanelRect& b = panels[k];
    CHECK((b.y > a.y || (b.y == a.y && b.x > a.x)));
  }
}
#endif

// The rows of a CSV file, each split at commas.
std::vector<std::vector<std::string>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream s(line);
    std::string cell;
    while (std::getline(s, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

}  // namespace

#ifdef CPS_HAVE_RENDERER
TEST_CASE("render and figure --quiet: no progress or context line, each kind of warning once",
          "[cli][figure][warnings]") {
  const fs::path dir = fresh_dir("quiet");
  // Two variants of the paper's push on the cradle of rods, both gaining energy: two warnings.
  const std::string cradle = std::string(CPS_TEST_DATA) + "/cradle.json";
  const std::string compare = " --compare beta=0.2,0.8 --size 160x120 ";
  const auto warnings = [](const std::string& err) {
    std::size_t n = 0;
    for (std::size_t at = 0; (at = err.find("cps: warning: ", at)) != std::string::npos; ++at) ++n;
    return n;
  };
  const Result loud = cps_run("render " + cradle + compare + "--seconds 4 --fps 4 --out r1", dir);
  REQUIRE(loud.exit_code == 0);
  CHECK(warnings(loud.err) == 2);
  CHECK(loud.err.find("render: ") != std::string::npos);  // the GL context
  CHECK(loud.err.find(" frames") != std::string::npos);   // the progress
  const Result quiet = cps_run("render " + cradle + compare + "--seconds 4 --fps 4 --out r2 --quiet", dir);
  REQUIRE(quiet.exit_code == 0);
  CHECK(warnings(quiet.err) == 1);
  CHECK(std::count(quiet.err.begin(), quiet.err.end(), '\n') == 1);
  CHECK(cps_run("render " + cradle + compare + "--seconds 4 --fps 4 --out r3 --quiet "
                "--warnings-as-errors", dir).exit_code == 3);
  const Result figure = cps_run("figure " + cradle + compare + "--times 0,4 --out f.png --quiet", dir);
  REQUIRE(figure.exit_code == 0);
  CHECK(warnings(figure.err) == 1);
  CHECK(std::count(figure.err.begin(), figure.err.end(), '\n') == 1);
}

TEST_CASE("figure --out takes a folder as render does (a trailing slash or an existing folder or "
          "a name without an extension gets the figure under its own name) and a file name is the file",
          "[cli][figure][output]") {
  const fs::path dir = fresh_dir("out_folder");
  fs::create_directories(dir / "existing");
  const std::string figure = "figure stack --times 0 --size 40x24 --no-label --out ";
  for (const std::string out : {"existing", "slash/", "plain"}) {
    INFO(out);
    const Result r = cps_run(figure + out, dir);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(png_size(dir / out / "stack.png") == std::make_pair(40, 24));
    CHECK(fs::exists(dir / out / "stack.png.json"));
  }
  // With --format, the folder's figure takes its extension; a file name is the file itself.
  REQUIRE(cps_run(figure + "vector --format svg", dir).exit_code == 0);
  CHECK(fs::exists(dir / "vector/stack.svg"));
  REQUIRE(cps_run(figure + "named.png", dir).exit_code == 0);
  CHECK(png_size(dir / "named.png") == std::make_pair(40, 24));
  // A file name with another format's extension is still refused, naming it.
  const Result wrong = cps_run(figure + "f.txt", dir);
  CHECK(wrong.exit_code == 2);
  CHECK(wrong.err.find("f.txt") != std::string::npos);
}

TEST_CASE("cps figure writes one PNG of times x variants panels with a sidecar", "[cli][figure]") {
  const fs::path dir = fresh_dir("size");
  const Result r = cps_run("figure intersecting_stack --times 0,0.25,0.5 --compare push=baumgarte,split --size 48x32 "
                       "--out f.png",
                       dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  // The page holds the 3 x 2 panels (one column per time, one row per variant of --push) and
  // their caption strips.
  const auto [w, h] = png_size(dir / "f.png");
  CHECK(std::make_pair(w, h) == sidecar_size(dir / "f.png"));
  CHECK(w > 3 * 48);
  CHECK(h > 2 * 32);
  const std::vector<PanelRect> panels = sidecar_panels(dir / "f.png");
  REQUIRE(panels.size() == 6);
  for (const PanelRect& p : panels) CHECK((p.w == 48 && p.h == 32));
  check_reading_order(panels);
  // Bare (--no-label): the panels alone, abutting.
  REQUIRE(cps_run("figure intersecting_stack --times 0,0.25,0.5 --compare push=baumgarte,split "
              "--size 48x32 --no-label --out bare.png", dir).exit_code == 0);
  CHECK(png_size(dir / "bare.png") == std::make_pair(3 * 48, 2 * 32));
  const nlohmann::json side = nlohmann::json::parse(slurp(dir / "f.png.json"));
  CHECK(side["written_by"] == "cps figure");
  CHECK(side["parameters"]["times_s"].size() == 3);
  CHECK(side["parameters"]["variants"].size() == 2);
  CHECK(side["parameters"]["variants"][1]["parameters"]["push"] == "split");
  CHECK(side["command_line"].dump().find("\"--times\",\"0,0.25,0.5\"") != std::string::npos);

  // Its own file is replaced without --force; the default name is out/figures/SCENE.png.
  CHECK(cps_run("figure intersecting_stack --times 0,0.25 --size 48x32 --no-label --out f.png", dir).exit_code == 0);
  CHECK(png_size(dir / "f.png") == std::make_pair(2 * 48, 32));
  CHECK(cps_run("figure stack --times 0 --size 40x24 --no-label", dir).exit_code == 0);
  CHECK(png_size(dir / "out/figures/stack.png") == std::make_pair(40, 24));
  CHECK(fs::exists(dir / "out/figures/stack.png.json"));
}

TEST_CASE("cps figure rejects bad --times with exit 2, naming the value, and writes nothing",
          "[cli][figure]") {
  const fs::path dir = fresh_dir("times");
  struct Case {
    std::string times;
    std::string says;
  };
  const Case cases[] = {{"0,abc", "'abc'"},     {"0,-1", "'-1'"},   {"0,1,0.5", "'0.5'"},
                        {"nan", "'nan'"},       {"0,inf", "'inf'"}, {"1,1", "'1'"},
                        {"1e999", "'1e999'"},   {"1,,2", "empty"},  {"0,1e6", "'1e6'"}};
  for (const Case& c : cases) {
    INFO("--times " << c.times);
    const Result r = cps_run("figure stack --size 32x32 --times '" + c.times + "'", dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
  }
  CHECK(cps_run("figure stack --size 32x32", dir).exit_code == 2);  // --times is required
  CHECK(cps_run("figure nosuchscene --times 0", dir).err.find("cps list") != std::string::npos);
  CHECK(!fs::exists(dir / "out"));
}

TEST_CASE("cps figure keeps a file it did not write unless --force", "[cli][figure]") {
  const fs::path dir = fresh_dir("foreign");
  const std::string foreign = "a figure someone made by hand\n";
  write_text(dir / "mine.png", foreign);
  const Result r = cps_run("figure stack --times 0 --size 32x32 --out mine.png", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--force") != std::string::npos);
  CHECK(slurp(dir / "mine.png") == foreign);
  CHECK(!fs::exists(dir / "mine.png.json"));

  // A sidecar that is not ours does not make the file ours either.
  write_text(dir / "mine.png.json", "{\"written_by\": \"someone else\"}");
  CHECK(cps_run("figure stack --times 0 --size 32x32 --out mine.png", dir).exit_code == 2);
  CHECK(slurp(dir / "mine.png") == foreign);

  CHECK(cps_run("figure stack --times 0 --size 32x32 --out mine.png --force", dir).exit_code == 0);
  CHECK(png_size(dir / "mine.png") == sidecar_size(dir / "mine.png"));
  CHECK(png_size(dir / "mine.png").first > 0);
}

TEST_CASE("cps figure never touches foreign files beside its targets", "[cli][figure][output]") {
  const fs::path dir = fresh_dir("foreign_tmp");
  // Named like temporaries of the figure and its sidecar: not cps's, kept as they are.
  write_text(dir / "f.png.tmp", "notes 1");
  write_text(dir / "f.png.json.tmp", "notes 2");
  for (const std::string force : {"", " --force"}) {
    const Result r = cps_run("figure stack --times 0 --size 32x32 --out f.png" + force, dir);
    INFO(force << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(png_size(dir / "f.png") == sidecar_size(dir / "f.png"));
    CHECK(slurp(dir / "f.png.tmp") == "notes 1");
    CHECK(slurp(dir / "f.png.json.tmp") == "notes 2");
  }
  // The folder's run.json lists what cps wrote there, over several runs.
  REQUIRE(cps_run("figure stack --times 0 --size 32x32 --out g.png", dir).exit_code == 0);
  const nlohmann::json manifest = nlohmann::json::parse(slurp(dir / "run.json"));
  CHECK(manifest["files"] == nlohmann::json({"f.png", "f.png.json", "g.png", "g.png.json"}));
  // A run.json that is not cps's is foreign, as any other file.
  const fs::path other = dir / "other";
  fs::create_directories(other);
  write_text(other / "run.json", "{\"mine\": true}");
  const Result refused = cps_run("figure stack --times 0 --size 32x32 --out other/f.png", dir);
  CHECK(refused.exit_code == 2);
  CHECK(refused.err.find("run.json") != std::string::npos);
  CHECK(slurp(other / "run.json") == "{\"mine\": true}");
  CHECK_FALSE(fs::exists(other / "f.png"));
}

TEST_CASE("cps figure --out below a file is refused before any work", "[cli][figure][output]") {
  const fs::path dir = fresh_dir("out_file");
  write_text(dir / "somefile", "not a folder");
  const Result r = cps_run("figure stack --times 0 --size 32x32 --out somefile/f.png", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("somefile") != std::string::npos);
  CHECK(slurp(dir / "somefile") == "not a folder");
}

TEST_CASE("cps figure paper writes the counterparts of Figs. 6 to 10", "[cli][figure]") {
  const fs::path dir = fresh_dir("paper");
  const Result r = cps_run("figure paper --size 32x24 --out figs", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const std::pair<std::string, int> figures[] = {{"fig6_stack", 6},
                                                 {"fig7_intersecting_stack", 7},
                                                 {"fig8_funnel", 8},
                                                 {"fig9_pendulum_grid", 9},
                                                 {"fig10_pendulum_wave", 10}};
  for (const auto& [name, number] : figures) {
    INFO(name);
    const fs::path png = dir / "figs" / (name + ".png");
    const nlohmann::json side = nlohmann::json::parse(slurp(fs::path(png.string() + ".json")));
    CHECK(side["parameters"]["caption"].get<std::string>().find("Fig. " + std::to_string(number)) !=
          std::string::npos);
    CHECK(png_size(png) == sidecar_size(png));
    // Every panel lettered, (a), (b), ... in reading order, the same way in every figure.
    const std::vector<PanelRect> panels = sidecar_panels(png);
    CHECK(panels.size() == side["parameters"]["times_s"].size() * side["parameters"]["variants"].size());
    for (const PanelRect& p : panels) CHECK((p.w == 32 && p.h == 24));
    check_reading_order(panels);
  }
  // Fig. 7 compares the original push factor with the single frame push factor at 0.5 s.
  const nlohmann::json fig7 =
      nlohmann::json::parse(slurp(dir / "figs/fig7_intersecting_stack.png.json"))["parameters"];
  CHECK(fig7["compare"] == "push=baumgarte,split");
  REQUIRE(fig7["variants"].size() == 2);
  CHECK(fig7["variants"][1]["parameters"]["push"] == "split");
  CHECK(std::find(fig7["times_s"].begin(), fig7["times_s"].end(), 0.5) != fig7["times_s"].end());
  CHECK(cps_run("figure paper --times 0,1", dir).exit_code == 2);
}

TEST_CASE("cps figure --format pdf writes its labels as text, svg as glyphs", "[cli][figure][format]") {
  const fs::path dir = fresh_dir("format");
  const Result r = cps_run("figure intersecting_stack --times 0,0.5 --compare push=baumgarte,split "
                       "--size 160x90 --format pdf --out f.pdf", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(slurp(dir / "f.pdf").substr(0, 5) == "%PDF-");
  CHECK(fs::exists(dir / "f.pdf.json"));
  // pdftotext finds every label as text: the letters of the four panels, the times, the
  // compared parameter and its values, the scene in the title.
  const std::string text = pdf_text(dir / "f.pdf");
  INFO(text);
  for (const char* label : {"(a)", "(b)", "(c)", "(d)", "t = 0.00 s", "t = 0.50 s", "push",
                            "baumgarte", "split", "intersecting_stack"}) {
    INFO(label);
    CHECK(text.find(label) != std::string::npos);
  }
  CHECK(text.find("(e)") == std::string::npos);  // four panels, four letters

  // The format follows --out's extension when --format is not given. cairo's SVG writes each
  // glyph once as a <symbol> and places it with <use>: the labels are glyph outlines, the
  // panels <image> elements.
  REQUIRE(cps_run("figure intersecting_stack --times 0,0.5 --size 64x36 --out f.svg", dir).exit_code == 0);
  const std::string svg = slurp(dir / "f.svg");
  CHECK(svg.find("<svg") != std::string::npos);
  CHECK(svg.find("<symbol overflow=\"visible\" id=\"glyph") != std::string::npos);
  CHECK(svg.find("xlink:href=\"#glyph") != std::string::npos);
  CHECK(svg.find("<image") != std::string::npos);
  CHECK(nlohmann::json::parse(slurp(dir / "f.svg.json"))["parameters"]["format"] == "svg");
}

TEST_CASE("cps figure's labels lie in strips outside the scene", "[cli][figure][format]") {
  const fs::path dir = fresh_dir("strips");
  const std::string args = "figure intersecting_stack --times 0,0.5 --compare push=baumgarte,split "
                           "--size 96x64 ";
  REQUIRE(cps_run(args + "--out labelled.png", dir).exit_code == 0);
  REQUIRE(cps_run(args + "--no-label --out bare.png", dir).exit_code == 0);
  const cps::render::Image labelled = cps::render::read_png(dir / "labelled.png");
  const cps::render::Image bare = cps::render::read_png(dir / "bare.png");
  const std::vector<PanelRect> at_l = sidecar_panels(dir / "labelled.png");
  const std::vector<PanelRect> at_b = sidecar_panels(dir / "bare.png");
  REQUIRE(at_l.size() == 4);
  REQUIRE(at_b.size() == 4);
  const auto pixel = [](const cps::render::Image& im, int x, int y, int ch) {
    return im.pixels[3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) +
                          static_cast<std::size_t>(x)) + static_cast<std::size_t>(ch)];
  };
  for (std::size_t k = 0; k < 4; ++k) {
    INFO("panel " << k);
    // The scene's pixels with labels are those without: no label covers any of them.
    int differ = 0;
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 96; ++x) {
        for (int ch = 0; ch < 3; ++ch) {
          differ += pixel(labelled, at_l[k].x + x, at_l[k].y + y, ch) !=
                    pixel(bare, at_b[k].x + x, at_b[k].y + y, ch);
        }
      }
    }
    CHECK(differ == 0);
    // And the caption strip below the panel holds text: dark pixels on white.
    int ink = 0;
    for (int y = at_l[k].y + 64; y < at_l[k].y + 64 + 14; ++y) {
      for (int x = at_l[k].x; x < at_l[k].x + 96; ++x) ink += pixel(labelled, x, y, 0) < 128;
    }
    CHECK(ink > 20);
  }
}

TEST_CASE("cps render --label writes the captions in a strip below the scene, never over it",
          "[cli][figure][format]") {
  const fs::path dir = fresh_dir("render_strips");
  REQUIRE(cps_run("render stack --seconds 0.5 --fps 2 --size 320x240 --label --out l", dir).exit_code == 0);
  const cps::render::Image labelled = cps::render::read_png(dir / "l/stack/frame_000001.png");
  CHECK(labelled.width == 320);  // the frame is --size; the scene gives up the strip's rows
  CHECK(labelled.height == 240);
  const nlohmann::json layout =
      nlohmann::json::parse(slurp(dir / "l/stack/run.json"))["parameters"]["layout"];
  REQUIRE(layout["panels_px"].size() == 1);
  const int x0 = layout["panels_px"][0][0];
  const int y0 = layout["panels_px"][0][1];
  const int w = layout["panels_px"][0][2];
  const int h = layout["panels_px"][0][3];
  CHECK(y0 + h < 240 - 20);  // two lines of 10 px text at least below it
  // The same scene at the scene's own size without a label: the camera frames the same aspect,
  // so every pixel of the scene must be the same. A label drawn over the scene would differ.
  const std::string bare_size = std::to_string(w) + "x" + std::to_string(h);
  REQUIRE(cps_run("render stack --seconds 0.5 --fps 2 --size " + bare_size + " --out b", dir).exit_code == 0);
  const cps::render::Image bare = cps::render::read_png(dir / "b/stack/frame_000001.png");
  REQUIRE(bare.width == w);
  REQUIRE(bare.height == h);
  const auto pixel = [](const cps::render::Image& im, int x, int y, int ch) {
    return im.pixels[3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) +
                          static_cast<std::size_t>(x)) + static_cast<std::size_t>(ch)];
  };
  int differ = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int ch = 0; ch < 3; ++ch) differ += pixel(labelled, x0 + x, y0 + y, ch) != pixel(bare, x, y, ch);
    }
  }
  CHECK(differ == 0);
  // The strip below holds the text (the scene's name and the time): dark pixels on white.
  int ink = 0;
  for (int y = y0 + h; y < 240; ++y) {
    for (int x = 0; x < 320; ++x) ink += pixel(labelled, x, y, 0) < 128;
  }
  CHECK(ink > 100);
}

TEST_CASE("cps figure on a full disk leaves no sidecar without its figure", "[cli][figure][output]") {
  const fs::path dir = fresh_dir("full_disk");
  const std::string args = "figure stack --times 0,0.5 --size 160x90 --format pdf --out f.pdf";
  // Room enough: the sidecar is smaller than the limit below, the PDF larger.
  fs::create_directories(dir / "room");
  REQUIRE(cps_run(args, dir / "room").exit_code == 0);
  REQUIRE(fs::file_size(dir / "room/f.pdf") > 16384);
  REQUIRE(fs::file_size(dir / "room/f.pdf.json") < 8192);
  // Every file limited to 16 KiB (SIGXFSZ ignored: a write past it fails with EFBIG, as one on a
  // full disk fails with ENOSPC).
  fs::create_directories(dir / "full");
  const Result r = run_cps(args, dir / "full", "trap '' XFSZ; prlimit --fsize=16384");
  INFO(r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("cannot write f.pdf: File too large") != std::string::npos);
  std::vector<std::string> left;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "full")) {
    left.push_back(e.path().filename().string());
  }
  // No f.pdf.json, no temporary, and no run.json: the failed run took itself off it, and a
  // run.json listing nothing is removed.
  CHECK(left.empty());
  fs::remove_all(dir);
}

TEST_CASE("cps figure rejects a bad --format with exit 2, naming it, and writes nothing",
          "[cli][figure][format]") {
  const fs::path dir = fresh_dir("bad_format");
  const Result r = cps_run("figure stack --times 0 --size 32x32 --format jpg", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("jpg") != std::string::npos);
  CHECK(r.err.find("png") != std::string::npos);  // and what is allowed
  // A name that does not end as the format says.
  const Result mismatch = cps_run("figure stack --times 0 --size 32x32 --format pdf --out f.png", dir);
  CHECK(mismatch.exit_code == 2);
  CHECK(mismatch.err.find(".pdf") != std::string::npos);
  const Result unknown = cps_run("figure stack --times 0 --size 32x32 --out f.jpg", dir);
  CHECK(unknown.exit_code == 2);
  CHECK(fs::is_empty(dir));
}

TEST_CASE("cps render takes the overlay and camera flags", "[cli][figure]") {
  const fs::path dir = fresh_dir("render_flags");
  const Result r = cps_run("render pendulum_grid --seconds 0.1 --fps 10 --size 96x96 --contacts "
                       "--no-rods --label --camera top --orbit 10 --out o",
                       dir);
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(png_size(dir / "o/pendulum_grid/frame_000001.png") == std::make_pair(96, 96));
  // At 32x32 the caption strips would leave the scene no room: refused, naming the size.
  const Result tiny = cps_run("render pendulum_grid --seconds 0.1 --fps 10 --size 32x32 --label --out t", dir);
  CHECK(tiny.exit_code == 2);
  CHECK(tiny.err.find("--size 32x32") != std::string::npos);
  CHECK(tiny.err.find("16x16") != std::string::npos);
  CHECK(!fs::exists(dir / "t"));
  const std::string quick = "render stack --seconds 0.1 --fps 10 --size 32x32 --out o ";
  CHECK(cps_run(quick + "--camera sideways", dir).exit_code == 2);
  // A camera name near an allowed one is named; a tracked body that does not exist is refused
  // with the range of indices before anything is drawn.
  const Result near = cps_run(quick + "--camera fit:panels", dir);
  CHECK(near.exit_code == 2);
  CHECK(near.err.find("did you mean 'fit:panel'") != std::string::npos);
  const Result no_body = cps_run(quick + "--camera track:12", dir);
  CHECK(no_body.exit_code == 2);
  CHECK(no_body.err.find("track:12") != std::string::npos);
  CHECK(no_body.err.find("from 0 to") != std::string::npos);
  CHECK(cps_run(quick + "--camera track:", dir).exit_code == 2);
  const Result nan = cps_run(quick + "--orbit nan", dir);
  CHECK(nan.exit_code == 2);
  CHECK(nan.err.find("--orbit") != std::string::npos);
  CHECK(!fs::exists(dir / "o/stack"));
}

TEST_CASE("cps render --speed spaces frames speed / fps simulated seconds apart", "[cli][figure]") {
  const fs::path dir = fresh_dir("render_speed");
  // 0.25 s/s at 10 fps: frames 0.025 s apart over 0.5 s = 21 frames; 1.5 steps of 1/60 s, so
  // each frame shows the nearest step and run.json says so.
  const Result slow = cps_run("render stack --seconds 0.5 --fps 10 --speed 0.25 --size 96x96 --label "
                          "--out o",
                          dir);
  INFO(slow.err);
  REQUIRE(slow.exit_code == 0);
  CHECK(fs::exists(dir / "o/stack/frame_000020.png"));
  CHECK(!fs::exists(dir / "o/stack/frame_000021.png"));
  const nlohmann::json p = nlohmann::json::parse(slurp(dir / "o/stack/run.json"))["parameters"];
  CHECK(p["speed"] == 0.25);
  CHECK(p["frames"] == 21);
  CHECK(p["frame_spacing_s"].get<double>() == Approx(0.025).epsilon(1e-12));
  REQUIRE(p["frame_times"].is_array());
  CHECK(p["frame_times"][0].get<std::string>().find("nearest") != std::string::npos);
  CHECK(slow.err.find("nearest") != std::string::npos);
  // 2 s/s at 30 fps: frames 1/15 s = 4 steps apart, exact; 1 s gives 16 frames.
  const Result fast = cps_run("render stack --seconds 1 --fps 30 --speed 2 --size 16x16 --out f", dir);
  REQUIRE(fast.exit_code == 0);
  const nlohmann::json q = nlohmann::json::parse(slurp(dir / "f/stack/run.json"))["parameters"];
  CHECK(q["frames"] == 16);
  CHECK(q["frame_times"] == "exact multiples of the physics step");
  const std::string quick = "render stack --seconds 0.1 --fps 10 --size 16x16 --out b ";
  for (const std::string bad : {"--speed 0", "--speed 101", "--speed nan", "--fov 170",
                                "--fov 1", "--eye 1,2", "--target a,b,c", "--eye 1e7,0,0",
                                "--eye 1,2,3 --target 1,2,3"}) {
    INFO(bad);
    const Result r = cps_run(quick + bad, dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(bad.substr(0, bad.find(' '))) != std::string::npos);
  }
  CHECK(!fs::exists(dir / "b"));
  // Eye, target and field of view are recorded with the camera actually used.
  REQUIRE(cps_run(quick + "--eye 10,8,20 --target 0,2,0 --fov 30", dir).exit_code == 0);
  const nlohmann::json c = nlohmann::json::parse(slurp(dir / "b/stack/run.json"))["parameters"];
  CHECK(c["camera_resolved"]["eye_m"][0] == 10.0);
  CHECK(c["camera_resolved"]["target_m"][1] == 2.0);
  CHECK(c["camera_resolved"]["fov_y_deg"] == 30.0);
}
#endif

TEST_CASE("cps simulate --trace writes every body per step and obeys free fall", "[cli][trace]") {
  const fs::path dir = fresh_dir("trace");
  const Result r = cps_run("simulate stack --seconds 0.5 --trace t.csv", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto rows = read_csv(dir / "t.csv");
  REQUIRE(rows.size() > 1);
  const std::vector<std::string> header = {"step", "t_s", "body", "x_m", "y_m", "z_m",
                                           "qw", "qx", "qy", "qz", "vx_mps", "vy_mps",
                                           "vz_mps", "wx_radps", "wy_radps", "wz_radps"};
  CHECK(rows.front() == header);
  // The stack: the ground plane and 5 cubes; 0.5 s at 60 Hz is 30 steps, plus the state as built.
  const int bodies = 6;
  const int steps = 30;
  REQUIRE(rows.size() == 1u + static_cast<std::size_t>((steps + 1) * bodies));
  const double dt = std::stod(rows[1 + bodies][1]);  // t of step 1
  CHECK(dt == Approx(1.0 / 60.0).margin(1e-9));
  const double g = 10.0;  // m/s^2, the paper's gravity
  for (int n = 0; n <= steps; ++n) {
    for (int b = 0; b < bodies; ++b) {
      const auto& row = rows[static_cast<std::size_t>(1 + n * bodies + b)];
      REQUIRE(row.size() == header.size());
      CHECK(std::stoi(row[0]) == n);
      CHECK(std::stoi(row[2]) == b);
    }
  }
  // Step 0 is the scene as built: cube i at (0, 2 + 3 i, 0) m (Sec. 10.1), at rest.
  for (int i = 0; i < 5; ++i) {
    const auto& row = rows[static_cast<std::size_t>(1 + 1 + i)];
    CHECK(std::stod(row[4]) == Approx(2.0 + 3.0 * i).margin(1e-9));
    CHECK(std::stod(row[11]) == Approx(0.0).margin(1e-12));
  }
  // The bottom cube (body 1, half edge 1.2 m, centre 2 m up) falls freely until it reaches the
  // ground after about sqrt(2 * 0.8 / g) = 0.4 s: semi-implicit Euler (Eq. 3.2.1-3.2.3) gives
  // v_n = -g n dt and y_n = 2 - g dt^2 n (n + 1) / 2 while nothing touches (n <= 20 here).
  for (int n = 1; n <= 20; ++n) {
    const auto& row = rows[static_cast<std::size_t>(1 + n * bodies + 1)];
    INFO("step " << n);
    CHECK(std::stod(row[4]) == Approx(2.0 - g * dt * dt * n * (n + 1) / 2.0).margin(1e-7));
    CHECK(std::stod(row[11]) == Approx(-g * dt * n).margin(1e-7));
  }
  // Afterwards it rests on the ground: y ends near the half edge 1.2 m, not below the ground.
  const auto& last = rows[static_cast<std::size_t>(1 + steps * bodies + 1)];
  CHECK(std::stod(last[4]) > 1.2 - 0.1);
  CHECK(std::stod(last[4]) < 1.2 + 0.1);
}

TEST_CASE("cps simulate --trace keeps a file that is not a trace unless --force", "[cli][trace]") {
  const fs::path dir = fresh_dir("trace_foreign");
  const std::string foreign = "measurements,from,the,lab\n1,2,3,4\n";
  write_text(dir / "lab.csv", foreign);
  const Result r = cps_run("simulate stack --seconds 0.1 --trace lab.csv", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--force") != std::string::npos);
  CHECK(slurp(dir / "lab.csv") == foreign);
  CHECK(!fs::exists(dir / "lab.csv.tmp"));
  // A trace written by cps is replaced without --force; --force replaces the foreign file.
  CHECK(cps_run("simulate stack --seconds 0.1 --trace t.csv", dir).exit_code == 0);
  CHECK(cps_run("simulate stack --seconds 0.2 --trace t.csv", dir).exit_code == 0);
  CHECK(read_csv(dir / "t.csv").size() == 1u + 13u * 6u);
  CHECK(cps_run("simulate stack --seconds 0.1 --trace lab.csv --force", dir).exit_code == 0);
  CHECK(slurp(dir / "lab.csv").rfind("step,t_s,", 0) == 0);
  // A folder that does not exist is created, as for the --out of render and figure.
  const Result missing = cps_run("simulate stack --seconds 0.1 --trace no/such/dir/t.csv", dir);
  CHECK(missing.exit_code == 0);
  CHECK(read_csv(dir / "no/such/dir/t.csv").size() == 1u + 7u * 6u);
  // run.json lists the traces cps wrote in that folder; it is cps's, so replaced without --force.
  const nlohmann::json manifest = nlohmann::json::parse(slurp(dir / "run.json"));
  CHECK(manifest["files"] == nlohmann::json({"t.csv", "lab.csv"}));
  CHECK(manifest["complete"] == true);
}

TEST_CASE("cps simulate --trace never touches a foreign file beside it", "[cli][trace][output]") {
  const fs::path dir = fresh_dir("trace_tmp");
  write_text(dir / "t.csv.tmp", "notes");
  const Result r = cps_run("simulate stack --seconds 0.1 --trace t.csv", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(slurp(dir / "t.csv.tmp") == "notes");
  CHECK(slurp(dir / "t.csv").rfind("step,t_s,", 0) == 0);
  // --trace below a file: refused before the run, naming it.
  write_text(dir / "somefile", "not a folder");
  const Result below = cps_run("simulate stack --seconds 0.1 --trace somefile/t.csv", dir);
  CHECK(below.exit_code == 2);
  CHECK(below.err.find("somefile") != std::string::npos);
  CHECK(slurp(dir / "somefile") == "not a folder");
}

TEST_CASE("every command's --help states the units of its options", "[cli][help]") {
  const fs::path dir = fresh_dir("help");
  struct Case {
    std::string command;
    std::vector<std::string> says;
  };
  std::vector<Case> cases = {
      {"list", {"(s)"}},
      {"simulate", {"(s)", "(m)", "(m/s)", "(rad/s)", "--trace", "--force", "never touched"}},
      {"report", {"warm start 0.8 and 1", "--repeats N", "[3, 100]", "CPU time", "INCOMPLETE", "--out TEXT=out/report"}},
      {"bench", {"us/step"}},
  };
#ifdef CPS_HAVE_RENDERER
  for (const std::string c : {"render", "figure"}) {
    cases.push_back({c,
                     {"(s)", "pixels", "degrees per", "--contacts", "--no-rods", "--label",
                      "--camera TEXT:{preset,auto,fit,fit:panel,fit:frame,front,side,top,track:BODY}=preset", "--orbit", "=0",
                      "--eye", "--target", "--fov"}});
  }
  cases[cases.size() - 2].says.push_back("never removed or changed");  // render --force
  cases[cases.size() - 2].says.push_back("--speed");
  cases.back().says.push_back("never touched");                         // figure --force
  cases.back().says.push_back("--size TEXT=640x360");
  cases.back().says.push_back("--times");
#endif
  for (const Case& c : cases) {
    const Result r = cps_run(c.command + " --help", dir);
    INFO("cps " << c.command << " --help");
    CHECK(r.exit_code == 0);
    for (const std::string& s : c.says) {
      INFO(s);
      CHECK(r.out.find(s) != std::string::npos);
    }
  }
}
