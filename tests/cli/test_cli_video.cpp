// `cps render --video mp4|gif`, run as a user runs it: the video is made by ffmpeg from the
// frames and checked with ffprobe (codec, frame count, even size). Without ffmpeg on this machine
// the video tests are reported SKIPPED (tests/skip.h); the missing-ffmpeg test always runs (it
// hides ffmpeg itself).

#include "cli_support.h"
#include "skip.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

using cli_test::Result;
using cli_test::run_cps;
using cli_test::slurp;

// Runs `ENV cps ARGS` in `dir` (ENV: variable assignments, may be empty).
Result cps(const std::string& env, const std::string& args, const fs::path& dir) {
  return run_cps(args, dir, env);
}

fs::path fresh_dir(const std::string& name) { return cli_test::fresh_dir("cps_cli_video_test_" + name); }

bool have_ffmpeg() {
  return std::system("command -v ffmpeg > /dev/null 2>&1 && command -v ffprobe > /dev/null 2>&1") == 0;
}

/// ffprobe's view of the first video stream: codec_name, width, height, pix_fmt, r_frame_rate and
/// nb_read_frames (frames decoded, counted by ffprobe).
nlohmann::json probe(const fs::path& video) {
  const std::string command = "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                              "stream=codec_name,width,height,pix_fmt,r_frame_rate,nb_read_frames "
                              "-of json '" + video.string() + "'";
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string text;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) text.append(buf, n);
  const int status = pclose(pipe);
  INFO("ffprobe output: " << text);
  REQUIRE(WIFEXITED(status));
  REQUIRE(WEXITSTATUS(status) == 0);
  const nlohmann::json j = nlohmann::json::parse(text);
  REQUIRE(j.contains("streams"));
  REQUIRE(j["streams"].size() == 1);
  return j["streams"][0];
}

int count_frames(const fs::path& folder) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("frame_", 0) == 0 && e.path().extension() == ".png") ++n;
  }
  return n;
}

/// No temporary file (".tmp", or ".partial" as older builds named them) is left in `dir`.
bool no_partial_files(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".partial" || e.path().extension() == ".tmp") return false;
  }
  return true;
}

// --seconds 0.4 at --fps 10: frames at t = 0, 0.1, 0.2, 0.3, 0.4.
constexpr int k_frames = 5;
const std::string k_small = "--seconds 0.4 --fps 10";

}  // namespace

