// Every OpenGL backend this machine has (OSMesa, EGL) renders the same scene into the same image.
// OSMesa must work unless the build left it out; a case that needs a backend this machine cannot
// create is reported SKIPPED (tests/skip.h).

#include "cps/render/draw_list.h"
#include "cps/render/renderer.h"
#include "skip.h"

#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

using namespace cps::render;

namespace {

constexpr int k_width = 160;
constexpr int k_height = 120;

/// A red box and a blue sphere side by side on a checkered ground plane, lit by the sun (so the
/// image has flat areas, edges, a checker pattern and shadows).
DrawList box_and_sphere() {
  DrawList list;
  BoxItem box;
  box.center = glm::vec3(-1.2f, 0.0f, 0.0f);
  box.half_extents = glm::vec3(1.0f);
  box.orientation = glm::angleAxis(glm::radians(25.0f), glm::vec3(0.0f, 1.0f, 0.0f));
  box.color = glm::vec3(0.9f, 0.1f, 0.1f);
  list.boxes.push_back(box);
  SphereItem sphere;
  sphere.center = glm::vec3(1.4f, 0.0f, 0.5f);
  sphere.radius = 1.0f;
  sphere.color = glm::vec3(0.1f, 0.2f, 0.9f);
  list.spheres.push_back(sphere);
  PlaneItem ground;
  ground.normal = glm::vec3(0.0f, 1.0f, 0.0f);
  ground.offset = -1.0f;  // y = -1: both bodies rest on it
  list.planes.push_back(ground);
  list.camera.eye = glm::vec3(0.0f, 3.0f, 9.0f);
  list.camera.target = glm::vec3(0.0f, -0.3f, 0.0f);
  return list;
}

/// Pixel (column, row from the top) where world point p lands, with the renderer's camera model.
std::array<int, 2> project_to_pixel(const Camera& cam, const glm::vec3& p) {
  const float aspect = static_cast<float>(k_width) / static_cast<float>(k_height);
  const glm::mat4 proj =
      glm::perspective(glm::radians(cam.fov_y_deg), aspect, cam.near_m, cam.far_m);
  const glm::mat4 view = glm::lookAt(cam.eye, cam.target, cam.up);
  const glm::vec3 win = glm::project(
      p, view, proj, glm::vec4(0.0f, 0.0f, static_cast<float>(k_width), static_cast<float>(k_height)));
  return {static_cast<int>(win.x), k_height - 1 - static_cast<int>(win.y)};
}

std::array<int, 3> pixel(const Image& img, const std::array<int, 2>& at) {
  const auto i = (static_cast<std::size_t>(at[1]) * static_cast<std::size_t>(img.width) +
                  static_cast<std::size_t>(at[0])) * 3u;
  return {img.pixels[i], img.pixels[i + 1], img.pixels[i + 2]};
}

/// Mean over all pixels of |a - b| for each channel (0..255 scale). Sizes must match.
std::array<double, 3> mean_abs_diff(const Image& a, const Image& b) {
  REQUIRE(a.width == b.width);
  REQUIRE(a.height == b.height);
  REQUIRE(a.pixels.size() == b.pixels.size());
  std::array<double, 3> sum{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    sum[i % 3] += std::abs(static_cast<int>(a.pixels[i]) - static_cast<int>(b.pixels[i]));
  }
  const double n = static_cast<double>(a.pixels.size() / 3u);
  return {sum[0] / n, sum[1] / n, sum[2] / n};
}

double max_of(const std::array<double, 3>& v) { return std::max({v[0], v[1], v[2]}); }

Image flipped_upside_down(const Image& img) {
  Image out = img;
  const auto row = static_cast<std::size_t>(img.width) * 3u;
  for (int y = 0; y < img.height; ++y) {
    std::copy_n(img.pixels.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(y)), row,
                out.pixels.begin() +
                    static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(img.height - 1 - y)));
  }
  return out;
}

