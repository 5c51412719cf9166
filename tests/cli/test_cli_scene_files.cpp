// Scene files through the cps command as a user runs it: `cps scene`, running a file wherever a
// scene name is taken, the errors of a bad file (exit 2, nothing written) and --seed.
#include "cli_support.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#ifdef CPS_HAVE_RENDERER
#include "cps/render/renderer.h"
#endif

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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
  // Names that would print as another (U+202E, a right-to-left override, turns the text after
  // it around), break a line (U+2028), or name cps's own files.
  const std::string plane = R"({"bodies": [{"shape": "plane", "normal": [0, 1, 0], "offset_m": 0}])";
  write(dir / "bidi.json", plane + ", \"name\": \"ab\u202ecd\"}");
  write(dir / "named_run.json", plane + ", \"name\": \"run\"}");
  write(dir / "named_run_json.json", plane + ", \"name\": \"run.json\"}");
  fs::create_directories(dir / "names");
  write(dir / "names/report.json", plane + "}");
  write(dir / "names/mass_ratio.json", plane + "}");
  write(dir / "names/x\u2028y.json", plane + "}");
  write(dir / "names/x\u2028y_named.json", plane + ", \"name\": \"fine\"}");
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
      {"simulate bidi.json", "bidi.json: /name: holds U+202E (a bidirectional control)"},
      {"simulate named_run.json", "would be named \"run\", which is one of cps's own files"},
      {"simulate named_run_json.json", "would be named \"run.json\""},
      {"report names/report.json --out out", "would be named \"report\""},
      {"report names/mass_ratio.json --out out", "would be named \"mass_ratio\""},
      {"scene 'names/x\u2028y.json'", "holds U+2028 (a line or paragraph separator)"},
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
  // A file whose name cannot be used names its outputs by a usable "name".
  CHECK(run_cps("simulate 'names/x\u2028y_named.json' --seconds 0.1", dir).exit_code == 0);
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

// Newton's cradle: five 1 kg balls on 1 m rods, touching, the first raised 60 degrees,
// restitution 1, the default push (Baumgarte).
const fs::path kCradle = CPS_TEST_DATA "/cradle.json";

TEST_CASE("a bouncing cradle under the default push warns that its energy rose, split does not",
          "[cli][scene_file][energy_rise]") {
  const fs::path dir = cli_test::fresh_dir("cps_cli_scene_files_energy");
  fs::copy_file(kCradle, dir / "cradle.json");
  const Result warned = run_cps("simulate cradle.json --json", dir);
  INFO(warned.err);
  CHECK(warned.exit_code == 0);
  CHECK(json::parse(warned.out)["steps"] == 240);  // stdout is the summary alone
  CHECK(warned.err.find("cps: warning: cradle.json: the energy (kinetic + potential) rose") == 0);
  CHECK(warned.err.find("--push baumgarte") != std::string::npos);
  CHECK(warned.err.find("try --push split") != std::string::npos);
  CHECK(std::count(warned.err.begin(), warned.err.end(), '\n') == 1);  // one line
  // The fix it names removes the rise.
  const Result fixed = run_cps("simulate cradle.json --push split", dir);
  INFO(fixed.err);
  CHECK(fixed.exit_code == 0);
  CHECK(fixed.err.find("warning") == std::string::npos);
  // A paper scene that loses energy (the stack lands and stands) does not warn.
  const Result stack = run_cps("simulate stack", dir);
  CHECK(stack.exit_code == 0);
  CHECK(stack.err.find("warning") == std::string::npos);
#ifdef CPS_HAVE_RENDERER
  // render and figure watch their runs too, and write the same files as without the warning.
  const Result render = run_cps("render cradle.json --seconds 2 --fps 2 --size 32x32 --out out", dir);
  INFO(render.err);
  CHECK(render.exit_code == 0);
  CHECK(render.err.find("cps: warning: cradle.json: the energy") != std::string::npos);
  CHECK(fs::exists(dir / "out" / "cradle" / "frame_000004.png"));
  const Result figure = run_cps("figure cradle.json --times 0,2 --size 32x32 --out f.png --compare push=baumgarte,split", dir);
  INFO(figure.err);
  CHECK(figure.exit_code == 0);
  CHECK(figure.err.find("cps: warning: cradle.json (push = baumgarte): the energy") != std::string::npos);
  CHECK(figure.err.find("(push = split)") == std::string::npos);
#endif
}

