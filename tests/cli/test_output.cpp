// The output rule of the cps command (demos/cps/output.h), checked in-process: atomic writes that
// fail cleanly on a full disk and never open a file they did not create, which targets a run may
// replace, run.json of exclusive and shared folders, and the leftovers of interrupted runs.
#include "options/options.h"
#include "output/output.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cps::cli::AtomicFile;
using cps::cli::FolderUse;
using cps::cli::OutputPlan;
using cps::cli::UsageError;

namespace {

// An empty folder of its own in the system's temporary folder, removed at the end.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() / ("cps_output_test_" + name + "_" + std::to_string(getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

std::vector<std::string> entries(const fs::path& folder) {
  std::vector<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(folder)) {
    names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// Runs `write` in a child process whose files may not grow past `limit` bytes (RLIMIT_FSIZE,
// SIGXFSZ ignored, so a write past it fails with EFBIG as on a full disk). Returns the message of
// the exception `write` threw, or "" if it threw none.
std::string error_with_file_size_limit(rlim_t limit, const std::function<void()>& write) {
  int pipe_fd[2];
  REQUIRE(pipe(pipe_fd) == 0);
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    close(pipe_fd[0]);
    signal(SIGXFSZ, SIG_IGN);
    const rlimit small{limit, limit};
    if (setrlimit(RLIMIT_FSIZE, &small) != 0) _exit(3);
    std::string message;
    try {
      write();
    } catch (const std::exception& e) {
      message = e.what();
    }
    const ssize_t n = ::write(pipe_fd[1], message.data(), message.size());
    _exit(n == static_cast<ssize_t>(message.size()) ? 0 : 4);
  }
  close(pipe_fd[1]);
  std::string message;
  char buf[512];
  for (ssize_t n; (n = read(pipe_fd[0], buf, sizeof buf)) > 0;) message.append(buf, static_cast<std::size_t>(n));
  close(pipe_fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  REQUIRE(WIFEXITED(status));
  REQUIRE(WEXITSTATUS(status) == 0);
  return message;
}

nlohmann::json manifest(const fs::path& folder) {
  return nlohmann::json::parse(slurp(folder / "run.json"));
}

const nlohmann::json k_info = {{"command", "test"}};

// plan_output for `files` in `folder`, written by the command "test" (no scene).
OutputPlan plan_for(const fs::path& folder, const std::vector<std::string>& files, bool force,
                    FolderUse use = FolderUse::exclusive, const std::string& option = "--out",
                    const std::string& command = "test") {
  return cps::cli::plan_output({.folder = folder,
                                .files = files,
                                .command = command,
                                .use = use,
                                .scenes = {},
                                .option = option,
                                .force = force});
}

// Plans, begins, writes `files` (each holding its own name) and ends one run into `folder`.
void one_run(const fs::path& folder, const std::vector<std::string>& files, FolderUse use,
             bool force = false) {
  const OutputPlan plan = plan_for(folder, files, force, use);
  cps::cli::begin_output(plan, k_info);
  for (const std::string& f : files) cps::cli::write_text_atomic(folder / f, f);
  cps::cli::end_output(plan, k_info);
}

// The message of the UsageError `f` throws ("" if it throws none; fails on another exception).
std::string usage_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

// A process id that surely ended: a child that exited and was reaped.
pid_t ended_pid() {
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) _exit(0);
  int status = 0;
  waitpid(pid, &status, 0);
  return pid;
}

// In a child process: plans and begins `folder` for `files` and starts writing the first one
// (its temporary holds "partial"); then the child ends without finishing (as if killed). Returns
// the child's run token.
std::string interrupted_run(const fs::path& folder, const std::vector<std::string>& files,
                            FolderUse use) {
  int pipe_fd[2];
  REQUIRE(pipe(pipe_fd) == 0);
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    close(pipe_fd[0]);
    try {
      const OutputPlan plan = plan_for(folder, files, true, use);
      cps::cli::begin_output(plan, k_info);
      auto* file = new AtomicFile(folder / files.front());  // never destroyed: no clean-up
      file->write("partial");
      file->hand_over();
      const std::string& token = cps::cli::run_token();
      if (::write(pipe_fd[1], token.data(), token.size()) != static_cast<ssize_t>(token.size())) _exit(2);
    } catch (...) {
      _exit(1);
    }
    _exit(0);
  }
  close(pipe_fd[1]);
  char token[64] = {};
  const ssize_t n = read(pipe_fd[0], token, sizeof token - 1);
  close(pipe_fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  REQUIRE(WIFEXITED(status));
  REQUIRE(WEXITSTATUS(status) == 0);
  REQUIRE(n == 16);
  return std::string(token, static_cast<std::size_t>(n));
}

}  // namespace