/// The renderer of `backend`, or nullptr with `why` set if this machine cannot create it. OSMesa
/// is required unless this build left it out (CPS_WITH_OSMESA=OFF, or no GL/osmesa.h), and auto
/// always: their failure fails the test.
std::unique_ptr<Renderer> try_renderer(Backend backend, std::string& why) {
  try {
    return std::make_unique<Renderer>(k_width, k_height, backend);
  } catch (const std::runtime_error& e) {
    const bool left_out = std::string(e.what()).find("built without") != std::string::npos;
    if (backend == Backend::osmesa && !left_out) FAIL("the OSMesa backend must work: " << e.what());
    if (backend == Backend::automatic) FAIL("--backend auto must find a backend: " << e.what());
    why = "backend " + std::string(backend_name(backend)) + " unavailable here: " + e.what();
    return nullptr;
  }
}

/// The renderer of auto's backend (OSMesa, or EGL in a build or on a machine without it).
std::unique_ptr<Renderer> automatic_renderer() {
  std::string why;
  return try_renderer(Backend::automatic, why);
}

// Bounds on the mean absolute difference per channel (0..255) between two backends' images.
// Same GL version and renderer string (e.g. llvmpipe through OSMesa and through EGL): the same
// rasterizer runs the same commands, so the images should be identical; 0.05 leaves room for a
// handful of pixels rounded differently and nothing more (moving the box by 5 cm already makes
// 0.7). Different rasterizers (a GPU through EGL): GL fixes pixel centres and coverage rules but
// not the 4x MSAA sample positions nor shader precision. So edge pixels (18% of this frame, the
// checker included: neighbours differing by more than 16) may differ by about one sample in four,
// a quarter of the edge contrast (about 60 for the checker): 0.18 * 60 / 4 = 2.7, plus 1 for
// rounding in flat areas: 4. Leaving the sphere out changes the image by 7.6, checked below, so
// even the looser bound catches a missing body.
constexpr double k_same_rasterizer_bound = 0.05;
constexpr double k_other_rasterizer_bound = 4.0;

}  // namespace

TEST_CASE("auto's backend renders the box and sphere scene, and a changed scene differs", "[backends]") {
  const DrawList list = box_and_sphere();
  // The reference: auto's backend (OSMesa, or EGL in a build or on a machine without it).
  std::unique_ptr<Renderer> first = automatic_renderer();
  REQUIRE(first);
  const Backend reference_backend = first->backend();
  const Image reference = first->draw(list);
  first.reset();

  // The reference shows what it should: the box red, the sphere blue, the ground grey, and the
  // comparison below can tell a wrong image from a right one.
  const auto box_px = pixel(reference, project_to_pixel(list.camera, glm::vec3(-1.2f, 0.3f, 1.0f)));
  const auto sphere_px = pixel(reference, project_to_pixel(list.camera, glm::vec3(1.4f, 0.3f, 1.5f)));
  INFO("box pixel " << box_px[0] << " " << box_px[1] << " " << box_px[2] << ", sphere pixel "
                    << sphere_px[0] << " " << sphere_px[1] << " " << sphere_px[2]);
  CHECK(box_px[0] > box_px[1] + 40);
  CHECK(box_px[0] > box_px[2] + 40);
  CHECK(sphere_px[2] > sphere_px[0] + 40);
  CHECK(sphere_px[2] > sphere_px[1] + 20);
  {
    // Both bounds can fail: real faults exceed them (measured with OSMesa itself).
    std::string why;
    std::unique_ptr<Renderer> check = try_renderer(reference_backend, why);
    REQUIRE(check);
    DrawList no_sphere = list;
    no_sphere.spheres.clear();
    DrawList moved = list;
    moved.boxes.front().center.x += 0.05f;  // m
    CHECK(max_of(mean_abs_diff(reference, check->draw(no_sphere))) > k_other_rasterizer_bound);
    CHECK(max_of(mean_abs_diff(reference, check->draw(moved))) > 4.0 * k_same_rasterizer_bound);
    CHECK(max_of(mean_abs_diff(reference, flipped_upside_down(reference))) >
          k_other_rasterizer_bound);
    CHECK(max_of(mean_abs_diff(reference, check->draw(list))) == 0.0);  // deterministic
  }
}

