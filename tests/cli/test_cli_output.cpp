// `cps render` output folders as a user meets them: foreign files are refused unless --force and
// never touched, a rerun replaces its own frames, run.json records the run, an interrupted run
// leaves only complete frames, and progress goes to stderr.
#include "cps/render/renderer.h"

#include "cli_support.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace {

using cli_test::Result;
using cli_test::run_cps;
using cli_test::slurp;


fs::path fresh_dir(const std::string& name) { return cli_test::fresh_dir("cps_cli_output_test_" + name); }

// Names in `folder` matching frame_NNNNNN.png, sorted.
std::vector<std::string> frames_in(const fs::path& folder) {
  static const std::regex frame(R"(frame_\d{6}\.png)");
  std::set<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(folder)) {
    const std::string n = e.path().filename().string();
    if (std::regex_match(n, frame)) names.insert(n);
  }
  return {names.begin(), names.end()};
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

const char* k_small = "render stack --size 64x48 --fps 5 --out out";

}  // namespace

TEST_CASE("render refuses a folder holding foreign files and keeps them", "[cli][output]") {
  const fs::path dir = fresh_dir("foreign");
  const fs::path folder = dir / "out/stack";
  fs::create_directories(folder);
  write_text(folder / "notes.txt", "mine, not cps's");
  write_text(folder / "frame_000001.png", "not a frame of cps");

  const Result refused = run_cps(std::string(k_small) + " --seconds 0.2", dir);
  CHECK(refused.exit_code == 2);
  CHECK(refused.err.find("--force") != std::string::npos);
  CHECK(refused.err.find("notes.txt") != std::string::npos);
  CHECK(slurp(folder / "notes.txt") == "mine, not cps's");
  CHECK(slurp(folder / "frame_000001.png") == "not a frame of cps");
  CHECK(!fs::exists(folder / "frame_000000.png"));
  CHECK(!fs::exists(folder / "run.json"));

  SECTION("--force writes the frames and keeps the other files") {
    const Result forced = run_cps(std::string(k_small) + " --seconds 0.2 --force", dir);
    REQUIRE(forced.exit_code == 0);
    CHECK(slurp(folder / "notes.txt") == "mine, not cps's");
    CHECK(frames_in(folder) == std::vector<std::string>{"frame_000000.png", "frame_000001.png"});
    CHECK(cps::render::read_png(folder / "frame_000001.png").width == 64);  // replaced, by force
    // A shorter rerun with --force removes nothing it did not write.
    write_text(folder / "frame_000007.png", "still not cps's");
    const Result again = run_cps(std::string(k_small) + " --seconds 0.1 --force", dir);
    REQUIRE(again.exit_code == 0);
    CHECK(slurp(folder / "notes.txt") == "mine, not cps's");
    CHECK(slurp(folder / "frame_000007.png") == "still not cps's");
  }
  fs::remove_all(dir);
}

TEST_CASE("render --force never touches a foreign file that is not a target", "[cli][output]") {
  const fs::path dir = fresh_dir("foreign_tmp");
  const fs::path folder = dir / "out/stack";
  fs::create_directories(folder);
  // Named like the temporary of a frame: not a frame, so --force must keep it as it is.
  write_text(folder / "frame_000001.png.tmp", "someone's notes");
  const Result forced = run_cps(std::string(k_small) + " --seconds 0.2 --force", dir);
  INFO(forced.err);
  REQUIRE(forced.exit_code == 0);
  CHECK(slurp(folder / "frame_000001.png.tmp") == "someone's notes");
  CHECK(frames_in(folder) == std::vector<std::string>{"frame_000000.png", "frame_000001.png"});
  fs::remove_all(dir);
}

TEST_CASE("a file named like a temporary of an own frame is still foreign", "[cli][output]") {
  const fs::path dir = fresh_dir("own_then_tmp");
  const fs::path folder = dir / "out/stack";
  REQUIRE(run_cps(std::string(k_small) + " --seconds 0.2", dir).exit_code == 0);
  write_text(folder / "frame_000001.png.tmp", "someone's notes");
  const Result refused = run_cps(std::string(k_small) + " --seconds 0.2", dir);
  CHECK(refused.exit_code == 2);
  CHECK(refused.err.find("frame_000001.png.tmp") != std::string::npos);
  CHECK(slurp(folder / "frame_000001.png.tmp") == "someone's notes");
  const Result forced = run_cps(std::string(k_small) + " --seconds 0.2 --force", dir);
  INFO(forced.err);
  REQUIRE(forced.exit_code == 0);
  CHECK(slurp(folder / "frame_000001.png.tmp") == "someone's notes");
  fs::remove_all(dir);
}

TEST_CASE("an --out naming a file, or a path below one, is refused before any work", "[cli][output]") {
  const fs::path dir = fresh_dir("out_file");
  write_text(dir / "somefile", "not a folder");
  for (const std::string out : {"somefile", "somefile/x"}) {
    INFO("--out " << out);
    const Result r = run_cps("render stack --size 64x36 --fps 10 --seconds 0.1 --out " + out, dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("somefile") != std::string::npos);
    CHECK(r.err.find("render stack:") == std::string::npos);  // no progress: nothing rendered
    CHECK(slurp(dir / "somefile") == "not a folder");
  }
  fs::remove_all(dir);
}

