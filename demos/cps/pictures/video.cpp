#include "pictures/video.h"

#include "output/atomic_file.h"

#include "cps/parameters.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <system_error>

extern char** environ;

namespace cps::cli {
namespace {

constexpr std::size_t k_log_tail_bytes = 8192;

/// `path` as an image2 pattern prefix: a literal '%' must be written "%%".
std::string escape_percent(const std::string& path) {
  std::string out;
  for (const char c : path) {
    out += c;
    if (c == '%') out += '%';
  }
  return out;
}

bool is_executable_file(const std::filesystem::path& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
}

/// Runs argv with stdin from /dev/null and stdout + stderr into one pipe; returns the exit status
/// (as from waitpid) and fills `log` with the output's last k_log_tail_bytes.
int run_captured(const std::vector<std::string>& args, std::string& log) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  int pipe_fd[2];
  if (::pipe2(pipe_fd, O_CLOEXEC) != 0) {
    throw VideoError(std::string("cannot create a pipe for ffmpeg: ") + std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fd[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fd[1], STDERR_FILENO);
  pid_t pid = 0;
  const int spawn_error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fd[1]);
  if (spawn_error != 0) {
    ::close(pipe_fd[0]);
    throw VideoError("cannot start " + args[0] + ": " + std::strerror(spawn_error));
  }
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(pipe_fd[0], buf, sizeof buf);
    if (n > 0) {
      log.append(buf, static_cast<std::size_t>(n));
      if (log.size() > 2 * k_log_tail_bytes) log.erase(0, log.size() - k_log_tail_bytes);
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  ::close(pipe_fd[0]);
  if (log.size() > k_log_tail_bytes) log.erase(0, log.size() - k_log_tail_bytes);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw VideoError(std::string("waitpid on ffmpeg: ") + std::strerror(errno));
  }
  return status;
}

}  // namespace

std::string_view video_format_name(VideoFormat format) {
  return format == VideoFormat::gif ? "gif" : "mp4";
}

std::optional<VideoFormat> parse_video_format(std::string_view name) {
  if (name == "mp4") return VideoFormat::mp4;
  if (name == "gif") return VideoFormat::gif;
  return std::nullopt;
}

std::optional<std::filesystem::path> find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return std::nullopt;
  const std::string_view all(path);
  std::size_t start = 0;
  while (start <= all.size()) {
    std::size_t end = all.find(':', start);
    if (end == std::string_view::npos) end = all.size();
    const std::string dir(all.substr(start, end - start));
    const std::filesystem::path candidate = 
        std::filesystem::path(dir.empty() ? std::string(".") : dir) / program;
    if (is_executable_file(candidate)) return candidate;
    start = end + 1;
  }
  return std::nullopt;
}

std::vector<std::string> ffmpeg_arguments(const std::string& ffmpeg, const VideoJob& job,
                                          const std::filesystem::path& target) {
  const std::string n = std::to_string(job.frames);
  std::vector<std::string> a = {
      ffmpeg, "-hide_banner", "-nostdin", "-loglevel", "warning", "-y",
      "-f", "image2", "-pattern_type", "sequence", "-framerate", shortest_decimal(job.fps),
      "-start_number", "0", "-i", escape_percent(job.frames_folder.string()) + "/frame_%06d.png",
  };
  // trim: only frames 0 .. frames-1, whatever else the folder holds.
  std::string filter = "trim=end_frame=" + n;
  if (job.format == VideoFormat::mp4) {
    const int dx = job.width % 2;
    const int dy = job.height % 2;
    if (dx != 0 || dy != 0) {
      filter += ",pad=" + std::to_string(job.width + dx) + ":" + std::to_string(job.height + dy) +
                ":0:0,fillborders=right=" + std::to_string(dx) +
                ":bottom=" + std::to_string(dy) + ":mode=smear";
    }
    filter += ",format=yuv420p";
    a.insert(a.end(), {"-vf", filter, "-frames:v", n, "-c:v", "libx264", "-pix_fmt", "yuv420p",
                       "-movflags", "+faststart", "-f", "mp4", target.string()});
  } else {
    filter += ",split[a][b];[a]palettegen=stats_mode=diff[p];"
              "[b][p]paletteuse=dither=bayer:bayer_scale=3:diff_mode=rectangle";
    a.insert(a.end(), {"-filter_complex", filter, "-frames:v", n, "-loop", "0", "-f", "gif",
                       target.string()});
  }
  return a;
}

std::string shell_command(const std::vector<std::string>& args) {
  std::string out;
  for (const std::string& arg : args) {
    if (!out.empty()) out += ' ';
    const bool plain = !arg.empty() && arg.find_first_not_of(
        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=.,/:%@") ==
        std::string::npos;
    if (plain) {
      out += arg;
      continue;
    }
    out += '\'';
    for (const char c : arg) {
      if (c == '\'') {
        out += "'\\''";
      } else {
        out += c;
      }
    }
    out += '\'';
  }
  return out;
}

void encode_video(const std::filesystem::path& ffmpeg, const VideoJob& job) {
  // ffmpeg writes this run's own temporary (created exclusively, then handed over; -y lets it
  // overwrite that empty file), which is renamed onto the video only when ffmpeg succeeded.
  AtomicFile video(job.output);
  try {
    video.hand_over();
  } catch (const std::exception& e) {
    throw VideoError(e.what());
  }
  const std::vector<std::string> args = ffmpeg_arguments(ffmpeg.string(), job, video.temporary());
  std::string log;
  const int status = run_captured(args, log);
  const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  struct stat st {};
  const bool wrote = ::stat(video.temporary().c_str(), &st) == 0 && st.st_size > 0;
  if (!ok || !wrote) {
    video.discard();
    std::string how = !ok ? (WIFEXITED(status) ? "exited with code " + std::to_string(WEXITSTATUS(status))
                                               : "was killed by signal " + std::to_string(WTERMSIG(status)))
                          : "wrote no file";
    throw VideoError("ffmpeg " + how + " making " + job.output.string() + "; the frames are kept in " +
                     job.frames_folder.string() + ".\ncommand: " + shell_command(args) +
                     "\nffmpeg's log:\n" + log);
  }
  try {
    video.commit();
  } catch (const std::exception& e) {
    throw VideoError(e.what());
  }
}

}  // namespace cps::cli
