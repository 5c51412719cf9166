// `cps diff` as CI uses it: identical renders pass (exit 0, nothing written), changed ones fail
// (exit 1) with a diff picture per frame past the tolerance, unmatched frames fail, bad input
// exits 2.
#include "cps/render/renderer.h"

#include "cli_support.h"
#include "skip.h"

#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using cli_test::Result;
using cli_test::run_cps;

// With the process id: these tests also run a second time at once, with libOSMesa hidden
// (tests/without_osmesa.sh).
fs::path fresh_dir(const std::string& name) {
  return cli_test::fresh_dir("cps_cli_diff_test_" + name + "_" + std::to_string(::getpid()));
}

const std::string k_frames = " --seconds 1 --fps 2 --size 96x72";

long long red_pixels(const cps::render::Image& image) {
  long long n = 0;
  for (std::size_t p = 0; p < image.pixels.size(); p += 3) {
    if (image.pixels[p] == 255 && image.pixels[p + 1] == 0 && image.pixels[p + 2] == 0) ++n;
  }
  return n;
}

void put_be32(std::vector<unsigned char>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<unsigned char>(v >> shift));
}

// One PNG chunk (PNG spec 5.3): length, type, data, CRC-32 of type and data.
void put_chunk(std::vector<unsigned char>& out, const char* type, const std::vector<unsigned char>& data) {
  put_be32(out, static_cast<std::uint32_t>(data.size()));
  std::vector<unsigned char> typed(type, type + 4);
  typed.insert(typed.end(), data.begin(), data.end());
  out.insert(out.end(), typed.begin(), typed.end());
  put_be32(out, static_cast<std::uint32_t>(crc32(0L, typed.data(), static_cast<uInt>(typed.size()))));
}

// A truecolour PNG of `width` x `height` pixels declared, `bit_depth` 8 or 16, every sample
// `sample` (in the depth's range), without gAMA or sRGB. `rows` rows are stored (fewer than
// declared makes a file that claims more than it holds).
std::vector<unsigned char> png_file(std::uint32_t width, std::uint32_t height, int bit_depth,
                                    unsigned sample, std::uint32_t rows) {
  std::vector<unsigned char> file = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<unsigned char> ihdr;
  put_be32(ihdr, width);
  put_be32(ihdr, height);
  // bit depth, colour type 2 (truecolour), compression, filter and interlace methods 0
  ihdr.insert(ihdr.end(), {static_cast<unsigned char>(bit_depth), 2, 0, 0, 0});
  put_chunk(file, "IHDR", ihdr);
  std::vector<unsigned char> raw;
  for (std::uint32_t y = 0; y < rows; ++y) {
    raw.push_back(0);  // filter type none
    for (std::uint32_t i = 0; i < width * 3; ++i) {
      if (bit_depth == 16) raw.push_back(static_cast<unsigned char>(sample >> 8));
      raw.push_back(static_cast<unsigned char>(sample & 0xff));
    }
  }
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::vector<unsigned char> idat(size);
  REQUIRE(compress(idat.data(), &size, raw.data(), static_cast<uLong>(raw.size())) == Z_OK);
  idat.resize(size);
  put_chunk(file, "IDAT", idat);
  put_chunk(file, "IEND", {});
  return file;
}

void write_bytes(const fs::path& path, const std::vector<unsigned char>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

TEST_CASE("cps diff passes two renders of one run and writes nothing", "[cli][diff]") {
  const fs::path dir = fresh_dir("same");
  REQUIRE(run_cps("render intersecting_stack" + k_frames + " --out a", dir).exit_code == 0);
  REQUIRE(run_cps("render intersecting_stack" + k_frames + " --out b", dir).exit_code == 0);
  const Result r = run_cps("diff a/intersecting_stack b/intersecting_stack", dir);
  INFO(r.out << r.err);
  CHECK(r.exit_code == 0);
  CHECK(r.out.find("3 of 3 frames within the tolerance") != std::string::npos);
  CHECK(r.out.find("max 0 levels") != std::string::npos);  // llvmpipe, twice on one machine: equal
  CHECK_FALSE(fs::exists(dir / "out"));
  // One file against itself, and the EGL backend against OSMesa where both run here.
  CHECK(run_cps("diff a/intersecting_stack/frame_000001.png a/intersecting_stack/frame_000001.png", dir)
            .exit_code == 0);
  if (run_cps("render intersecting_stack" + k_frames + " --backend egl --out e", dir).exit_code == 0) {
    CHECK(run_cps("diff a/intersecting_stack e/intersecting_stack", dir).exit_code == 0);
  }
  fs::remove_all(dir);
}

TEST_CASE("cps diff fails a changed push and a changed camera, with a picture of where", "[cli][diff]") {
  const fs::path dir = fresh_dir("changed");
  // The fixed view (the scene's default frames each run on its own, so its first frames differ).
  const std::string fixed = k_frames + " --camera preset";
  REQUIRE(run_cps("render intersecting_stack" + fixed + " --out a", dir).exit_code == 0);
  REQUIRE(run_cps("render intersecting_stack" + fixed + " --push split --out b", dir).exit_code == 0);
  REQUIRE(run_cps("render intersecting_stack" + fixed + " --fov 40 --out c", dir).exit_code == 0);
  // The first frame is the start, the same under both pushes; the later ones are not.
  Result r = run_cps("diff a/intersecting_stack b/intersecting_stack --out d", dir);
  INFO(r.out << r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.out.find("frame_000000.png: max 0 levels") != std::string::npos);
  CHECK(r.out.find("2 of 3 frames past the tolerance") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "d/frame_000000-diff.png"));
  const cps::render::Image picture = cps::render::read_png(dir / "d/frame_000002-diff.png");
  CHECK(picture.width == 96);
  CHECK(red_pixels(picture) > 96 * 72 / 1000);  // more than the 0.1 % the tolerance allows
  // Another field of view changes every frame.
  r = run_cps("diff a/intersecting_stack c/intersecting_stack --out d2", dir);
  CHECK(r.exit_code == 1);
  CHECK(r.out.find("3 of 3 frames past the tolerance") != std::string::npos);
  // A looser tolerance passes what it allows: every pixel.
  CHECK(run_cps("diff a/intersecting_stack c/intersecting_stack --tolerance 100 --out d3", dir).exit_code == 0);
  fs::remove_all(dir);
}