TEST_CASE("write_json_atomic on a full disk keeps the old file, leaves no temporary and names "
          "the target and the reason", "[output]") {
  TempDir dir("full_json");
  const fs::path target = dir.path / "run.json";
  write_text(target, "{\"old\": true}\n");
  nlohmann::json big;
  big["payload"] = std::string(64 * 1024, 'x');  // far past the 4 KiB limit
  const std::string message =
      error_with_file_size_limit(4096, [&] { cps::cli::write_json_atomic(target, big); });
  INFO(message);
  CHECK(message.find(target.string()) != std::string::npos);
  CHECK(message.find(".tmp") == std::string::npos);              // the target, not a temporary
  CHECK(message.find(std::strerror(EFBIG)) != std::string::npos);  // the reason
  CHECK(slurp(target) == "{\"old\": true}\n");
  CHECK(entries(dir.path) == std::vector<std::string>{"run.json"});
}

TEST_CASE("write_file_atomic and AtomicFile on a full disk keep the old file and name the target",
          "[output]") {
  TempDir dir("full_bytes");
  const fs::path target = dir.path / "frame_000001.png";
  write_text(target, "old frame");
  const std::vector<std::uint8_t> big(256 * 1024, 7);
  SECTION("one call") {
    const std::string message =
        error_with_file_size_limit(4096, [&] { cps::cli::write_file_atomic(target, big); });
    INFO(message);
    CHECK(message == "cannot write " + target.string() + ": " + std::strerror(EFBIG));
  }
  SECTION("many small writes, the last in commit") {
    const std::string message = error_with_file_size_limit(4096, [&] {
      AtomicFile file(target);
      for (int i = 0; i < 1000; ++i) file.write("a row of a trace, 31 bytes long\n");
      file.commit();
    });
    INFO(message);
    CHECK(message == "cannot write " + target.string() + ": " + std::strerror(EFBIG));
  }
  CHECK(slurp(target) == "old frame");
  CHECK(entries(dir.path) == std::vector<std::string>{"frame_000001.png"});
}

TEST_CASE("AtomicFile never opens a file it did not create, and removes only its own temporary",
          "[output]") {
  TempDir dir("exclusive_tmp");
  const fs::path target = dir.path / "a.txt";
  const fs::path squatter = dir.path / cps::cli::temporary_name("a.txt", cps::cli::run_token());
  write_text(squatter, "someone's");
  CHECK_THROWS_WITH(AtomicFile(target), Catch::Contains(target.string()) &&
                                            Catch::Contains(std::strerror(EEXIST)));
  CHECK(slurp(squatter) == "someone's");
  CHECK_FALSE(fs::exists(target));
  fs::remove(squatter);

  // Not committed: the temporary goes, the target stays as it was.
  write_text(target, "old");
  {
    AtomicFile file(target);
    file.write("new");
    CHECK(fs::exists(file.temporary()));
    CHECK(file.temporary().parent_path() == dir.path);
  }
  CHECK(slurp(target) == "old");
  CHECK(entries(dir.path) == std::vector<std::string>{"a.txt"});

  // Handed over to another program, which writes the temporary; commit renames it.
  AtomicFile file(target);
  file.hand_over();
  const std::string command = "printf hello > '" + file.temporary().string() + "'";
  REQUIRE(std::system(command.c_str()) == 0);
  CHECK(file.commit() == 5);
  CHECK(slurp(target) == "hello");
  CHECK(entries(dir.path) == std::vector<std::string>{"a.txt"});
  CHECK_THROWS_AS(file.write("more"), std::logic_error);
}

