// Where outputs go, as a user and a CI script meet it: other
// commands' files in a frames folder are kept, outputs are named by the scene (never by the path
// of a scene file as typed) and lie under --out, two scenes of one name are refused, and a file
// cps wrote is replaced only while it is what cps wrote, never when it is the command's input.
#include "cli_support.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace {

using cli_test::Result;
using cli_test::run_cps;
using cli_test::slurp;

fs::path fresh_dir(const std::string& name) { return cli_test::fresh_dir("cps_cli_paths_test_" + name); }

void write_text(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream out(p, std::ios::binary);
  out << text;
}

// A box dropped on a plane, for 0.2 s; `name` is its "name" ("" for none).
std::string drop_scene(const std::string& name) {
  return "{" + (name.empty() ? std::string() : "\"name\": \"" + name + "\", ") +
         R"("seconds": 0.2, "bodies": [{"shape": "plane", "normal": [0, 1, 0], "offset_m": 0},
            {"shape": "box", "half_extents_m": [0.5, 0.5, 0.5], "mass_kg": 1,
             "position_m": [0, 0.6, 0]}]})";
}

const char* k_small = "--seconds 0.2 --fps 5 --size 64x48";

}  // namespace

TEST_CASE("render keeps the files other commands wrote in its frames folder", "[cli][output][paths]") {
  const fs::path dir = fresh_dir("others");
  REQUIRE(run_cps("export stack --seconds 0.2 --out res/stack/run.glb", dir).exit_code == 0);
  REQUIRE(run_cps("figure stack --times 0 --size 64x48 --out res/stack/fig.png", dir).exit_code == 0);
  REQUIRE(run_cps("simulate stack --seconds 0.2 --trace res/stack/trace.csv", dir).exit_code == 0);
  const std::string glb = slurp(dir / "res/stack/run.glb");
  const std::string fig = slurp(dir / "res/stack/fig.png");
  const std::string trace = slurp(dir / "res/stack/trace.csv");
  REQUIRE_FALSE(glb.empty());

  for (const char* fps : {"5", "10", "5"}) {  // the second rerun has stale frames to remove
    const Result r = run_cps(std::string("render stack --seconds 0.2 --size 64x48 --fps ") + fps +
                                 " --out res", dir);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(slurp(dir / "res/stack/run.glb") == glb);
    CHECK(slurp(dir / "res/stack/fig.png") == fig);
    CHECK(fs::exists(dir / "res/stack/fig.png.json"));
    CHECK(slurp(dir / "res/stack/trace.csv") == trace);
  }
  CHECK(fs::exists(dir / "res/stack/frame_000001.png"));
  CHECK_FALSE(fs::exists(dir / "res/stack/frame_000002.png"));  // the 10 fps run's, removed
  // run.json still knows every file and who wrote it.
  const nlohmann::json m = nlohmann::json::parse(slurp(dir / "res/stack/run.json"));
  CHECK(m["written"]["run.glb"]["command"] == "export");
  CHECK(m["written"]["trace.csv"]["command"] == "simulate");
  CHECK(m["written"]["frame_000000.png"]["command"] == "render");
  // Figure reruns into the same folder: render's frames are not its to judge.
  CHECK(run_cps("figure stack --times 0 --size 64x48 --out res/stack/fig.png", dir).exit_code == 0);
}

TEST_CASE("a file another command wrote is never replaced, even with --force", "[cli][output][paths]") {
  const fs::path dir = fresh_dir("kinds");
  REQUIRE(run_cps("scene stack --out o/fig.png.json", dir).exit_code == 0);
  const std::string scene = slurp(dir / "o/fig.png.json");
  for (const char* force : {"", " --force"}) {
    const Result r = run_cps(std::string("figure stack --times 0 --size 64x48 --out o/fig.png") + force, dir);
    INFO(r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("fig.png.json was written by cps scene") != std::string::npos);
    CHECK(slurp(dir / "o/fig.png.json") == scene);
    CHECK_FALSE(fs::exists(dir / "o/fig.png"));
  }
}

TEST_CASE("scene files name their outputs, wherever they lie and however they are typed",
          "[cli][output][paths]") {
  const fs::path dir = fresh_dir("names");
  const fs::path work = dir / "work";
  write_text(dir / "data/plain drop.json", drop_scene(""));
  write_text(dir / "data/titled.json", drop_scene("cradle"));
  write_text(dir / "data/\xce\xb2 drop.json", drop_scene(""));  // "β drop"
  fs::create_directories(work);
  const std::string abs = (dir / "data/plain drop.json").string();

  // An absolute path: frames in OUT/STEM/, as a CI script would pass it.
  Result r = run_cps("render '" + abs + "' " + k_small + " --out o", work);
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(fs::exists(work / "o/plain drop/frame_000000.png"));
  // `..`: under --out all the same, nothing written beside the scene file.
  r = run_cps("render '../data/plain drop.json' " + std::string(k_small) + " --out o2", work);
  CHECK(r.exit_code == 0);
  CHECK(fs::exists(work / "o2/plain drop/frame_000000.png"));
  // The file's "name" names its outputs; unicode stems work.
  CHECK(run_cps("render ../data/titled.json " + std::string(k_small) + " --out o3", work).exit_code == 0);
  CHECK(fs::exists(work / "o3/cradle/frame_000000.png"));
  CHECK(run_cps("render '../data/\xce\xb2 drop.json' " + std::string(k_small) + " --out o4", work).exit_code == 0);
  CHECK(fs::exists(work / "o4/\xce\xb2 drop/frame_000000.png"));
  // A figure of an absolute path goes to out/figures, not beside the file.
  r = run_cps("figure '" + abs + "' --times 0 --size 64x48", work);
  CHECK(r.exit_code == 0);
  CHECK(fs::exists(work / "out/figures/plain drop.png"));
  // Nothing but the scene files was ever written into data/.
  std::size_t in_data = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "data")) {
    INFO(e.path());
    CHECK(e.path().extension() == ".json");
    ++in_data;
  }
  CHECK(in_data == 3);
}

