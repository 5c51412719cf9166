#pragma once
// `cps render --video mp4|gif`: assembling the written PNG frames into one video with ffmpeg.

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace cps::cli {

/// The container and codec of a video: mp4 (H.264 by libx264, yuv420p, even width and height,
/// moov atom first for streaming) or gif (one palette optimised for the whole clip).
enum class VideoFormat { mp4, gif };

/// "mp4" or "gif" (also the file extension).
std::string_view video_format_name(VideoFormat format);

/// The format named `name` ("mp4", "gif"), or nullopt.
std::optional<VideoFormat> parse_video_format(std::string_view name);

/// A failure to make a video (ffmpeg missing, failing, or the result not storable).
struct VideoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The first executable regular file named `program` in the folders of $PATH (an empty entry
/// means the current folder), or nullopt if there is none (or PATH is unset).
std::optional<std::filesystem::path> find_on_path(const std::string& program);

/// What to assemble: frames_folder/frame_000000.png .. frame_{frames-1}.png (frames >= 1), each
/// width x height pixels (>= 1), shown at `fps` frames per second (> 0), into `output`.
struct VideoJob {
  VideoFormat format = VideoFormat::mp4;
  std::filesystem::path frames_folder;
  int frames = 0;
  double fps = 30.0;
  int width = 0;
  int height = 0;
  std::filesystem::path output;
};

/// The ffmpeg command (argv[0] = `ffmpeg`) that writes `job` into `target`:
///   -framerate FPS -start_number 0 -i FOLDER/frame_%06d.png, only the first `frames` frames
///   (frames left over from an earlier, longer render in the same folder are ignored);
///   mp4: libx264, -pix_fmt yuv420p, an odd width or height padded by one column or row that
///   repeats the edge (pad + fillborders smear; yuv420p needs even sizes), -movflags +faststart;
///   gif: split, palettegen (stats_mode=diff) and paletteuse in one filtergraph, looping forever.
/// The container is given with -f, so `target` may have any extension.
std::vector<std::string> ffmpeg_arguments(const std::string& ffmpeg, const VideoJob& job,
                                          const std::filesystem::path& target);

/// `args` quoted for a POSIX shell, for messages the user can paste.
std::string shell_command(const std::vector<std::string>& args);

/// Runs `ffmpeg` (a path, e.g. from find_on_path) on `job` with posix_spawn and an argument
/// vector (no shell), stdin from /dev/null, its output captured. ffmpeg writes this run's own
/// temporary file of job.output (an AtomicFile handed over to it, atomic_file.h), which is renamed
/// onto job.output only when ffmpeg succeeded, so an interrupted or failed run never leaves a
/// half-written video, and no other file is opened. The caller checks job.output first
/// (plan_output, output.h). Throws VideoError holding the command and ffmpeg's log (its last
/// 8 kB) if ffmpeg cannot start, fails or writes nothing, or "cannot write OUTPUT: REASON" if the
/// temporary cannot be made or renamed.
void encode_video(const std::filesystem::path& ffmpeg, const VideoJob& job);

}  // namespace cps::cli
