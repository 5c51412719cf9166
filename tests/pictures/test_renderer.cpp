// Tests of the offscreen renderer (OSMesa), PNG round trip and camera framing helpers.

#include "cps/render/draw_list.h"
#include "cps/render/renderer.h"

#include <catch2/catch.hpp>
#include <zlib.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

namespace fs = std::filesystem;
using namespace cps::render;

namespace {

struct Rgb {
  int r, g, b;
};

Rgb pixel(const Image& img, int x, int y) {
  const auto i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) +
                  static_cast<std::size_t>(x)) * 3u;
  return {img.pixels[i], img.pixels[i + 1], img.pixels[i + 2]};
}

int max_channel_diff(const Rgb& a, const Rgb& b) {
  return std::max({std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
}

Rgb to_bytes(const glm::vec3& c) {
  return {static_cast<int>(std::lround(c.r * 255.0f)), static_cast<int>(std::lround(c.g * 255.0f)),
          static_cast<int>(std::lround(c.b * 255.0f))};
}

/// A fresh, empty folder under the system temp folder, removed at scope exit.
struct TempDir {
  fs::path path;
  TempDir() {
    std::random_device rd;
    path = fs::temp_directory_path() / ("cps_test_renderer_" + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

/// A plain file sink for these tests (the cps command writes atomically, see demos/cps/output.h):
/// writes `bytes` to `path`, throws std::runtime_error naming the path if it cannot.
void write_bytes(const fs::path& path, std::span<const std::uint8_t> bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

/// `image` encoded as a PNG file at `path`.
void write_png(const fs::path& path, const Image& image) { write_bytes(path, encode_png(image)); }

DrawList red_box_scene() {
  DrawList list;
  BoxItem box;
  box.center = glm::vec3(0.0f);
  box.half_extents = glm::vec3(1.0f);
  box.color = glm::vec3(0.9f, 0.1f, 0.1f);
  list.boxes.push_back(box);
  PlaneItem ground;
  ground.normal = glm::vec3(0.0f, 1.0f, 0.0f);
  ground.offset = -1.0f;  // y = -1, under the box
  list.planes.push_back(ground);
  list.camera.eye = glm::vec3(0.0f, 2.0f, 8.0f);
  list.camera.target = glm::vec3(0.0f);
  list.camera.up = glm::vec3(0.0f, 1.0f, 0.0f);
  list.camera.fov_y_deg = 45.0f;
  list.camera.near_m = 0.1f;
  list.camera.far_m = 200.0f;
  list.background = glm::vec3(0.86f, 0.90f, 0.95f);
  return list;
}

/// Pixel (column, row from the top) where world point p lands, with the renderer's camera model.
std::array<int, 2> project_to_pixel(const Camera& cam, int width, int height, const glm::vec3& p) {
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const glm::mat4 proj =
      glm::perspective(glm::radians(cam.fov_y_deg), aspect, cam.near_m, cam.far_m);
  const glm::mat4 view = glm::lookAt(cam.eye, cam.target, cam.up);
  const glm::vec3 win = glm::project(p, view, proj,
                                     glm::vec4(0.0f, 0.0f, static_cast<float>(width),
                                               static_cast<float>(height)));
  const int x = static_cast<int>(win.x);
  const int y = height - 1 - static_cast<int>(win.y);  // window y goes up, image rows go down
  return {x, y};
}

}  // namespace

TEST_CASE("renderer draws a lit box over a plane and the PNG round trips", "[renderer]") {
  constexpr int w = 160;
  constexpr int h = 120;
  Renderer renderer(w, h);
  REQUIRE(renderer.width() == w);
  REQUIRE(renderer.height() == h);

  const DrawList list = red_box_scene();
  const Image img = renderer.draw(list);
  REQUIRE(img.width == w);
  REQUIRE(img.height == h);
  REQUIRE(img.pixels.size() == static_cast<std::size_t>(w * h * 3));

  const Rgb bg = to_bytes(list.background);
  const auto [cx, cy] = project_to_pixel(list.camera, w, h, glm::vec3(0.0f));
  REQUIRE(cx >= 0);
  REQUIRE(cx < w);
  REQUIRE(cy >= 0);
  REQUIRE(cy < h);
  const Rgb centre = pixel(img, cx, cy);
  INFO("box centre pixel (" << cx << ", " << cy << ") = " << centre.r << " " << centre.g << " "
                            << centre.b);
  CHECK(max_channel_diff(centre, bg) > 60);
  CHECK(centre.r > centre.g + 40);  // it is the red box, not the grey ground
  CHECK(centre.r > centre.b + 40);

  // Top corners look over the horizon: pure background.
  for (int x : {0, w - 1}) {
    const Rgb sky = pixel(img, x, 0);
    INFO("sky pixel (" << x << ", 0) = " << sky.r << " " << sky.g << " " << sky.b);
    CHECK(max_channel_diff(sky, bg) <= 2);
  }
  // The ground straight below the box, near the bottom of the frame, is drawn (not background).
  const Rgb ground = pixel(img, w / 2, h - 2);
  CHECK(max_channel_diff(ground, bg) > 10);

  // Drawing the same list again gives the same frame (no state leaks between frames).
  const Image again = renderer.draw(list);
  CHECK(again.pixels == img.pixels);

  TempDir dir;
  const fs::path png = dir.path / "frame.png";
  write_png(png, img);
  REQUIRE(fs::exists(png));
  const Image back = read_png(png);
  CHECK(back.width == w);
  CHECK(back.height == h);
  CHECK(back.pixels == img.pixels);
  // Overwriting an existing frame works too.
  write_png(png, again);
  CHECK(read_png(png).pixels == again.pixels);
}

TEST_CASE("renderer shows the background when the list is empty", "[renderer]") {
  Renderer renderer(32, 24);
  DrawList list;
  list.background = glm::vec3(0.2f, 0.4f, 0.6f);
  const Image img = renderer.draw(list);
  const Rgb bg = to_bytes(list.background);
  for (int y : {0, 12, 23}) {
    for (int x : {0, 16, 31}) CHECK(max_channel_diff(pixel(img, x, y), bg) <= 1);
  }
}

TEST_CASE("renderer draws spheres, lines and translucent planes", "[renderer]") {
  constexpr int w = 120;
  constexpr int h = 90;
  Renderer renderer(w, h);
  DrawList list;
  SphereItem ball;
  ball.center = glm::vec3(0.0f, 0.0f, 0.0f);
  ball.radius = 1.0f;
  ball.color = glm::vec3(0.1f, 0.2f, 0.9f);
  list.spheres.push_back(ball);
  LineItem rod;
  rod.a = glm::vec3(-3.0f, 2.0f, 0.0f);
  rod.b = glm::vec3(3.0f, 2.0f, 0.0f);
  rod.color = glm::vec3(0.0f);
  rod.width_px = 3.0f;
  list.lines.push_back(rod);
  list.camera.eye = glm::vec3(0.0f, 0.0f, 10.0f);
  list.camera.target = glm::vec3(0.0f);
  const Rgb bg = to_bytes(list.background);

  const Image opaque = renderer.draw(list);
  const auto [sx, sy] = project_to_pixel(list.camera, w, h, ball.center);
  const Rgb s = pixel(opaque, sx, sy);
  CHECK(s.b > s.r + 30);  // the blue ball
  const auto [lx, ly] = project_to_pixel(list.camera, w, h, glm::vec3(2.5f, 2.0f, 0.0f));
  const Rgb l = pixel(opaque, lx, ly);
  INFO("line pixel " << l.r << " " << l.g << " " << l.b);
  CHECK(max_channel_diff(l, bg) > 100);  // the black rod

  // A half-transparent plane in front of the ball (between it and the camera): the ball still
  // shows through, but its pixel changes.
  PlaneItem glass;
  glass.normal = glm::vec3(0.0f, 0.0f, 1.0f);
  glass.offset = 2.0f;  // z = 2
  glass.half_size = 4.0f;
  glass.alpha = 0.5f;
  glass.color_a = glass.color_b = glm::vec3(1.0f, 1.0f, 0.0f);
  list.planes.push_back(glass);
  const Image behind = renderer.draw(list);
  const Rgb t = pixel(behind, sx, sy);
  CHECK(max_channel_diff(t, s) > 20);
  CHECK(t.b > 40);  // blue still contributes
}

TEST_CASE("renderer rejects invalid sizes", "[renderer]") {
  CHECK_THROWS_AS(Renderer(0, 10), std::invalid_argument);
  CHECK_THROWS_AS(Renderer(-1, 10), std::invalid_argument);
  CHECK_THROWS_AS(Renderer(9000, 10), std::invalid_argument);
  CHECK_THROWS_AS(Renderer(10, 0), std::invalid_argument);
  CHECK_THROWS_AS(Renderer(10, -1), std::invalid_argument);
  CHECK_THROWS_AS(Renderer(10, 9000), std::invalid_argument);
  CHECK_THROWS_WITH(Renderer(9000, 10), Catch::Contains("9000"));
  CHECK_NOTHROW(Renderer(1, 1));
}

TEST_CASE("encode_png refuses invalid images, read_png names the path it cannot read",
          "[renderer]") {
  TempDir dir;
  Image img;
  img.width = 4;
  img.height = 3;
  img.pixels.assign(4 * 3 * 3, 128);
  CHECK(encode_png(img).size() > 8);
  Image empty;
  CHECK_THROWS_AS(encode_png(empty), std::invalid_argument);
  Image short_pixels = img;
  short_pixels.pixels.pop_back();
  CHECK_THROWS_AS(encode_png(short_pixels), std::invalid_argument);
  CHECK_THROWS_WITH(encode_png(short_pixels), Catch::Contains("4x3"));

  CHECK_THROWS_AS(read_png(dir.path / "nope.png"), std::runtime_error);
  CHECK_THROWS_WITH(read_png(dir.path / "nope.png"), Catch::Contains("nope.png"));
}

TEST_CASE("bounds covers rotated boxes and spheres", "[renderer]") {
  DrawList list;
  glm::vec3 lo(7.0f);
  glm::vec3 hi(7.0f);
  CHECK_FALSE(bounds(list, lo, hi));
  CHECK(lo == glm::vec3(7.0f));  // untouched
  CHECK(hi == glm::vec3(7.0f));

  BoxItem box;
  box.center = glm::vec3(1.0f, 2.0f, 3.0f);
  box.half_extents = glm::vec3(1.0f, 2.0f, 3.0f);
  box.orientation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0.0f, 1.0f, 0.0f));
  list.boxes.push_back(box);
  SphereItem ball;
  ball.center = glm::vec3(-5.0f, 0.0f, 3.0f);
  ball.radius = 0.5f;
  list.spheres.push_back(ball);
  REQUIRE(bounds(list, lo, hi));
  // 90 degrees about y swaps the x and z half extents.
  CHECK(lo.x == Approx(-5.5f));
  CHECK(hi.x == Approx(1.0f + 3.0f).margin(1e-5));
  CHECK(lo.y == Approx(-0.5f));
  CHECK(hi.y == Approx(4.0f));
  CHECK(lo.z == Approx(2.0f).margin(1e-5));
  CHECK(hi.z == Approx(4.0f).margin(1e-5));
}

TEST_CASE("frame_bounds keeps the whole box in view", "[renderer]") {
  const glm::vec3 lo(-1.2f, 0.0f, -1.2f);
  const glm::vec3 hi(1.2f, 12.0f, 1.2f);  // a tall stack
  const glm::vec3 lo2(-6.0f, 0.0f, -0.5f);
  const glm::vec3 hi2(6.0f, 1.0f, 0.5f);  // a wide row
  for (const auto& [l, h] : {std::pair{lo, hi}, std::pair{lo2, hi2}}) {
    for (float aspect : {16.0f / 9.0f, 1.0f}) {
      const Camera cam = frame_bounds(l, h, aspect);
      INFO("aspect " << aspect << ", box height " << (h.y - l.y));
      CHECK(cam.eye.z > cam.target.z);  // in front
      CHECK(cam.eye.y > cam.target.y);  // above
      CHECK(cam.eye.x != Approx(cam.target.x));  // to the side
      CHECK(cam.near_m > 0.0f);
      CHECK(cam.far_m > cam.near_m);
      CHECK(glm::all(glm::lessThan(glm::abs(cam.target - 0.5f * (l + h)), glm::vec3(1e-5f))));
      const glm::mat4 proj =
          glm::perspective(glm::radians(cam.fov_y_deg), aspect, cam.near_m, cam.far_m);
      const glm::mat4 view = glm::lookAt(cam.eye, cam.target, cam.up);
      float max_ndc = 0.0f;
      for (int i = 0; i < 8; ++i) {
        const glm::vec3 c((i & 1) ? h.x : l.x, (i & 2) ? h.y : l.y, (i & 4) ? h.z : l.z);
        const glm::vec4 clip = proj * view * glm::vec4(c, 1.0f);
        REQUIRE(clip.w > 0.0f);
        const glm::vec3 ndc = glm::vec3(clip) / clip.w;
        CHECK(std::abs(ndc.x) < 1.0f);
        CHECK(std::abs(ndc.y) < 1.0f);
        CHECK(std::abs(ndc.z) < 1.0f);
        max_ndc = std::max({max_ndc, std::abs(ndc.x), std::abs(ndc.y)});
      }
      // Not absurdly far away either: the box fills a fair part of the frame.
      CHECK(max_ndc > 0.4f);
    }
  }
  CHECK_THROWS_AS(frame_bounds(glm::vec3(1.0f), glm::vec3(0.0f), 1.0f), std::invalid_argument);
  CHECK_THROWS_AS(frame_bounds(lo, hi, 0.0f), std::invalid_argument);
  CHECK_THROWS_AS(frame_bounds(lo, hi, -1.0f), std::invalid_argument);
}

TEST_CASE("encode_png keeps every pixel of noise, flat and tiny images", "[renderer]") {
  // Noise does not compress: the encoder must fall back to stored blocks within its output room.
  // read_png (libpng) checks every chunk's CRC and the zlib stream's Adler-32.
  TempDir dir;
  std::mt19937 rng(12345);
  const auto image = [&](int w, int h, bool noise) {
    Image img;
    img.width = w;
    img.height = h;
    img.pixels.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3u);
    for (std::size_t i = 0; i < img.pixels.size(); ++i) {
      img.pixels[i] = noise ? static_cast<std::uint8_t>(rng() >> 24) : static_cast<std::uint8_t>(60 + i % 3);
    }
    return img;
  };
  for (const auto& [w, h, noise] : {std::tuple{1, 1, true}, std::tuple{333, 257, true},
                                    std::tuple{640, 360, false}, std::tuple{7, 300, true}}) {
    INFO(w << "x" << h << (noise ? " noise" : " flat"));
    const Image img = image(w, h, noise);
    const fs::path png = dir.path / "img.png";
    write_png(png, img);
    const Image back = read_png(png);
    CHECK(back.width == w);
    CHECK(back.height == h);
    CHECK(back.pixels == img.pixels);
    // Noise takes about its raw size (the rows with their filter bytes, plus up to 1 % for block
    // headers and the chunks); a flat image compresses at least 100:1.
    const auto bytes = static_cast<double>(fs::file_size(png));
    const double raw = static_cast<double>((3 * w + 1) * h);
    if (noise) CHECK(bytes < 1.01 * raw + 200.0);
    if (!noise) CHECK(bytes < static_cast<double>(img.pixels.size()) / 100.0);
  }
  // A file cut short is refused, naming the file.
  const Image img = image(64, 48, true);
  write_png(dir.path / "cut.png", img);
  fs::resize_file(dir.path / "cut.png", fs::file_size(dir.path / "cut.png") - 20);
  CHECK_THROWS_WITH(read_png(dir.path / "cut.png"), Catch::Contains("cut.png"));
}

/// Big-endian 32-bit value at p (PNG's byte order).
std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

TEST_CASE("encode_png writes RGB rows unfiltered in one zlib stream, every chunk's CRC right",
          "[renderer]") {
  // The file is taken apart here, without libpng: signature, chunks (each CRC-32 of its type and
  // data, PNG spec 5.3), IHDR 8-bit RGB, and the IDAT data inflated by zlib (which checks the
  // Adler-32): height rows of a filter byte 0 (none) and the image's bytes unchanged. Random
  // content defeats any row filter a writer might pick by itself; sizes go large, small, then
  // large again, so that the encoder's kept buffers are reused and regrown.
  std::mt19937 rng(2017);
  for (const auto& [w, h] : {std::pair{1280, 720}, std::pair{3, 2}, std::pair{1920, 1081}}) {
    INFO(w << "x" << h);
    Image img;
    img.width = w;
    img.height = h;
    img.pixels.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3u);
    // Half the rows noise, half smooth ramps (which row filters up/sub/paeth would shrink).
    for (int y = 0; y < h; ++y) {
      for (int i = 0; i < 3 * w; ++i) {
        const std::size_t k = static_cast<std::size_t>(y) * static_cast<std::size_t>(3 * w) +
                              static_cast<std::size_t>(i);
        img.pixels[k] = (y % 2 == 0) ? static_cast<std::uint8_t>(rng() >> 24)
                                     : static_cast<std::uint8_t>(i / 3 + y);
      }
    }
    const std::span<const std::uint8_t> file = encode_png(img);
    REQUIRE(file.size() > 8u + 25u + 12u + 12u);
    const std::array<std::uint8_t, 8> signature = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
    CHECK(std::equal(signature.begin(), signature.end(), file.begin()));
    std::vector<std::uint8_t> zlib_stream;
    std::vector<std::string> types;
    std::size_t at = 8;
    while (at + 12u <= file.size()) {
      const std::uint32_t length = be32(file.data() + at);
      REQUIRE(at + 12u + length <= file.size());
      const std::uint8_t* type = file.data() + at + 4;
      types.emplace_back(reinterpret_cast<const char*>(type), 4);
      const auto crc = static_cast<std::uint32_t>(crc32(0L, type, static_cast<uInt>(length + 4)));
      CHECK(be32(type + 4 + length) == crc);
      if (types.back() == "IHDR") {
        REQUIRE(length == 13u);
        CHECK(be32(type + 4) == static_cast<std::uint32_t>(w));
        CHECK(be32(type + 8) == static_cast<std::uint32_t>(h));
        CHECK(type[12] == 8);  // bits per sample
        CHECK(type[13] == 2);  // colour type RGB
        CHECK(type[16] == 0);  // no interlace
      }
      if (types.back() == "IDAT") zlib_stream.insert(zlib_stream.end(), type + 4, type + 4 + length);
      at += 12u + length;
    }
    CHECK(at == file.size());
    REQUIRE(types.size() >= 3u);
    CHECK(types.front() == "IHDR");
    CHECK(types.back() == "IEND");

    const std::size_t row = 3u * static_cast<std::size_t>(w);
    std::vector<std::uint8_t> rows((row + 1u) * static_cast<std::size_t>(h) + 1u);  // 1 spare
    uLongf rows_size = static_cast<uLongf>(rows.size());
    REQUIRE(uncompress(rows.data(), &rows_size, zlib_stream.data(),
                       static_cast<uLong>(zlib_stream.size())) == Z_OK);
    REQUIRE(rows_size == (row + 1u) * static_cast<std::size_t>(h));
    int filtered_rows = 0;
    bool same = true;
    for (std::size_t y = 0; y < static_cast<std::size_t>(h); ++y) {
      const std::uint8_t* line = rows.data() + (row + 1u) * y;
      if (line[0] != 0) ++filtered_rows;
      same = same && std::equal(line + 1, line + 1 + row, img.pixels.begin() +
                                                               static_cast<std::ptrdiff_t>(row * y));
    }
    CHECK(filtered_rows == 0);
    CHECK(same);
  }
}

TEST_CASE("PngWriter writes every queued image and reports a failed write by its path",
          "[renderer]") {
  TempDir dir;
  Image img;
  img.width = 40;
  img.height = 30;
  img.pixels.resize(40 * 30 * 3);
  for (std::size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = static_cast<std::uint8_t>(i * 7);

  SECTION("all images arrive, byte for byte, each through the sink") {
    PngWriter writer(write_bytes, 2, 3);
    for (int k = 0; k < 12; ++k) writer.write(dir.path / (std::to_string(k) + ".png"), img);
    writer.finish();
    CHECK(writer.written() == 12);
    for (int k = 0; k < 12; ++k) {
      const Image back = read_png(dir.path / (std::to_string(k) + ".png"));
      CHECK(back.width == 40);
      CHECK(back.height == 30);
      CHECK(back.pixels == img.pixels);  // PNG is lossless
    }
    for (const fs::directory_entry& e : fs::directory_iterator(dir.path)) {
      CHECK(e.path().extension() == ".png");
    }
  }
  SECTION("a failed write stops the queue and is thrown with its path") {
    PngWriter writer(write_bytes, 1, 2);
    writer.write(dir.path / "missing_folder" / "a.png", img);
    CHECK_THROWS_WITH(writer.finish(), Catch::Contains("missing_folder"));
    CHECK_THROWS_AS(writer.write(dir.path / "b.png", img), std::runtime_error);
    CHECK_FALSE(fs::exists(dir.path / "b.png"));
  }
  SECTION("an invalid image is reported with its path, and the sink is not called") {
    int calls = 0;
    PngWriter writer([&calls](const fs::path&, std::span<const std::uint8_t>) { ++calls; }, 1, 2);
    Image bad = img;
    bad.pixels.pop_back();
    writer.write(dir.path / "bad.png", bad);
    CHECK_THROWS_WITH(writer.finish(), Catch::Contains("bad.png"));
    CHECK(calls == 0);
  }
  CHECK_THROWS_AS(PngWriter(write_bytes, 0, 3), std::invalid_argument);
  CHECK_THROWS_AS(PngWriter(write_bytes, 2, 1), std::invalid_argument);
  CHECK_THROWS_AS(PngWriter(FileSink(), 1, 3), std::invalid_argument);
}

TEST_CASE("spheres stay round at every level of detail", "[renderer]") {
  // A sphere of radius r seen from distance D covers about pi * (r * f / D)^2 pixels, f the
  // focal length in pixels. From far (a few pixels across, the coarsest mesh) to near (the
  // finest), the covered area stays within 8 % of the disc (the coarsest mesh allowed at a
  // radius deviates by at most 0.5 px; an icosahedron, the level below, would lose about 17 %).
  constexpr int w = 320;
  constexpr int h = 240;
  Renderer renderer(w, h);
  const float f = 0.5f * static_cast<float>(h) / std::tan(glm::radians(22.5f));
  for (const float radius_px : {6.0f, 12.0f, 30.0f, 60.0f, 100.0f}) {
    DrawList list;
    list.camera.eye = glm::vec3(0.0f, 0.0f, 20.0f);
    list.camera.target = glm::vec3(0.0f);
    list.camera.fov_y_deg = 45.0f;
    SphereItem ball;
    // The projected radius of a sphere is r f / sqrt(D^2 - r^2); solve for r at D = 20 m.
    const float t = radius_px / f;
    ball.radius = 20.0f * t / std::sqrt(1.0f + t * t);
    ball.color = glm::vec3(0.9f, 0.1f, 0.1f);
    list.spheres.push_back(ball);
    const Image img = renderer.draw(list);
    const Rgb bg = to_bytes(list.background);
    double covered = 0.0;  // pixels clearly not background: edge pixels about half covered count
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) covered += max_channel_diff(pixel(img, x, y), bg) > 60 ? 1.0 : 0.0;
    }
    const double disc = 3.14159265 * static_cast<double>(radius_px) * radius_px;
    INFO("radius " << radius_px << " px: " << covered << " px covered, disc " << disc);
    CHECK(covered == Approx(disc).epsilon(0.08));
  }
}