#ifdef CPS_HAVE_RENDERER
namespace {

// Pixels of `image` that are clearly red (the thrown ball's colour, lit or in shade): red above
// 60 and above twice green and blue; the sky and the grey ground are not.
int red_pixels(const cps::render::Image& image) {
  int count = 0;
  for (std::size_t i = 0; i + 2 < image.pixels.size(); i += 3) {
    const int r = image.pixels[i];
    const int g = image.pixels[i + 1];
    const int b = image.pixels[i + 2];
    if (r > 60 && r > 2 * g && r > 2 * b) ++count;
  }
  return count;
}

}  // namespace

TEST_CASE("a scene file without a camera keeps its moving bodies in every frame",
          "[cli][scene_file][camera]") {
  // A red ball of radius 0.5 m thrown at 8 m/s sideways and 5 m/s up from a grey box at rest: it
  // lands near x = 8 m after 1 s and rolls on, about 14 m away at 2 s, far outside the framing of
  // the bodies as built (about 10 m across around the origin).
  const fs::path dir = cli_test::fresh_dir("cps_cli_scene_files_fit");
  write(dir / "throw.json",
        R"({"seconds": 2, "bodies": [{"shape": "plane", "normal": [0, 1, 0], "offset_m": 0},
            {"shape": "box", "half_extents_m": [0.5, 0.5, 0.5], "mass_kg": 1,
             "position_m": [0, 0.5, 0], "color": "#808080"},
            {"shape": "sphere", "radius_m": 0.5, "mass_kg": 1, "position_m": [1.5, 0.5, 0],
             "velocity_mps": [8, 5, 0], "color": "#ff0000"}]})");
  const Result fit = run_cps("render throw.json --fps 4 --size 160x120 --out fit", dir);
  INFO(fit.err);
  REQUIRE(fit.exit_code == 0);
  CHECK(json::parse(slurp(dir / "fit" / "throw" / "run.json"))["parameters"]["camera"] == "fit");
  // The framing as built (the default before scene files were fitted) loses the ball: the check
  // below can fail.
  const Result as_built = run_cps("render throw.json --fps 4 --size 160x120 --camera auto --out auto", dir);
  REQUIRE(as_built.exit_code == 0);
  int lost_as_built = 0;
  for (int k = 0; k <= 8; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06d.png", k);
    INFO(name);
    CHECK(red_pixels(cps::render::read_png(dir / "fit" / "throw" / name)) >= 4);
    if (red_pixels(cps::render::read_png(dir / "auto" / "throw" / name)) == 0) ++lost_as_built;
  }
  CHECK(lost_as_built >= 2);
}
#endif

TEST_CASE("messages that help: the scene file beside a name, a missing or wrong value, a switch "
          "given twice, and did-you-mean for choices and --compare names",
          "[cli][scene_file][messages]") {
  const fs::path dir = cli_test::fresh_dir("cps-test-messages");
  fs::copy_file(std::string(CPS_TEST_DATA) + "/cradle.json", dir / "cradle.json");
  struct Case {
    std::string args;
    std::vector<std::string> words;  // what the message says
  };
  std::vector<Case> cases = {
      {"simulate cradle --seconds 0.1", {"did you mean the scene file 'cradle.json' in this folder?"}},
      {"simulate stack --seconds 0.1 --solver-error", {"--solver-error needs a value", "CSV"}},
      {"simulate stack --seconds", {"--seconds needs a value", "simulated time (s)"}},
      {"simulate stack --push baumgrate", {"'baumgrate' is not one of", "did you mean 'baumgarte'?"}},
      {"simulate stack --solver jacobbi", {"did you mean 'jacobi'?"}},
  };
#ifdef CPS_HAVE_RENDERER
  cases.push_back({"render stack --rods=maybe --seconds 0.1 --out o",
                   {"--rods is a switch", "not 'maybe'"}});
  cases.push_back({"render stack --label --no-label --seconds 0.1 --out o",
                   {"--label or --no-label given more than once"}});
  cases.push_back({"render stack --compare pussh=baumgarte,split --seconds 0.1 --out o",
                   {"'pussh' is not a parameter --compare takes; did you mean 'push'?"}});
  cases.push_back({"render stack --compare push=baumgarte,splt --seconds 0.1 --out o",
                   {"did you mean 'split'?"}});
#endif
  for (const Case& c : cases) {
    INFO(c.args);
    const Result r = run_cps(c.args, dir);
    INFO(r.err);
    CHECK(r.exit_code == 2);
    for (const std::string& w : c.words) CHECK(r.err.find(w) != std::string::npos);
    CHECK(r.err.find("Could not convert") == std::string::npos);
    CHECK(r.err.find("required TEXT missing") == std::string::npos);
    CHECK_FALSE(fs::exists(dir / "o"));
  }
  fs::remove_all(dir);
}