TEST_CASE("cps render --video mp4 writes H.264 with even dimensions from an odd size",
          "[cli][video]") {
  if (!have_ffmpeg()) CPS_SKIP("ffmpeg or ffprobe is not installed (apt-get install ffmpeg)");
  const fs::path dir = fresh_dir("mp4");
  // An earlier, longer render wrote frames 5..9: the rerun removes them, the video has 5 frames.
  const Result longer = cps("", "render stack --size 65x49 --seconds 0.9 --fps 10 --out out", dir);
  REQUIRE(longer.exit_code == 0);
  REQUIRE(count_frames(dir / "out" / "stack") == 10);

  const Result r = cps("", "render stack --size 65x49 " + k_small + " --video mp4 --out out", dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  const fs::path video = dir / "out" / "stack.mp4";
  REQUIRE(fs::exists(video));
  CHECK(r.out.find("stack.mp4") != std::string::npos);
  const nlohmann::json s = probe(video);
  INFO(s.dump());
  CHECK(s["codec_name"] == "h264");
  CHECK(s["pix_fmt"] == "yuv420p");
  CHECK(s["width"] == 66);  // 65 padded to even
  CHECK(s["height"] == 50);
  CHECK(s["r_frame_rate"] == "10/1");
  CHECK(s["nb_read_frames"] == std::to_string(k_frames));
  // The frames stay; the rerun removed its own extra frames 5..9 of the longer run (output.h).
  CHECK(count_frames(dir / "out" / "stack") == k_frames);
  CHECK(no_partial_files(dir / "out"));
  fs::remove_all(dir);
}

TEST_CASE("cps render --video gif writes a GIF with every frame", "[cli][video]") {
  if (!have_ffmpeg()) CPS_SKIP("ffmpeg or ffprobe is not installed (apt-get install ffmpeg)");
  const fs::path dir = fresh_dir("gif");
  const Result r = cps("", "render stack --size 64x48 " + k_small + " --video gif --out out", dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  const fs::path video = dir / "out" / "stack.gif";
  REQUIRE(fs::exists(video));
  const nlohmann::json s = probe(video);
  INFO(s.dump());
  CHECK(s["codec_name"] == "gif");
  CHECK(s["width"] == 64);
  CHECK(s["height"] == 48);
  CHECK(s["nb_read_frames"] == std::to_string(k_frames));
  CHECK(count_frames(dir / "out" / "stack") == k_frames);
  CHECK(no_partial_files(dir / "out"));
  fs::remove_all(dir);
}

TEST_CASE("cps render --video with --compare names the video after the compare folder",
          "[cli][video]") {
  if (!have_ffmpeg()) CPS_SKIP("ffmpeg or ffprobe is not installed (apt-get install ffmpeg)");
  const fs::path dir = fresh_dir("compare");
  const Result r =
      cps("", "render stack --size 640x360 " + k_small + " --compare push --video mp4 --out out", dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  const fs::path video = dir / "out" / "stack-compare-push.mp4";
  REQUIRE(fs::exists(video));
  CHECK_FALSE(fs::exists(dir / "out" / "stack.mp4"));
  const nlohmann::json s = probe(video);
  CHECK(s["width"] == 640);  // --size: the push methods (7 or 8) in 2 x 4 cells of 160 x 180,
  CHECK(s["height"] == 360);  // captions included
  CHECK(s["nb_read_frames"] == std::to_string(k_frames));
  fs::remove_all(dir);
}

TEST_CASE("cps render --video without ffmpeg fails clearly and keeps the frames", "[cli][video]") {
  // PATH names only an empty folder: no ffmpeg can be found, whatever this machine has.
  const fs::path dir = fresh_dir("no_ffmpeg");
  fs::create_directories(dir / "empty_bin");
  const Result r = cps("PATH='" + (dir / "empty_bin").string() + "'",
                       "render stack --size 64x48 " + k_small + " --video mp4 --out out", dir);
  INFO("exit " << r.exit_code << ", stderr: " << r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("ffmpeg is not on PATH") != std::string::npos);
  CHECK(r.err.find("apt-get install ffmpeg") != std::string::npos);
  CHECK(r.err.find("frame_%06d.png") != std::string::npos);  // the command that finishes the job
  REQUIRE(fs::exists(dir / "out" / "stack"));
  CHECK(count_frames(dir / "out" / "stack") == k_frames);
  CHECK_FALSE(fs::exists(dir / "out" / "stack.mp4"));
  CHECK(no_partial_files(dir / "out"));
  fs::remove_all(dir);
}

TEST_CASE("cps render --video with an unknown format is a usage error that writes nothing",
          "[cli][video]") {
  const fs::path dir = fresh_dir("bad_format");
  const Result r = cps("", "render stack --size 64x48 " + k_small + " --video avi --out out", dir);
  INFO("stderr: " << r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--video") != std::string::npos);
  CHECK(r.err.find("mp4") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "out"));
  fs::remove_all(dir);
}

TEST_CASE("cps render --video refuses a video it did not write before rendering anything",
          "[cli][video][output]") {
  // Runs with or without ffmpeg: the check comes before any frame is drawn.
  const fs::path dir = fresh_dir("foreign_video");
  for (const std::string format : {"mp4", "gif"}) {
    INFO("--video " << format);
    fs::remove_all(dir / "out");
    fs::create_directories(dir / "out");
    const std::string foreign = "a " + format + " someone made by hand\n";
    const fs::path video = dir / "out" / ("stack." + format);
    std::ofstream(video, std::ios::binary) << foreign;
    const Result r = cps("", "render stack --size 64x36 --seconds 0.1 --fps 10 --video " + format +
                                 " --out out", dir);
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("stack." + format) != std::string::npos);
    CHECK(r.err.find("--force") != std::string::npos);
    CHECK(slurp(video) == foreign);
    CHECK_FALSE(fs::exists(dir / "out" / "stack"));  // no frame was rendered
  }
  fs::remove_all(dir);
}

TEST_CASE("cps render --video --force replaces a foreign video, its own is replaced without it",
          "[cli][video][output]") {
  if (!have_ffmpeg()) CPS_SKIP("ffmpeg or ffprobe is not installed (apt-get install ffmpeg)");
  const fs::path dir = fresh_dir("force_video");
  fs::create_directories(dir / "out");
  std::ofstream(dir / "out" / "stack.mp4", std::ios::binary) << "not a video\n";
  std::ofstream(dir / "out" / "notes.txt", std::ios::binary) << "mine\n";
  const std::string args = "render stack --size 64x36 --seconds 0.1 --fps 10 --video mp4 --out out";
  const Result forced = cps("", args + " --force", dir);
  INFO("stderr: " << forced.err);
  REQUIRE(forced.exit_code == 0);
  CHECK(probe(dir / "out" / "stack.mp4")["codec_name"] == "h264");
  // OUT/ collects the videos: its run.json lists them, so a rerun needs no --force.
  const nlohmann::json manifest = nlohmann::json::parse(slurp(dir / "out" / "run.json"));
  CHECK(manifest["files"] == nlohmann::json({"stack.mp4"}));
  const Result again = cps("", args, dir);
  INFO("stderr: " << again.err);
  CHECK(again.exit_code == 0);
  CHECK(slurp(dir / "out" / "notes.txt") == "mine\n");
  CHECK(no_partial_files(dir / "out"));
  fs::remove_all(dir);
}
