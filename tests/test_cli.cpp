// The cps command as a user runs it: exit codes, messages, and that bad input writes nothing.
#include "cli_support.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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

Result cps(const std::string& args, const fs::path& dir) { return run_cps(args, dir); }

fs::path fresh_dir(const std::string& name) { return cli_test::fresh_dir("cps_cli_test_" + name); }

// A command line that must be refused, and what its message must name.
struct Case {
  std::string args;
  std::string says;
};

// Each case exits with 2, its message names what it says, and nothing is written to dir/out.
void expect_refused(const std::vector<Case>& cases, const fs::path& dir) {
  for (const Case& c : cases) {
    INFO("cps " << c.args);
    const Result r = cps(c.args, dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
    CHECK(!fs::exists(dir / "out"));
  }
}

}  // namespace

TEST_CASE("bad arguments exit with 2, name the problem and write nothing", "[cli]") {
  const fs::path dir = fresh_dir("bad");
  std::vector<Case> cases = {
      {"render nosuchscene", "unknown scene 'nosuchscene'"},
      {"simulate nosuchscene", "stack"},  // lists the scenes that exist
      {"render stack --size 12x", "--size"},
      {"render stack --size 8x8", "[16, 8192]"},
      {"render stack --fps 0", "--fps"},
      {"render stack --seconds -1", "--seconds"},
      {"render stack --seconds nan", "--seconds"},
      {"render stack --dt abc", "--dt"},
      {"render stack --iterations 0", "--iterations"},
      {"simulate stack --beta 1.5", "--beta"},
      {"simulate stack --friction -0.1", "--friction"},
      {"simulate stack --push sideways", "baumgarte, split"},
      {"render stack --compare push --push split", "--compare push"},
      {"frobnicate", "unknown command 'frobnicate'"},
      {"--nosuch", "--nosuch"},
      {"-z simulate stack", "-z"},
  };
  for (Case& c : cases) {
    if (c.args.rfind("render", 0) == 0) c.args += " --out out";
  }
  expect_refused(cases, dir);
  fs::remove_all(dir);
}

TEST_CASE("work that would not end and malformed numbers are refused before any work",
          "[cli][limits]") {
  const fs::path dir = fresh_dir("limits");
  const std::vector<Case> cases = {
      // Runs that would take forever or overflow a count.
      {"simulate stack --seconds 1e12", "--seconds"},
      {"simulate stack --seconds 1e5 --dt 1e-6", "steps"},
      {"simulate stack --dt 1e-300", "--dt"},
      {"simulate stack --dt 5e-324", "--dt"},
      {"simulate stack --dt 1e308", "--dt"},
      {"simulate stack --iterations 1000000", "--iterations"},
      {"report --run stack.pgs.baumgarte.fixed.it100000.ss100000 --out out", "it100000"},
      {"report --run pendulum_wave.pgs.baumgarte.fixed.it25.ss1001 --out out", "ss1001"},
      // Numbers read one way: decimal, whole, nothing after.
      {"simulate stack --iterations 0x10", "--iterations"},
      {"simulate stack --friction 0x10", "--friction"},
      {"simulate stack --contact-margin 0x10", "--contact-margin"},
      {"simulate stack --dt 0x10", "--dt"},
      {"simulate stack --seconds 1s", "--seconds"},
      {"simulate stack --dt 1/0", "--dt"},
      {"report --run stack.pgs.baumgarte.fixed.it4294967297.ss1 --out out", "it4294967297"},
      {"report --run stack.pgs.baumgarte.fixed.it1x.ss1 --out out", "it1x"},
      // Empty names mean nothing: refused.
      {"report --run '' --out out", "--run"},
      {"report stack --out ''", "--out"},
      {"report --merge '' --out out", "--merge"},
      {"simulate stack --trace ''", "--trace"},
      {"simulate stack --expect-hash ''", "--expect-hash"},
#ifdef CPS_HAVE_RENDERER
      {"render stack --seconds 1e12 --out out", "--seconds"},
      {"render stack --seconds 1e8 --out out", "--seconds"},
      {"render stack --fps 1e308 --out out", "--fps"},
      {"render stack --fps 1e9 --seconds 0.2 --out out", "--fps"},
      {"render stack --fps 1000 --seconds 1000 --out out", "frames"},
      {"render stack --out ''", "--out"},
      {"figure stack --times 0,1 --out ''", "--out"},
      {"figure stack --times 0,1e12 --out out/f.png", "--times"},
      {"figure stack --times 0,1e5 --dt 1e-6 --out out/f.png", "steps"},
#endif
  };
  expect_refused(cases, dir);
  // A time step may be given as a fraction, and means exactly that value.
  const Result fraction = cps("simulate stack --seconds 0.1 --dt 1/60 --json", dir);
  REQUIRE(fraction.exit_code == 0);
  CHECK(nlohmann::json::parse(fraction.out)["parameters"]["dt_s"].get<double>() == 1.0 / 60.0);
  fs::remove_all(dir);
}