TEST_CASE("plan_output refuses foreign targets and unusable folders before writing anything",
          "[output]") {
  TempDir dir("plan");
  const fs::path folder = dir.path / "out";
  fs::create_directories(folder);
  write_text(folder / "notes.txt", "mine");
  // Exclusive: any foreign entry; named, with what to do.
  const std::string exclusive = usage_error([&] {
    plan_for(folder, {"frame_000000.png"}, false, FolderUse::exclusive);
  });
  CHECK(exclusive.find("notes.txt") != std::string::npos);
  CHECK(exclusive.find("--force") != std::string::npos);
  CHECK_NOTHROW(plan_for(folder, {"frame_000000.png"}, true, FolderUse::exclusive));
  // Shared: other entries are no concern; a foreign target is refused, naming it.
  CHECK_NOTHROW(plan_for(folder, {"f.png"}, false, FolderUse::shared));
  const std::string shared = usage_error(
      [&] { plan_for(folder, {"notes.txt"}, false, FolderUse::shared, "--trace"); });
  CHECK(shared.find((folder / "notes.txt").string()) != std::string::npos);
  CHECK(shared.find("--trace") != std::string::npos);
  CHECK_NOTHROW(plan_for(folder, {"notes.txt"}, true, FolderUse::shared));
  // A foreign run.json is foreign too.
  write_text(folder / "run.json", "{\"someone\": \"else\"}");
  CHECK(usage_error([&] { plan_for(folder, {"f.png"}, false, FolderUse::shared); })
            .find("run.json") != std::string::npos);
  // A target that is a folder: refused even with force.
  fs::create_directories(folder / "f.png");
  CHECK(usage_error([&] { plan_for(folder, {"f.png"}, true, FolderUse::shared); })
            .find("f.png") != std::string::npos);
  // Names that are not plain file names, or run.json.
  for (const std::string bad : {"", ".", "..", "a/b", "run.json"}) {
    INFO("'" << bad << "'");
    CHECK_THROWS_AS(plan_for(folder, {bad}, true, FolderUse::shared), UsageError);
  }
  // The folder is a file, or below one.
  write_text(dir.path / "somefile", "x");
  for (const fs::path& f : {dir.path / "somefile", dir.path / "somefile" / "x" / "y"}) {
    INFO(f);
    const std::string message =
        usage_error([&] { plan_for(f, {"a.png"}, true, FolderUse::exclusive); });
    CHECK(message.find((dir.path / "somefile").string()) != std::string::npos);
  }
  // A missing folder below a folder is fine: begin_output creates it.
  CHECK_NOTHROW(plan_for(dir.path / "new" / "deeper", {"a.png"}, false));
  CHECK(slurp(folder / "notes.txt") == "mine");
  CHECK_FALSE(fs::exists(dir.path / "new"));
}

TEST_CASE("an exclusive folder lists exactly its run's files, a shared one every run's",
          "[output]") {
  TempDir dir("manifests");
  const fs::path frames = dir.path / "frames";
  one_run(frames, {"a.png", "b.png", "c.png"}, FolderUse::exclusive);
  one_run(frames, {"a.png"}, FolderUse::exclusive);  // a shorter rerun: b and c are its own
  CHECK(entries(frames) == std::vector<std::string>{"a.png", "run.json"});
  CHECK(manifest(frames)["files"] == nlohmann::json({"a.png"}));
  CHECK(manifest(frames)["complete"] == true);
  CHECK(manifest(frames)["unfinished_runs"].empty());

  const fs::path shared = dir.path / "figures";
  fs::create_directories(shared);
  write_text(shared / "notes.txt", "mine");
  one_run(shared, {"x.png", "x.png.json"}, FolderUse::shared);
  one_run(shared, {"y.png"}, FolderUse::shared);
  CHECK(manifest(shared)["files"] == nlohmann::json({"x.png", "x.png.json", "y.png"}));
  one_run(shared, {"x.png"}, FolderUse::shared);  // its own: replaced without force
  fs::remove(shared / "y.png");
  one_run(shared, {"z.png"}, FolderUse::shared);
  CHECK(manifest(shared)["files"] == nlohmann::json({"x.png", "x.png.json", "z.png"}));
  CHECK(manifest(shared)["command"] == "test");
  CHECK(slurp(shared / "notes.txt") == "mine");
  CHECK_THROWS_AS(one_run(shared, {"notes.txt"}, FolderUse::shared), UsageError);
  CHECK(slurp(shared / "notes.txt") == "mine");
}