TEST_CASE("renderer draws a still view's frames as a fresh renderer draws each", "[renderer]") {
  // Once the view has stayed for a frame, the renderer redraws only the rectangle where bodies,
  // lines and shadows are, over a kept frame of the planes alone (renderer.cpp): every pixel
  // must still be the same, to the bit, as a renderer without history draws it. The frames move
  // a box, a ball and a line over a ground plane behind a translucent wall, then take the ball
  // behind the eye (the whole frame is redrawn), then leave only the planes.
  constexpr int w = 200;
  constexpr int h = 150;
  Renderer kept(w, h);
  DrawList list = red_box_scene();
  PlaneItem wall;
  wall.normal = glm::normalize(glm::vec3(0.3f, 0.0f, -1.0f));
  wall.offset = -3.0f;
  wall.center_hint = glm::vec3(0.0f, 0.0f, 3.0f);
  wall.half_size = 2.0f;
  wall.alpha = 0.4f;
  list.planes.push_back(wall);
  SphereItem ball;
  ball.radius = 0.4f;
  ball.color = glm::vec3(0.1f, 0.3f, 0.9f);
  list.spheres.push_back(ball);
  LineItem rod;
  rod.width_px = 3.0f;
  list.lines.push_back(rod);
  for (int k = 0; k < 7; ++k) {
    const float t = 0.3f * static_cast<float>(k);
    list.boxes[0].center = glm::vec3(-1.0f + t, 0.5f * t, -0.5f * t);
    list.boxes[0].orientation = glm::angleAxis(t, glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f)));
    list.spheres[0].center = k == 5 ? glm::vec3(0.0f, 2.0f, 9.0f) : glm::vec3(1.5f - t, 1.0f, t);
    list.lines[0].a = list.spheres[0].center;
    list.lines[0].b = glm::vec3(1.5f, 3.0f, 0.0f);
    if (k == 6) {
      list.boxes.clear();
      list.spheres.clear();
      list.lines.clear();
    }
    const Image frame = kept.draw(list);
    Renderer fresh(w, h);
    const Image expected = fresh.draw(list);
    INFO("frame " << k);
    CHECK(frame.pixels == expected.pixels);
  }
}
