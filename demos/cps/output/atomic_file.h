#pragma once
// Writing one file so that readers see its old content or its new content, never a part: the
// bytes go to a temporary file of this run next to the target, every write and the close are
// checked, and the temporary is renamed onto the target at the end. Part of the output rule of
// the cps command (output.h decides which targets a run may write; this writes them).

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

namespace cps::cli {

/// This run's token: 16 lowercase hex digits drawn at random (getrandom) the first time it is
/// asked for in a process (a forked child draws its own). Every temporary file the run makes
/// carries it in its name (temporary_name), and begin_output records it in the folder's run.json,
/// so that a later run can tell this run's leftovers from anyone else's files. Thread-safe.
const std::string& run_token();

/// The name of the temporary file of `name` (a plain file name) for the run whose token is
/// `token`: "NAME.TOKEN.tmp".
std::string temporary_name(std::string_view name, std::string_view token);

/// One file being written: created as temporary_name(target's name, run_token()) in the target's
/// folder, renamed onto the target by commit(). The temporary is created with
/// O_CREAT | O_EXCL (mode 0666 less the umask), so an existing file of any name is never opened
/// for writing, truncated or renamed away; if commit() is not reached (an error, an exception)
/// the destructor removes the temporary, which is this run's own. A process killed meanwhile
/// leaves the temporary behind; the folder's run.json names its run (output.h), so the next run
/// removes it. Not copyable; use from one thread.
class AtomicFile {
 public:
  /// Creates the temporary file of `target` (its folder must exist). Throws std::runtime_error
  /// "cannot write TARGET: REASON" (the OS's reason, e.g. "No such file or directory",
  /// "Permission denied", or "File exists" for a temporary of that name that is not this
  /// object's) if it cannot.
  explicit AtomicFile(std::filesystem::path target);
  /// Not committed: closes and removes the temporary (the target is left as it was).
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// The final path, as given.
  const std::filesystem::path& target() const { return target_; }
  /// The temporary file's path (in the target's folder).
  const std::filesystem::path& temporary() const { return temporary_; }

  /// Appends `bytes` (buffered: up to 64 KiB are kept before they are written). Throws
  /// std::runtime_error "cannot write TARGET: REASON" (e.g. "No space left on device", "File too
  /// large") if a write fails, after removing the temporary; the object is then discarded.
  /// Throws std::logic_error after hand_over(), commit() or discard().
  void write(std::span<const std::uint8_t> bytes);
  /// As write(bytes), for text.
  void write(std::string_view text);

  /// Writes what is buffered and closes this process's handle, so that another program (ffmpeg,
  /// gnuplot) may write temporary() instead; then only commit() or discard() may follow. Throws
  /// as write() does, and also if the close fails.
  void hand_over();

  /// Writes what is buffered, closes the file (both checked) and renames the temporary onto the
  /// target, replacing it. Returns the file's size in bytes. On failure removes the temporary and
  /// throws std::runtime_error "cannot write TARGET: REASON"; if another program was handed the
  /// file and left no regular file at temporary(), REASON says so.
  std::uintmax_t commit();

  /// Closes and removes the temporary if it is still there; the target is left as it was. Never
  /// throws; a second call does nothing.
  void discard() noexcept;

 private:
  void flush();
  [[noreturn]] void fail(const std::string& reason);

  std::filesystem::path target_;
  std::filesystem::path temporary_;
  std::string buffer_;
  int fd_ = -1;
  bool done_ = false;
};

/// Writes `bytes` as the whole content of `target` through an AtomicFile (temporary, checked
/// writes and close, rename). Throws std::runtime_error "cannot write TARGET: REASON" on failure;
/// the target then keeps its old content and no temporary is left. Thread-safe for distinct
/// targets.
void write_file_atomic(const std::filesystem::path& target, std::span<const std::uint8_t> bytes);

/// As write_file_atomic, for text.
void write_text_atomic(const std::filesystem::path& target, std::string_view text);

}  // namespace cps::cli
