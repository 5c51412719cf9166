// Lower limits that mean something and names taken exactly, through the cps command as a user
// runs it: a run of at least one step, a frame rate of one frame in the longest run or more, a
// scene file written as .json, scaled scene names without leading zeros, and "did you mean" for
// a mistyped scene or option; and the upper limits on a run's work (--max-work) and an export's
// samples. Each refused with exit 2, nothing written.
#include "cli_support.h"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using cli_test::fresh_dir;
using cli_test::Result;
using cli_test::run_cps;

namespace {

// Exit 2, a message that contains `says`, and an empty working folder `folder` (nothing written).
// The folder's name carries the process id: ctest runs each test case in a process of its own,
// in parallel.
void check_refused(const std::string& args, const std::string& says,
                   const std::string& folder = "cps_limits") {
  const fs::path dir = fresh_dir(folder + "_" + std::to_string(::getpid()));
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

TEST_CASE("a run's work, bodies x steps x substeps x iterations, is bounded by --max-work",
          "[cli][limits]") {
  const std::string folder = "cps_limits_work";
  // 6 bodies x 6e6 steps x 1000 substeps x 1e4 iterations = 3.6e14, hundreds of hours.
  const std::string huge = "simulate stack --push soft --soft-substeps 1000 --iterations 10000";
  check_refused(huge + " --seconds 1e5", "3.6e+14 body-iterations", folder);
  check_refused(huge + " --seconds 1e5", "budget of 1e+11 body-iterations", folder);
  check_refused(huge + " --seconds 1e5", "--max-work", folder);
  // The same run for 0.1 s: 3.6e8, within the default budget (the stack is still falling, so
  // it has no rows to solve and takes milliseconds).
  const fs::path dir = fresh_dir("cps_limits_work_ok");
  CHECK(run_cps(huge + " --seconds 0.1", dir).exit_code == 0);
  // Every factor counts, and --max-work moves the budget: 6 x 60 x 25 = 9000 at the defaults,
  // 6 x 60 x 2 x 3 = 2160 with two soft substeps of three iterations.
  check_refused("simulate stack --seconds 1 --max-work 8999", "is 9000 body-iterations", folder);
  CHECK(run_cps("simulate stack --seconds 1 --max-work 9000", dir).exit_code == 0);
  const std::string soft = "simulate stack --seconds 1 --push soft --soft-substeps 2 --iterations 3";
  check_refused(soft + " --max-work 2159", "6 bodies x 60 steps x 2 substeps x 3 iterations", folder);
  CHECK(run_cps(soft + " --max-work 2160", dir).exit_code == 0);
  // The other commands that step a run check it too, before any work.
  check_refused("report intersecting_stack --run intersecting_stack.pgs.baumgarte.fixed.it1.ss1 "
                "--out out --max-work 1",
                "--max-work", folder);
  check_refused("report intersecting_stack --list-runs --out out --max-work 1", "--max-work", folder);
  check_refused("bench --quick --scene intersecting_stack --max-work 1", "--max-work", folder);
  // --list-runs passes a budget on to each run's command.
  const Result list = run_cps("report intersecting_stack --list-runs --out out --max-work 1e12", dir);
  CHECK(list.exit_code == 0);
  CHECK(list.out.find("--run intersecting_stack.pgs.baumgarte.fixed.it1.ss1 --out") != std::string::npos);
  CHECK(list.out.find("--max-work 1e+12\n") != std::string::npos);
#ifdef CPS_HAVE_RENDERER
  check_refused("render stack --seconds 0.1 --fps 10 --size 32x32 --out out --max-work 1",
                "--max-work", folder);
  check_refused("figure stack --times 0,0.1 --size 32x32 --out out/f.png --max-work 1",
                "--max-work", folder);
  check_refused("export stack --seconds 0.1 --fps 10 --out out/s.glb --max-work 1", "--max-work",
                folder);
#endif
}

#ifdef CPS_HAVE_RENDERER
TEST_CASE("an export's samples x bodies are bounded before any step", "[cli][limits]") {
  const std::string folder = "cps_limits_export";
  // 99990 samples of 2004 balls: 5351 MiB of samples, which ran out of memory at 3.2 GB.
  check_refused("export funnel_2000 --seconds 99.989 --fps 1000 --out out/f.glb",
                "99990 samples x (4 B + 2004 bodies x 28 B + 0 rods x 40 B) is 5351 MiB", folder);
  check_refused("export funnel_2000 --seconds 99.989 --fps 1000 --out out/f.glb",
                "lower --fps", folder);
  // Rods count too: 4001 samples of 2000 pendulums is 213 MiB of bodies alone, 519 MiB with
  // their rods, past the 512 MiB.
  check_refused("export pendulum_wave_2000 --seconds 4 --fps 1000 --out out/p.glb",
                "is 519 MiB", folder);
}
#endif
