// Scene files through the cps command as a user runs it: `cps scene`, running a file wherever a
// scene name is taken, the errors of a bad file (exit 2, nothing written) and --seed.
#include "cli_support.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using cli_test::Result;
using cli_test::run_cps;
using cli_test::slurp;
using nlohmann::json;

namespace {

std::string hash_of(const std::string& args, const fs::path& dir) {
  const Result r = run_cps("simulate " + args + " --json --seconds 1", dir);
  INFO("cps simulate " << args << ": " << r.err);
  REQUIRE(r.exit_code == 0);
  return json::parse(r.out)["state_hash"];
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

}  // namespace

TEST_CASE("cps scene stack > s.json runs to the built-in stack's state_hash", "[cli][scene_file]") {
  const fs::path dir = cli_test::fresh_dir("cps_cli_scene_files_hash");
  for (const std::string scene : {"stack", "intersecting_stack", "funnel", "pendulum_grid",
                                  "pendulum_wave", "random_7"}) {
    INFO(scene);
    const Result r = run_cps("scene " + scene, dir);  // its stdout, as 'cps scene NAME > FILE'
    REQUIRE(r.exit_code == 0);
    write(dir / (scene + ".json"), r.out);
    CHECK(hash_of(scene + ".json", dir) == hash_of(scene, dir));
  }
  // The same through --out, which follows the output rule: a foreign file is kept.
  write(dir / "foreign.json", "{}");
  const Result refused = run_cps("scene stack --out foreign.json", dir);
  CHECK(refused.exit_code == 2);
  CHECK(slurp(dir / "foreign.json") == "{}");
  REQUIRE(run_cps("scene stack --out sub/stack.json", dir).exit_code == 0);
  CHECK(fs::exists(dir / "sub" / "run.json"));
  CHECK(hash_of("sub/stack.json", dir) == hash_of("stack", dir));
  CHECK(run_cps("scene stack --out sub/stack.json", dir).exit_code == 0);  // its own file
}

TEST_CASE("a bad scene file exits 2 naming the file and the pointer, and writes nothing",
          "[cli][scene_file]") {
  const fs::path dir = cli_test::fresh_dir("cps_cli_scene_files_bad");
  write(dir / "typo.json",
        R"({"bodies": [{"shape": "sphere", "radius_m": 1, "mass_kg": 1, "positon_m": [0, 2, 0]}]})");
  write(dir / "notjson.json", "bodies: none\n");
  fs::create_directories(dir / "folder.json");
  struct Case {
    std::string args;
    std::string says;
  };
  const Case cases[] = {
      {"simulate typo.json", "typo.json: /bodies/0/positon_m: unknown key \"positon_m\"; did you mean \"position_m\"?"},
      {"simulate notjson.json", "notjson.json:1:1: not valid JSON"},
      {"simulate missing.json", "missing.json: no such file"},
      {"simulate folder.json", "folder.json: not a regular file"},
      {"report typo.json --out out", "/bodies/0/positon_m"},
      {"bench --scene typo.json", "/bodies/0/positon_m"},
      {"scene typo.json", "/bodies/0/positon_m"},
      {"simulate stack --seed 3", "the scene stack is not random"},
      {"simulate random_2 --seed 3", "already names its seed"},
      {"simulate random --seed x", "give a decimal integer"},
      {"simulate nosuch", "the example scene files"},
#ifdef CPS_HAVE_RENDERER
      {"render typo.json --out out", "/bodies/0/positon_m"},
      {"figure typo.json --times 0 --out out", "/bodies/0/positon_m"},
#endif
  };
  for (const Case& c : cases) {
    INFO("cps " << c.args);
    const Result r = run_cps(c.args, dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
    CHECK(!fs::exists(dir / "out"));
  }
}

TEST_CASE("the seed option makes the random scene random_N, and cps list shows examples and families",
          "[cli][scene_file]") {
  const fs::path dir = cli_test::fresh_dir("cps_cli_scene_files_seed");
  CHECK(hash_of("random --seed 7", dir) == hash_of("random_7", dir));
  CHECK(hash_of("random --seed 1", dir) == hash_of("random", dir));
  const Result list = run_cps("list", dir);
  REQUIRE(list.exit_code == 0);
  for (const char* name : {"dominoes", "chain_hit", "ramp", "random_SEED", "pyramid_N", "1..20000"}) {
    CHECK(list.out.find(name) != std::string::npos);
  }
}

#ifdef CPS_HAVE_RENDERER
TEST_CASE("a scene file renders", "[cli][scene_file]") {
  const fs::path dir = cli_test::fresh_dir("cps_cli_scene_files_render");
  REQUIRE(run_cps("scene chain_hit --out chain.json", dir).exit_code == 0);
  const Result r = run_cps("render chain.json --seconds 0.1 --fps 10 --size 64x48 --out out", dir);
  INFO(r.err);
  CHECK(r.exit_code == 0);
  // Named by the file's "name" (chain_hit), never by the path as typed.
  CHECK(fs::exists(dir / "out" / "chain_hit" / "frame_000000.png"));
  CHECK_FALSE(fs::exists(dir / "out" / "chain.json"));
}
#endif

TEST_CASE("cps report takes a scene file in a folder and writes its files in --out",
          "[cli][scene_file][report]") {
  // A box dropped for 0.25 s: the quick sweep's runs and their reference take a moment.
  const fs::path dir = cli_test::fresh_dir("cps_cli_scene_files_report");
  fs::create_directories(dir / "scenes");
  write(dir / "scenes" / "drop.json",
        R"({"seconds": 0.25, "bodies": [{"shape": "plane", "normal": [0, 1, 0], "offset_m": 0},
            {"shape": "box", "half_extents_m": [0.5, 0.5, 0.5], "mass_kg": 1,
             "position_m": [0, 0.6, 0]}]})");
  // One run, as --list-runs prints it: its CSV is named after the file's stem (it has no
  // "name"), not the folder or the path.
  const Result one = run_cps("report scenes/drop.json --run scenes/drop.json.pgs.baumgarte.fixed.it4.ss1 --out one", dir);
  INFO(one.err);
  REQUIRE(one.exit_code == 0);
  CHECK(fs::exists(dir / "one" / "drop.pgs.baumgarte.fixed.it4.ss1.csv"));
  // The whole quick sweep: report.md links the CSV that is there.
  const Result all = run_cps("report scenes/drop.json --quick --out all", dir);
  INFO(all.err);
  REQUIRE(all.exit_code == 0);
  CHECK(fs::exists(dir / "all" / "drop.csv"));
  CHECK(slurp(dir / "all" / "report.md").find("(drop.csv)") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "all" / "scenes"));
}