TEST_CASE("OSMesa and EGL render the box and sphere scene into the same image", "[backends]") {
  const DrawList list = box_and_sphere();
  std::string why;
  std::unique_ptr<Renderer> osmesa = try_renderer(Backend::osmesa, why);
  if (!osmesa) CPS_SKIP(why);
  std::unique_ptr<Renderer> egl = try_renderer(Backend::egl, why);
  if (!egl) CPS_SKIP(why);
  const std::string reference_info = osmesa->context_description();
  const std::string info = egl->context_description();
  const std::array<double, 3> d = mean_abs_diff(osmesa->draw(list), egl->draw(list));
  // Same rasterizer: the GL version and renderer strings after the backend name agree.
  const bool same = reference_info.substr(reference_info.find(": ")) == info.substr(info.find(": "));
  const double bound = same ? k_same_rasterizer_bound : k_other_rasterizer_bound;
  INFO(reference_info << "\n" << info << "\nmean |difference| per channel: " << d[0] << " " << d[1]
                      << " " << d[2] << " (bound " << bound << ")");
  CHECK(d[0] <= bound);
  CHECK(d[1] <= bound);
  CHECK(d[2] <= bound);
}

TEST_CASE("renderers of two backends can be used in turn on one thread", "[backends]") {
  // Each draw makes its renderer's context current and must release the other one: GL calls
  // that reached the wrong context would give a black or stale image.
  std::string why;
  std::unique_ptr<Renderer> osmesa = try_renderer(Backend::osmesa, why);
  if (!osmesa) CPS_SKIP(why);
  std::unique_ptr<Renderer> egl = try_renderer(Backend::egl, why);
  if (!egl) CPS_SKIP(why);
  const DrawList a = box_and_sphere();
  DrawList b = a;
  b.background = glm::vec3(0.2f, 0.1f, 0.1f);
  b.boxes.front().color = glm::vec3(0.1f, 0.9f, 0.1f);
  b.spheres.clear();

  const Image a1 = osmesa->draw(a);
  const Image b1 = egl->draw(b);
  const Image a2 = osmesa->draw(a);
  const Image b2 = egl->draw(b);
  CHECK(max_of(mean_abs_diff(a1, a2)) == 0.0);
  CHECK(max_of(mean_abs_diff(b1, b2)) == 0.0);
  CHECK(max_of(mean_abs_diff(a1, b1)) > 10.0);  // different scenes really were drawn
  // The EGL renderer's image of scene b agrees with OSMesa's (same bound as above).
  const Image b_osmesa = osmesa->draw(b);
  CHECK(max_of(mean_abs_diff(b_osmesa, b1)) <= k_other_rasterizer_bound);
  // Destroying one leaves the other working.
  egl.reset();
  CHECK(max_of(mean_abs_diff(a1, osmesa->draw(a))) == 0.0);
}

TEST_CASE("backend names round trip and unknown names are rejected", "[backends]") {
  for (const Backend b : {Backend::osmesa, Backend::egl, Backend::automatic}) {
    const std::optional<Backend> parsed = parse_backend(backend_name(b));
    REQUIRE(parsed);
    CHECK(*parsed == b);
  }
  CHECK(backend_name(Backend::automatic) == "auto");
  CHECK_FALSE(parse_backend("opengl"));
  CHECK_FALSE(parse_backend(""));
  CHECK_FALSE(parse_backend("EGL"));
}

TEST_CASE("the auto backend takes OSMesa where it renders, else EGL, and says which", "[backends]") {
  std::unique_ptr<Renderer> chosen = automatic_renderer();
  REQUIRE(chosen);
  CHECK(chosen->backend() != Backend::automatic);
  const std::string info = chosen->context_description();
  CHECK(info.rfind(std::string(backend_name(chosen->backend())), 0) == 0);
  chosen.reset();
  bool osmesa_renders = true;
  try {
    Renderer osmesa(k_width, k_height, Backend::osmesa);
  } catch (const std::runtime_error&) {
    osmesa_renders = false;
  }
  Renderer again(k_width, k_height, Backend::automatic);
  CHECK(again.backend() == (osmesa_renders ? Backend::osmesa : Backend::egl));
}