TEST_CASE("cps --version names the build; list and unknown scenes name the scaled families",
          "[cli]") {
  const fs::path dir = fresh_dir("version");
  const Result version = cps("--version", dir);
  CHECK(version.exit_code == 0);
  CHECK(version.out.rfind("cps ", 0) == 0);
  const Result list = cps("list", dir);
  CHECK(list.exit_code == 0);
  for (const char* family : {"stack_N", "pyramid_N", "funnel_N", "pendulum_wave_N", "pendulum_grid_N"}) {
    CHECK(list.out.find(family) != std::string::npos);
  }
  const Result unknown = cps("simulate pyramid", dir);
  CHECK(unknown.exit_code == 2);
  CHECK(unknown.err.find("pyramid_N (about N boxes, 1..20000)") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("cps report flags a run whose penetration passes the largest body's size as diverged",
          "[cli][report]") {
  const fs::path dir = fresh_dir("diverged");
  // The funnel's balls are 1 m across. Jacobi at 60 Hz and 16 iterations pushes them metres into
  // each other and the walls (212 m by 10 s, once reported as not diverged); PGS at the paper's
  // settings keeps the penetration under 0.2 m.
  const auto diverged = [&](const std::string& id) {
    const Result r = cps("report --run " + id + " --quick --out runs", dir);
    REQUIRE(r.exit_code == 0);
    std::ifstream csv(dir / "runs" / (id + ".csv"));
    std::string header;
    std::string values;
    std::getline(csv, header);
    std::getline(csv, values);
    const auto column = [](const std::string& line, std::size_t k) {
      std::stringstream s(line);
      std::string cell;
      for (std::size_t i = 0; i <= k; ++i) std::getline(s, cell, ',');
      return cell;
    };
    std::stringstream h(header);
    std::size_t k = 0;
    for (std::string name; std::getline(h, name, ',') && name != "diverged";) ++k;
    return column(values, k) == "1";
  };
  CHECK(diverged("funnel.jacobi.baumgarte.fixed.it16.ss1"));
  CHECK_FALSE(diverged("funnel.pgs.baumgarte.fixed.it25.ss1"));
  fs::remove_all(dir);
}

TEST_CASE("cps list names every scene of the paper", "[cli]") {
  const fs::path dir = fresh_dir("list");
  const Result r = cps("list", dir);
  CHECK(r.exit_code == 0);
  for (const char* scene :
       {"stack", "intersecting_stack", "funnel", "pendulum_grid", "pendulum_wave"}) {
    CHECK(r.out.find(scene) != std::string::npos);
  }
  fs::remove_all(dir);
}

TEST_CASE("cps simulate --json reports parameters, metrics and the final bodies", "[cli]") {
  const fs::path dir = fresh_dir("json");
  const Result r = cps("simulate stack --seconds 1 --dt 0.01 --json", dir);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  CHECK(j["scene"] == "stack");
  CHECK(j["parameters"]["dt_s"].get<double>() == Approx(0.01));
  CHECK(j["parameters"]["iterations"] == 25);
  CHECK(j["steps"] == 100);
  CHECK(j["simulated_s"].get<double>() == Approx(1.0));
  for (const char* key : {"wall_s", "us_per_step"}) CHECK(j[key].get<double>() > 0.0);
  for (const char* key : {"topple_time_s", "max_drift_m", "max_tilt_deg", "max_penetration_m"}) {
    CHECK(j["metrics"].contains(key));
  }
  for (const char* key : {"pairs_tested", "contacts", "rows", "solves"}) {
    CHECK(j["counters"].contains(key));
  }
  REQUIRE(j["bodies"].size() == 5);
  // After 1 s the lowest cube has fallen 0.8 m onto the ground: centre at about 1.2 m.
  CHECK(j["bodies"][0]["position"][1].get<double>() == Approx(1.2).margin(0.05));
  CHECK(j["bodies"][0]["orientation"].size() == 4);
  fs::remove_all(dir);
}

TEST_CASE("cps bench --scene --json times each scene over a window where it is in contact",
          "[cli][bench]") {
  const fs::path dir = fresh_dir("bench_json");
  const Result r = cps("bench --quick --json --scene intersecting_stack --scene funnel", dir);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  REQUIRE(j["physics"].size() == 2);
  CHECK_FALSE(j.contains("growth"));
  CHECK_FALSE(j.contains("rendering"));
  for (const nlohmann::json& row : j["physics"]) {
    INFO(row.dump());
    for (const char* key : {"explicit_us_per_step", "matrix_free_us_per_step"}) {
      CHECK(std::isfinite(row[key].get<double>()));
      CHECK(row[key].get<double>() > 0.0);
    }
    // Timed while the bodies touch: contact points in every scene's window.
    CHECK(row["contacts_per_step"].get<double>() > 0.0);
    CHECK(row["window_end_s"].get<double>() > row["window_start_s"].get<double>());
    CHECK(row["repeats"].get<int>() >= 5);
  }
  // The intersecting stack's cubes part about 0.12 s in and fly until about 3.4 s: its window
  // must close before they part.
  CHECK(j["physics"][0]["scene"] == "intersecting_stack");
  CHECK(j["physics"][0]["window_end_s"].get<double>() <= 0.12);
  CHECK(cps("bench --scene no_such_scene", dir).exit_code == 2);
  CHECK(cps("bench --scene stack --rendering", dir).exit_code == 2);
  fs::remove_all(dir);
}

TEST_CASE("cps simulate --expect-hash exits 1 on another state, 0 on the same", "[cli][state_hash]") {
  const fs::path dir = fresh_dir("hash");
  const Result first = cps("simulate funnel --seconds 0.5 --json", dir);
  REQUIRE(first.exit_code == 0);
  const nlohmann::json j = nlohmann::json::parse(first.out);
  const std::string hash = j["state_hash"];
  CHECK(hash.size() == 16);
  CHECK(hash.find_first_not_of("0123456789abcdef") == std::string::npos);
  CHECK(!j["engine_version"].get<std::string>().empty());
  // The same run again ends in the same state.
  CHECK(cps("simulate funnel --seconds 0.5 --expect-hash " + hash, dir).exit_code == 0);
  // Any other hash: exit 1, both hashes printed.
  std::string wrong = hash;
  wrong[15] = wrong[15] == '0' ? '1' : '0';
  const Result differs = cps("simulate funnel --seconds 0.5 --expect-hash " + wrong, dir);
  CHECK(differs.exit_code == 1);
  CHECK(differs.err.find(hash) != std::string::npos);
  CHECK(differs.err.find(wrong) != std::string::npos);
  // One more step is another state.
  CHECK(cps("simulate funnel --seconds 0.52 --expect-hash " + hash, dir).exit_code == 1);
  // Not a hash: a usage error.
  const Result bad = cps("simulate funnel --seconds 0.5 --expect-hash 12345", dir);
  CHECK(bad.exit_code == 2);
  CHECK(bad.err.find("--expect-hash 12345") != std::string::npos);
  fs::remove_all(dir);
}

#ifdef CPS_HAVE_RENDERER
TEST_CASE("cps render writes numbered frames of the requested size", "[cli][renderer]") {
  const fs::path dir = fresh_dir("render");
  const Result r = cps("render stack --seconds 0.2 --fps 10 --size 64x48 --out out", dir);
  REQUIRE(r.exit_code == 0);
  CHECK(fs::exists(dir / "out/stack/frame_000000.png"));
  CHECK(fs::exists(dir / "out/stack/frame_000002.png"));
  CHECK(!fs::exists(dir / "out/stack/frame_000003.png"));
  // PNG header: the IHDR chunk holds width and height big-endian at bytes 16..23.
  std::ifstream png(dir / "out/stack/frame_000001.png", std::ios::binary);
  unsigned char header[24] = {};
  png.read(reinterpret_cast<char*>(header), sizeof header);
  const int width = (header[16] << 24) | (header[17] << 16) | (header[18] << 8) | header[19];
  const int height = (header[20] << 24) | (header[21] << 16) | (header[22] << 8) | header[23];
  CHECK(width == 64);
  CHECK(height == 48);
  fs::remove_all(dir);
}
#endif

TEST_CASE("cps report writes CSVs with units and plots and report.md and runs spread and merge",
          "[cli][report]") {
  const fs::path dir = fresh_dir("report");
  SECTION("one id, run on its own, then merged with another") {
    const char* ids[] = {"stack.pgs.split.fixed.it4.ss1", "stack.jacobi.split.fixed.it4.ss1"};
    for (const char* id : ids) {
      const Result r = cps(std::string("report --run ") + id + " --out runs --quick", dir);
      REQUIRE(r.exit_code == 0);
      CHECK(fs::exists(dir / "runs" / (std::string(id) + ".csv")));
    }
    const Result merged = cps("report --merge runs --out merged", dir);
    REQUIRE(merged.exit_code == 0);
    const std::string csv = slurp(dir / "merged/stack.csv");
    CHECK(csv.find("wall_s_per_sim_s") != std::string::npos);
    CHECK(csv.find("residual_rms_N") != std::string::npos);
    CHECK(csv.find("penetration_max_m") != std::string::npos);
    CHECK(std::count(csv.begin(), csv.end(), '\n') == 3);  // header and two runs
    CHECK(fs::exists(dir / "merged/report.md"));
    CHECK(fs::file_size(dir / "merged/stack_residual_rms_N.png") > 1000);
    CHECK(fs::exists(dir / "merged/stack_residual_rms_N.svg"));
  }
  SECTION("--list-runs prints one command per run") {
    const Result r = cps("report pendulum_wave --quick --list-runs --out o", dir);
    REQUIRE(r.exit_code == 0);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 25);  // 24 runs and the merge line
    CHECK(r.out.find("report --run pendulum_wave.pgs.baumgarte.fixed.it25.ss1") != std::string::npos);
    CHECK(r.out.find("--merge") != std::string::npos);
  }
  SECTION("a malformed run id is a usage error") {
    const Result r = cps("report --run stack.pgs.sideways.fixed.it4.ss1 --out o", dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("unknown push 'sideways'") != std::string::npos);
    CHECK(!fs::exists(dir / "o"));
  }
  fs::remove_all(dir);
}