TEST_CASE("two scene files of one name into one --out are refused, naming both",
          "[cli][output][paths]") {
  const fs::path dir = fresh_dir("same_stem");
  write_text(dir / "a/x.json", drop_scene(""));
  write_text(dir / "b/x.json", drop_scene(""));
  REQUIRE(run_cps("render a/x.json " + std::string(k_small) + " --out o", dir).exit_code == 0);
  const std::string first = slurp(dir / "o/x/frame_000000.png");
  const Result r = run_cps("render b/x.json " + std::string(k_small) + " --out o", dir);
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find((fs::canonical(dir) / "a/x.json").string()) != std::string::npos);
  CHECK(r.err.find((fs::canonical(dir) / "b/x.json").string()) != std::string::npos);
  CHECK(slurp(dir / "o/x/frame_000000.png") == first);
  // A built-in scene of the file's name is another scene too.
  write_text(dir / "c/stack.json", drop_scene(""));
  REQUIRE(run_cps("render stack " + std::string(k_small) + " --out o", dir).exit_code == 0);
  CHECK(run_cps("render c/stack.json " + std::string(k_small) + " --out o", dir).exit_code == 2);
  // The same file by another path is the same scene; --force replaces the other's.
  CHECK(run_cps("render ./a/../a/x.json " + std::string(k_small) + " --out o", dir).exit_code == 0);
  CHECK(run_cps("render b/x.json " + std::string(k_small) + " --out o --force", dir).exit_code == 0);
}

TEST_CASE("a file cps wrote and the user edited is foreign, and a command never writes over its input",
          "[cli][output][paths]") {
  const fs::path dir = fresh_dir("edited");
  REQUIRE(run_cps("scene stack --out o/s.json", dir).exit_code == 0);
  // A rerun replaces its own file while it is as cps wrote it.
  REQUIRE(run_cps("scene stack --out o/s.json", dir).exit_code == 0);
  std::string text = slurp(dir / "o/s.json");
  text += "\n";  // an edit that keeps it a valid scene file
  write_text(dir / "o/s.json", text);
  Result r = run_cps("scene stack --out o/s.json", dir);
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("changed since cps wrote it") != std::string::npos);
  CHECK(slurp(dir / "o/s.json") == text);
  // The edited scene file is the input of simulate: never its trace, even with --force.
  for (const char* force : {"", " --force"}) {
    r = run_cps(std::string("simulate o/s.json --seconds 0.1 --trace o/s.json") + force, dir);
    INFO(r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("input of this command") != std::string::npos);
    CHECK(slurp(dir / "o/s.json") == text);
  }
  // --force replaces the edited file with cps's own again.
  CHECK(run_cps("scene stack --out o/s.json --force", dir).exit_code == 0);
  CHECK(slurp(dir / "o/s.json") != text);

  // The same for a figure: an edited figure is kept.
  r = run_cps("figure stack --times 0 --size 64x48 --out f/fig.png", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  write_text(dir / "f/fig.png", "my own picture");
  r = run_cps("figure stack --times 0 --size 64x48 --out f/fig.png", dir);
  CHECK(r.exit_code == 2);
  CHECK(slurp(dir / "f/fig.png") == "my own picture");
}

TEST_CASE("report runs of two scene files of one name into one --out are refused, and a merge "
          "never writes over the CSVs it reads", "[cli][output][paths][report]") {
  const fs::path dir = fresh_dir("report");
  write_text(dir / "a/x.json", drop_scene(""));
  write_text(dir / "b/x.json", drop_scene(""));
  Result r = run_cps("report a/x.json --run a/x.json.pgs.baumgarte.fixed.it4.ss1 --out o", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const fs::path csv = dir / "o/x.pgs.baumgarte.fixed.it4.ss1.csv";
  const std::string first = slurp(csv);
  r = run_cps("report b/x.json --run b/x.json.pgs.baumgarte.fixed.it4.ss1 --out o", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("two scenes with one name") != std::string::npos);
  CHECK(slurp(csv) == first);
  // A whole report folder merged into itself: its x.csv is both read and written.
  REQUIRE(run_cps("report a/x.json --quick --out q", dir).exit_code == 0);
  const std::string table = slurp(dir / "q/x.csv");
  r = run_cps("report --merge q --out q", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("is the --merge folder q") != std::string::npos);
  CHECK(slurp(dir / "q/x.csv") == table);
}

TEST_CASE("an output folder through a dangling symbolic link is refused with exit 2, naming the link",
          "[cli][output][paths]") {
  const fs::path dir = fresh_dir("dangling");
  fs::create_symlink("nowhere", dir / "out");
  for (const char* line : {"simulate stack --seconds 0.1 --trace out/t.csv",
                           "simulate stack --seconds 0.1 --energy out/sub/e.csv",
                           "scene stack --out out/s.json"}) {
    INFO(line);
    const Result r = run_cps(line, dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("out is a symbolic link to nowhere, which does not exist") != std::string::npos);
  }
  CHECK(!fs::exists(dir / "nowhere"));
  // Once its target exists, the link is a folder like any other.
  fs::create_directories(dir / "nowhere");
  CHECK(run_cps("simulate stack --seconds 0.1 --trace out/t.csv", dir).exit_code == 0);
  CHECK(fs::exists(dir / "nowhere/t.csv"));
  fs::remove_all(dir);
}