TEST_CASE("the leftovers of an interrupted own run are removed, similar foreign files are not",
          "[output]") {
  TempDir dir("leftovers");
  for (const FolderUse use : {FolderUse::exclusive, FolderUse::shared}) {
    const fs::path folder = dir.path / (use == FolderUse::exclusive ? "exclusive" : "shared");
    const std::string token = interrupted_run(folder, {"a.png", "b.png"}, use);
    const std::string leftover = cps::cli::temporary_name("a.png", token);
    REQUIRE(slurp(folder / leftover) == "partial");
    const nlohmann::json before = manifest(folder);
    CHECK(before["complete"] == false);
    REQUIRE(before["unfinished_runs"].size() == 1);
    CHECK(before["unfinished_runs"][0]["run_token"] == token);
    // Foreign files named like temporaries: of a listed file but another token, with the token
    // but another suffix, of an unlisted file with the token.
    const std::vector<std::string> foreign = {
        "a.png.tmp", cps::cli::temporary_name("a.png", "0123456789abcdef"), leftover + ".bak",
        cps::cli::temporary_name("c.png", token)};
    for (const std::string& f : foreign) write_text(folder / f, "someone's " + f);

    if (use == FolderUse::exclusive) {
      const std::string refused = usage_error(
          [&] { plan_for(folder, {"a.png", "b.png"}, false, use); });
      for (const std::string& f : foreign) CHECK(refused.find(f) != std::string::npos);
      CHECK(refused.find(leftover + ",") == std::string::npos);  // the leftover is not foreign
      CHECK(refused.find(leftover + ":") == std::string::npos);
      CHECK(refused.find(std::to_string(foreign.size()) + " file(s)") != std::string::npos);
    }
    one_run(folder, {"a.png", "b.png"}, use, /*force=*/use == FolderUse::exclusive);
    CHECK_FALSE(fs::exists(folder / leftover));
    for (const std::string& f : foreign) CHECK(slurp(folder / f) == "someone's " + f);
    CHECK(slurp(folder / "a.png") == "a.png");
    CHECK(manifest(folder)["complete"] == true);
    CHECK(manifest(folder)["unfinished_runs"].empty());
  }
}

TEST_CASE("a run killed while it wrote its first run.json leaves a temporary the next run removes",
          "[output]") {
  TempDir dir("first_manifest");
  const std::string token = "00112233445566ff";
  char host[256] = {};
  REQUIRE(gethostname(host, sizeof host - 1) == 0);
  const nlohmann::json dead_run = {
      {"tool", "cps"},
      {"complete", false},
      {"files", {"a.png"}},
      {"unfinished_runs", {{{"run_token", token}, {"pid", ended_pid()}, {"host", host}, {"start", 0}}}}};
  const std::string ours = cps::cli::temporary_name("run.json", token);
  write_text(dir.path / ours, dead_run.dump());
  // The same name with content that does not name that run: foreign.
  const std::string other = cps::cli::temporary_name("run.json", "ffeeddccbbaa9988");
  write_text(dir.path / other, dead_run.dump());
  CHECK(usage_error([&] { plan_for(dir.path, {"a.png"}, false); })
            .find("1 file(s)") != std::string::npos);
  one_run(dir.path, {"a.png"}, FolderUse::exclusive, true);
  CHECK(entries(dir.path) == std::vector<std::string>{"a.png", "run.json", other});
}