TEST_CASE("cps diff fails unmatched frames and refuses bad input", "[cli][diff]") {
  const fs::path dir = fresh_dir("bad");
  REQUIRE(run_cps("render stack" + k_frames + " --out a", dir).exit_code == 0);
  REQUIRE(run_cps("render stack --seconds 0.5 --fps 2 --size 96x72 --out b", dir).exit_code == 0);
  REQUIRE(run_cps("render stack --seconds 0.5 --fps 2 --size 64x48 --out c", dir).exit_code == 0);
  Result r = run_cps("diff a/stack b/stack", dir);
  CHECK(r.exit_code == 1);
  CHECK(r.out.find("frame_000002.png: only in a/stack") != std::string::npos);
  r = run_cps("diff b/stack c/stack", dir);
  CHECK(r.exit_code == 1);
  CHECK(r.out.find("sizes differ (96x72 and 64x48)") != std::string::npos);
  std::ofstream(dir / "not.png") << "not a picture";
  for (const char* bad : {"diff a/stack nosuch", "diff a/stack a/stack/frame_000000.png",
                                 "diff not.png a/stack/frame_000000.png",
                                 "diff a/stack b/stack --threshold 256", "diff a/stack b/stack --tolerance -1"}) {
    INFO(bad);
    r = run_cps(bad, dir);
    CHECK(r.exit_code == 2);
    CHECK_FALSE(r.err.empty());
  }
  CHECK_FALSE(fs::exists(dir / "out"));
  fs::remove_all(dir);
}

namespace {

/// Renders the five paper scenes as the baselines were made (frames at 0, 1 and 2 s, 160x120)
/// through `backend` into dir/backend and compares each with its baseline (assets/baselines,
/// scripts/update-baselines.sh). Returns cps's message if the backend does not render here (the
/// first scene failed), else "" after checking every scene.
std::string check_baselines(const fs::path& dir, const std::string& backend) {
  const fs::path baselines = CPS_BASELINES;
  const fs::path out = dir / backend;
  for (const char* scene : {"stack", "intersecting_stack", "funnel", "pendulum_grid", "pendulum_wave"}) {
    INFO(backend << " " << scene);
    const Result render = run_cps(std::string("render ") + scene + " --seconds 2 --fps 1 --size 160x120" +
                                      " --backend " + backend + " --out '" + out.string() + "'",
                                  dir);
    if (render.exit_code != 0 && std::string(scene) == "stack") return render.err;
    INFO(render.err);
    REQUIRE(render.exit_code == 0);
    const Result r = run_cps("diff '" + (baselines / scene).string() + "' '" + (out / scene).string() +
                                 "' --out '" + (dir / "diff").string() + "'",
                             dir);
    INFO(r.out << r.err);
    CHECK(r.exit_code == 0);
  }
  return "";
}

}  // namespace

TEST_CASE("the paper scenes render as their baselines through auto's backend, and a change fails",
          "[cli][diff][baselines]") {
  const fs::path baselines = CPS_BASELINES;
  const fs::path dir = fresh_dir("baselines");
  const std::string frames = " --seconds 2 --fps 1 --size 160x120";
  // auto must render (OSMesa where libOSMesa loads, else EGL).
  const std::string auto_failed = check_baselines(dir, "auto");
  INFO(auto_failed);
  REQUIRE(auto_failed.empty());
  // Tests that must fail: the paper's push replaced, and the camera's field of view changed.
  CHECK(run_cps("render intersecting_stack" + frames + " --push split --out changed", dir).exit_code == 0);
  CHECK(run_cps("render stack" + frames + " --fov 40 --out changed", dir).exit_code == 0);
  for (const char* scene : {"intersecting_stack", "stack"}) {
    INFO(scene);
    const Result r = run_cps("diff '" + (baselines / scene).string() + "' changed/" + scene + " --out d", dir);
    CHECK(r.exit_code == 1);
  }
  fs::remove_all(dir);
}

