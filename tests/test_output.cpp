// The output rule of the cps command (demos/cps/output.h), checked in-process: atomic writes that
// fail cleanly on a full disk, and the manifest of each output folder.
#include "output.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

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