TEST_CASE("render all checks every folder before it writes any", "[cli][output]") {
  const fs::path dir = fresh_dir("all");
  fs::create_directories(dir / "out/pendulum_wave");  // the last scene's folder
  write_text(dir / "out/pendulum_wave/notes.txt", "mine");
  const Result r = run_cps("render all --size 64x48 --fps 5 --seconds 0.2 --out out", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("pendulum_wave") != std::string::npos);
  std::vector<std::string> entries;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "out")) {
    entries.push_back(e.path().filename().string());
  }
  CHECK(entries == std::vector<std::string>{"pendulum_wave"});  // no scene was rendered
  CHECK(slurp(dir / "out/pendulum_wave/notes.txt") == "mine");
  fs::remove_all(dir);
}

TEST_CASE("a rerun replaces its own frames and removes its own extra frames", "[cli][output]") {
  const fs::path dir = fresh_dir("rerun");
  const fs::path folder = dir / "out/stack";
  const Result first = run_cps("render stack --size 64x48 --fps 5 --seconds 0.8 --out out", dir);
  REQUIRE(first.exit_code == 0);
  CHECK(frames_in(folder).size() == 5);

  const Result second = run_cps("render stack --size 80x60 --fps 5 --seconds 0.2 --out out", dir);
  REQUIRE(second.exit_code == 0);
  CHECK(frames_in(folder) == std::vector<std::string>{"frame_000000.png", "frame_000001.png"});
  for (const std::string& f : frames_in(folder)) {
    const cps::render::Image image = cps::render::read_png(folder / f);
    CHECK(image.width == 80);  // the new run's frames, not the old ones
    CHECK(image.height == 60);
  }
  const nlohmann::json manifest = nlohmann::json::parse(slurp(folder / "run.json"));
  CHECK(manifest["files"].size() == 2);
  CHECK(manifest["complete"] == true);
  fs::remove_all(dir);
}

TEST_CASE("run.json records the parameters, command line, version and date", "[cli][output]") {
  const fs::path dir = fresh_dir("manifest");
  const Result r = run_cps(
      "render stack --size 64x48 --fps 5 --seconds 0.4 --dt 0.01 --iterations 7 --out out", dir);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "out/stack/run.json"));
  const nlohmann::json& p = j["parameters"];
  CHECK(p["scene"] == "stack");
  CHECK(p["seconds"].get<double>() == Approx(0.4));
  CHECK(p["fps"].get<double>() == Approx(5.0));
  CHECK(p["frames"] == 3);
  CHECK(p["size"]["width"] == 64);
  CHECK(p["size"]["height"] == 48);
  CHECK(p["compare"].is_null());
  CHECK(p["overrides"]["dt_s"].get<double>() == Approx(0.01));
  CHECK(p["overrides"]["iterations"] == 7);
  CHECK(p["world"][0]["parameters"]["iterations"] == 7);
  CHECK(j["command"] == "render");
  REQUIRE(j["command_line"].is_array());
  CHECK(j["command_line"][1] == "render");
  CHECK(j["command_line"].size() == 15);  // cps render stack and 6 options with values
  CHECK(!j["engine_version"].get<std::string>().empty());
  CHECK(std::regex_match(j["date_utc"].get<std::string>(),
                         std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")));
  CHECK(j["files"].size() == 3);
  fs::remove_all(dir);
}

TEST_CASE("a killed render leaves only complete frames and the rerun recovers", "[cli][output]") {
  const fs::path dir = fresh_dir("killed");
  const fs::path folder = dir / "out/stack";
  // A long run (3001 frames), killed with SIGKILL once its first frames are on disk.
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(127);
    std::FILE* quiet = std::freopen("/dev/null", "w", stderr);
    (void)quiet;
    execl(CPS_EXE, CPS_EXE, "render", "stack", "--size", "64x48", "--fps", "30", "--seconds",
          "100", "--out", "out", static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait (at most about 60 s, a guard, not a timing assertion) for the fourth frame.
  for (int i = 0; i < 6000 && !fs::exists(folder / "frame_000003.png"); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  REQUIRE(WIFSIGNALED(status));
  const std::vector<std::string> frames = frames_in(folder);
  REQUIRE(frames.size() >= 4);
  REQUIRE(frames.size() < 3001);  // it was killed mid-run
  for (const std::string& f : frames) {
    INFO(f);
    const cps::render::Image image = cps::render::read_png(folder / f);  // throws if truncated
    CHECK(image.width == 64);
    CHECK(image.height == 48);
  }
  // The killed run's files (frames, temporaries) are its own: a shorter rerun replaces them
  // without --force and leaves neither extra frames nor temporaries.
  const Result rerun = run_cps("render stack --size 64x48 --fps 5 --seconds 0.2 --out out", dir);
  INFO(rerun.err);
  REQUIRE(rerun.exit_code == 0);
  CHECK(frames_in(folder).size() == 2);
  for (const fs::directory_entry& e : fs::directory_iterator(folder)) {
    CHECK(e.path().extension() != ".tmp");
  }
  fs::remove_all(dir);
}

TEST_CASE("progress goes to stderr as plain lines when stderr is not a terminal",
          "[cli][output]") {
  const fs::path dir = fresh_dir("progress");
  const Result r = run_cps("render stack --size 64x48 --fps 10 --seconds 1 --out out", dir);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("render stack: 11/11 frames (100 %)") != std::string::npos);
  CHECK(r.err.find('\r') == std::string::npos);  // no terminal redraws in a log
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') >= 2);
  CHECK(r.out.find("frames (") == std::string::npos);  // stdout stays clean
  // A short simulate (well under 2 s) prints no progress at all: --json output stays clean.
  const Result s = run_cps("simulate stack --seconds 0.5 --json", dir);
  REQUIRE(s.exit_code == 0);
  CHECK(s.err.empty());
  CHECK(nlohmann::json::parse(s.out)["scene"] == "stack");
  fs::remove_all(dir);
}