TEST_CASE("the paper scenes render as their baselines through OSMesa", "[cli][diff][baselines]") {
  const fs::path dir = fresh_dir("baselines_osmesa");
  const std::string failed = check_baselines(dir, "osmesa");
  fs::remove_all(dir);
  if (!failed.empty()) CPS_SKIP("the osmesa backend does not render here: " << failed);
}

TEST_CASE("the paper scenes render as their baselines through EGL", "[cli][diff][baselines]") {
  const fs::path dir = fresh_dir("baselines_egl");
  const std::string failed = check_baselines(dir, "egl");
  fs::remove_all(dir);
  if (!failed.empty()) CPS_SKIP("the egl backend does not render here: " << failed);
}

TEST_CASE("cps render --backend egl without an EGL driver says which step failed", "[cli][backends]") {
  // GLVND's libEGL reads its driver list from __EGL_VENDOR_LIBRARY_FILENAMES when set: a missing
  // file leaves it with no driver, as on a machine without libegl-mesa0.
  const fs::path dir = fresh_dir("no_egl");
  const Result r = run_cps("render stack --seconds 0.1 --size 32x24 --backend egl --out out", dir,
                           "__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/cps.json");
  const int code = r.exit_code;
  const std::string err = r.err;
  const bool rendered = fs::exists(dir / "out" / "stack" / "frame_000000.png");
  fs::remove_all(dir);
  INFO("exit " << code << ", stderr:\n" << err);
  if (code == 0) {
    CPS_SKIP("this libEGL ignores __EGL_VENDOR_LIBRARY_FILENAMES (not GLVND?): cannot simulate a "
             "machine without an EGL driver here");
  }
  CHECK(code == 1);
  CHECK(err.find("egl backend") != std::string::npos);
  CHECK(err.find("libegl-mesa0") != std::string::npos);      // what to install
  CHECK(err.find("--backend osmesa") != std::string::npos);  // what to do instead
  CHECK_FALSE(rendered);
}

TEST_CASE("cps diff reads 16-bit PNGs as sRGB, opens only regular files and keeps exit 1 for differing frames",
          "[cli][diff]") {
  const fs::path dir = fresh_dir("hostile");
  // The same grey, 8-bit and 16-bit (x 257), neither with gAMA or sRGB: one picture (PNG spec
  // 11.3.3.2), so no level differs. Read as linear light, 100/255 would become about 175.
  write_bytes(dir / "grey8.png", png_file(32, 24, 8, 100, 24));
  write_bytes(dir / "grey16.png", png_file(32, 24, 16, 100 * 257, 24));
  Result r = run_cps("diff grey8.png grey16.png --threshold 0", dir);
  INFO(r.out << r.err);
  CHECK(r.exit_code == 0);
  CHECK(r.out.find("max 0 levels") != std::string::npos);
  const cps::render::Image grey = cps::render::read_png(dir / "grey16.png");
  CHECK(grey.pixels.at(0) == 100);
  // A file of a few hundred bytes declaring 100000 x 100000 pixels (30 GB of RGB) is refused
  // before its pixels are allocated: under a 512 MiB address-space limit it still exits 2.
  write_bytes(dir / "bomb.png", png_file(100000, 100000, 8, 0, 0));
  CHECK(fs::file_size(dir / "bomb.png") < 1000);
  r = run_cps("diff bomb.png grey8.png", dir, "ulimit -v 524288;");
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("declares 100000x100000 pixels") != std::string::npos);
  // A FIFO named .png is never opened (opening it would block), a link loop is named, and an
  // --out among the compared folders is refused: all exit 2, never 1 ("frames differ").
  REQUIRE(::mkfifo((dir / "fifo.png").c_str(), 0600) == 0);
  fs::create_symlink("loop.png", dir / "loop.png");
  fs::create_directories(dir / "a");
  fs::create_directories(dir / "b");
  fs::copy_file(dir / "grey8.png", dir / "a/frame.png");
  write_bytes(dir / "b/frame.png", png_file(32, 24, 8, 200, 24));
  for (const char* bad : {"diff fifo.png grey8.png", "diff grey8.png loop.png", "diff a b --out b",
                          "diff a/frame.png b/frame.png --out a", "diff a b --out ./a/"}) {
    INFO(bad);
    r = run_cps(bad, dir);
    CHECK(r.exit_code == 2);
    CHECK_FALSE(r.err.empty());
  }
  CHECK(run_cps("diff a b --out d", dir).exit_code == 1);
  CHECK(fs::exists(dir / "d/frame-diff.png"));
  // A diff picture that cannot be written (d is a file) is an error, exit 3, not "frames differ".
  std::ofstream(dir / "e") << "a file";
  r = run_cps("diff a b --out e/sub", dir);
  CHECK(r.exit_code != 0);
  CHECK(r.exit_code != 1);
  fs::remove_all(dir);
}
