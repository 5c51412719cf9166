// Lower limits that mean something and names taken exactly, through the cps command as a user
// runs it: a run of at least one step, a frame rate of one frame in the longest run or more, a
// scene file written as .json, scaled scene names without leading zeros, and "did you mean" for
// a mistyped scene or option. Each refused with exit 2, nothing written.
#include "cli_support.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using cli_test::fresh_dir;
using cli_test::Result;
using cli_test::run_cps;

namespace {

// Exit 2, a message that contains `says`, and an empty working folder (nothing written).
void check_refused(const std::string& args, const std::string& says) {
  const fs::path dir = fresh_dir("cps_limits");
  const Result r = run_cps(args, dir);
  INFO("cps " << args << "\nstderr: " << r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find(says) != std::string::npos);
  CHECK(fs::is_empty(dir));
}

}  // namespace

TEST_CASE("a run is at least one step, and a frame rate at least one frame a longest run",
          "[cli][limits]") {
  // 1e-300 s is no step of dt = 1/60 s: refused, not a run of 0 steps with exit 0.
  check_refused("simulate stack --seconds 1e-300", "less than one step");
  check_refused("simulate stack --seconds 0.008", "less than one step");  // rounds to 0 steps
  // One frame every 1e300 s: longer than any run may last (1e5 s).
  check_refused("render stack --seconds 0.1 --fps 1e-300 --size 32x32 --out out", "--fps");
  check_refused("export stack --seconds 0.1 --fps 1e-300 --out out/s.glb", "--fps");
  // The controls: one step, and the first frame after the start.
  const fs::path dir = fresh_dir("cps_limits_ok");
  CHECK(run_cps("simulate stack --seconds 0.01", dir).exit_code == 0);  // rounds to 1 step
  CHECK(run_cps("render stack --seconds 0.1 --fps 10 --size 32x32 --out out", dir).exit_code == 0);
}

TEST_CASE("cps scene --out writes only a .json file", "[cli][limits]") {
  check_refused("scene stack --out o", "ending in .json");
  check_refused("scene stack --out o.txt", "ending in .json");
  const fs::path dir = fresh_dir("cps_limits_scene");
  CHECK(run_cps("scene stack --out s.json", dir).exit_code == 0);
  CHECK(fs::is_regular_file(dir / "s.json"));
}

TEST_CASE("scene names are taken exactly, and a mistyped one gets the nearest name",
          "[cli][limits]") {
  check_refused("simulate stack_01 --seconds 0.1", "without leading zeros");  // not stack_1
  check_refused("simulate pyramid_20001 --seconds 0.1", "1..20000");
  check_refused("simulate stak --seconds 0.1", "did you mean 'stack'?");
  check_refused("simulate pendulum_wav --seconds 0.1", "did you mean 'pendulum_wave'?");
  check_refused("simulate chain_hitt --seconds 0.1", "did you mean 'chain_hit'?");
  // Short enough to read: no list of every scene.
  const Result r = run_cps("simulate stak --seconds 0.1", fresh_dir("cps_limits_short"));
  CHECK(r.err.size() < 300);
}

TEST_CASE("a mistyped option gets the nearest one, and figure --seconds points to --times",
          "[cli][limits]") {
  check_refused("simulate stack --iteration 10", "did you mean '--iterations'?");
  check_refused("render stack --fsp 10 --out out", "did you mean '--fps'?");
  check_refused("figure stack --seconds 2 --out out/f.png", "--times");
}

TEST_CASE("times are taken as fractions wherever they are taken, as --dt is", "[cli][limits]") {
  const fs::path dir = fresh_dir("cps_limits_fractions");
  CHECK(run_cps("simulate stack --seconds 1/10", dir).exit_code == 0);
#ifdef CPS_HAVE_RENDERER
  const Result r = run_cps("figure stack --times 0,1/60,1/30 --size 64x64 --out f.png", dir);
  INFO(r.err);
  CHECK(r.exit_code == 0);
#endif
  check_refused("simulate stack --seconds 1/0", "--seconds");
}