TEST_CASE("a run still writing a shared folder keeps its temporaries and its files are listed",
          "[output]") {
  TempDir dir("concurrent");
  int to_child[2];
  int to_parent[2];
  REQUIRE(pipe(to_child) == 0);
  REQUIRE(pipe(to_parent) == 0);
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    close(to_child[1]);
    close(to_parent[0]);
    int code = 0;
    try {
      const OutputPlan plan = plan_for(dir.path, {"slow.csv"}, false, FolderUse::shared);
      cps::cli::begin_output(plan, k_info);
      AtomicFile file(dir.path / "slow.csv");
      file.write("first half, ");
      file.hand_over();  // on disk now
      const std::string& token = cps::cli::run_token();
      if (::write(to_parent[1], token.data(), token.size()) != 16) _exit(2);
      char go = 0;
      if (read(to_child[0], &go, 1) != 1) _exit(3);  // until the parent's run has ended
      const std::string command = "printf 'second half' >> '" + file.temporary().string() + "'";
      if (std::system(command.c_str()) != 0) _exit(4);
      file.commit();
      cps::cli::end_output(plan, k_info);
    } catch (...) {
      code = 1;
    }
    _exit(code);
  }
  close(to_child[0]);
  close(to_parent[1]);
  char token[17] = {};
  REQUIRE(read(to_parent[0], token, 16) == 16);
  const std::string child_tmp = cps::cli::temporary_name("slow.csv", token);
  REQUIRE(fs::exists(dir.path / child_tmp));
  // An exclusive run is refused while another writes the folder.
  CHECK(usage_error([&] { plan_for(dir.path, {"x.png"}, false); })
            .find("another cps run") != std::string::npos);
  one_run(dir.path, {"fast.csv"}, FolderUse::shared);
  CHECK(fs::exists(dir.path / child_tmp));  // not removed: its run still runs
  CHECK(manifest(dir.path)["complete"] == false);
  REQUIRE(write(to_child[1], "g", 1) == 1);
  int status = 0;
  waitpid(pid, &status, 0);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  close(to_child[1]);
  close(to_parent[0]);
  CHECK(slurp(dir.path / "slow.csv") == "first half, second half");
  CHECK(manifest(dir.path)["files"] == nlohmann::json({"slow.csv", "fast.csv"}));
  CHECK(manifest(dir.path)["complete"] == true);
  CHECK(entries(dir.path) == std::vector<std::string>{"fast.csv", "run.json", "slow.csv"});
}

TEST_CASE("run.json records who wrote each file and its hash: edits are foreign, other commands' "
          "files are kept", "[output]") {
  TempDir dir("records");
  const fs::path folder = dir.path / "out";
  // Two commands share a folder: "a" writes x.txt, "b" writes y.txt.
  auto run = [&](const std::string& command, const std::string& file, FolderUse use, bool force) {
    const OutputPlan plan = plan_for(folder, {file}, force, use, "--out", command);
    cps::cli::begin_output(plan, k_info);
    cps::cli::write_text_atomic(folder / file, command + " wrote " + file);
    cps::cli::end_output(plan, k_info);
    return plan;
  };
  run("a", "x.txt", FolderUse::shared, false);
  run("b", "y.txt", FolderUse::shared, false);
  const nlohmann::json m = manifest(folder);
  CHECK(m["written"]["x.txt"]["command"] == "a");
  CHECK(m["written"]["y.txt"]["xxh3_64"].get<std::string>().size() == 16);
  // An exclusive run of "a" keeps b's file (neither stale nor foreign) and lists it.
  const OutputPlan exclusive = run("a", "z.txt", FolderUse::exclusive, false);
  CHECK(exclusive.stale == std::vector<std::string>{"x.txt"});
  CHECK(exclusive.kept == std::vector<std::string>{"y.txt"});
  CHECK(slurp(folder / "y.txt") == "b wrote y.txt");
  CHECK_FALSE(fs::exists(folder / "x.txt"));
  // "a" may not replace b's file, even with force.
  for (const bool force : {false, true}) {
    CHECK(usage_error([&] { plan_for(folder, {"y.txt"}, force, FolderUse::shared, "--out", "a"); })
              .find("written by cps b") != std::string::npos);
  }
  // b's file edited: foreign to b, named as changed; force replaces it.
  write_text(folder / "y.txt", "edited");
  CHECK(usage_error([&] { plan_for(folder, {"y.txt"}, false, FolderUse::shared, "--out", "b"); })
            .find("changed since cps wrote it") != std::string::npos);
  CHECK_NOTHROW(plan_for(folder, {"y.txt"}, true, FolderUse::shared, "--out", "b"));
  // A command's input is never its target, even with force.
  cps::cli::note_input(folder / "z.txt");
  CHECK(usage_error([&] { plan_for(folder, {"z.txt"}, true, FolderUse::shared, "--out", "a"); })
            .find("input of this command") != std::string::npos);
}
