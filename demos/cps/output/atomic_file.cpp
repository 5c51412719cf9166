#include "output/atomic_file.h"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <random>
#include <stdexcept>

namespace cps::cli {
namespace fs = std::filesystem;
namespace {

constexpr std::size_t k_buffer_bytes = 64 * 1024;

std::string draw_token() {
  std::uint64_t bits = 0;
  if (getrandom(&bits, sizeof bits, 0) != static_cast<ssize_t>(sizeof bits)) {
    std::random_device device;
    bits = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(bits));
  return text;
}

// Writes all of [data, data + size) to fd; returns 0 or the errno of the failure.
int write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return ENOSPC;  // no progress: treat as a full device
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return 0;
}

}  // namespace

const std::string& run_token() {
  static std::mutex mutex;
  static std::string token;
  static pid_t owner = 0;
  const std::lock_guard lock(mutex);
  if (token.empty() || owner != ::getpid()) {
    token = draw_token();
    owner = ::getpid();
  }
  return token;
}

std::string temporary_name(std::string_view name, std::string_view token) {
  std::string t(name);
  t += '.';
  t += token;
  t += ".tmp";
  return t;
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  temporary_ = target_.parent_path() / temporary_name(target_.filename().string(), run_token());
  fd_ = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    done_ = true;  // nothing of ours to remove: the temporary was not created
    throw std::runtime_error("cannot write " + target_.string() + ": " + std::strerror(errno));
  }
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::fail(const std::string& reason) {
  discard();
  throw std::runtime_error("cannot write " + target_.string() + ": " + reason);
}

void AtomicFile::flush() {
  if (buffer_.empty()) return;
  const int error = write_all(fd_, buffer_.data(), buffer_.size());
  buffer_.clear();
  if (error != 0) fail(std::strerror(error));
}

void AtomicFile::write(std::span<const std::uint8_t> bytes) {
  if (done_ || fd_ < 0) {
    throw std::logic_error("AtomicFile::write after commit, discard or hand_over: " + target_.string());
  }
  const char* data = reinterpret_cast<const char*>(bytes.data());
  if (buffer_.size() + bytes.size() <= k_buffer_bytes) {
    buffer_.append(data, bytes.size());
    return;
  }
  flush();
  if (bytes.size() >= k_buffer_bytes) {  // large: straight to the file
    const int error = write_all(fd_, data, bytes.size());
    if (error != 0) fail(std::strerror(error));
  } else {
    buffer_.append(data, bytes.size());
  }
}

void AtomicFile::write(std::string_view text) {
  write(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

void AtomicFile::hand_over() {
  if (done_ || fd_ < 0) {
    throw std::logic_error("AtomicFile::hand_over after commit, discard or hand_over: " + target_.string());
  }
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) fail(std::strerror(errno));
}

std::uintmax_t AtomicFile::commit() {
  if (done_) throw std::logic_error("AtomicFile::commit after commit or discard: " + target_.string());
  if (fd_ >= 0) {
    flush();
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) fail(std::strerror(errno));
  }
  struct stat st {};
  if (::lstat(temporary_.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
    fail("the program writing it left no regular file at " + temporary_.string());
  }
  if (::rename(temporary_.c_str(), target_.c_str()) != 0) fail(std::strerror(errno));
  done_ = true;
  return static_cast<std::uintmax_t>(st.st_size);
}

void AtomicFile::discard() noexcept {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!done_) ::unlink(temporary_.c_str());
  done_ = true;
  buffer_.clear();
}

void write_file_atomic(const fs::path& target, std::span<const std::uint8_t> bytes) {
  AtomicFile file(target);
  file.write(bytes);
  file.commit();
}

void write_text_atomic(const fs::path& target, std::string_view text) {
  AtomicFile file(target);
  file.write(text);
  file.commit();
}

}  // namespace cps::cli
