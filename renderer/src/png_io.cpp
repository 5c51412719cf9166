// write_png through libpng (Debian's libpng16 + zlib), PngWriter (encoding on worker threads) and
// read_png through stb_image (Debian's libstb).

#include "cps/render/renderer.h"

#include <png.h>
#include <stb_image.h>

#include <condition_variable>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <deque>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

namespace cps::render {
namespace {

// Speed over size. Measured on 15 real 1280x720 frames of the five paper scenes (llvmpipe host,
// Debian 12, median ms per frame, encoding to memory; mean KiB per frame):
//   stb_image_write default (adaptive filter, level 8)   72 ms  263 KiB
//   stb_image_write, filter none, level 1                 29 ms  236 KiB
//   libpng, zlib level 1, filter none                     11 ms  218 KiB
//   libpng, zlib level 6, all filters (libpng default)    52 ms  189 KiB
// The renders are mostly flat colour, which deflate compresses well without row prediction.
constexpr int k_zlib_level = 1;
constexpr int k_png_filters = PNG_FILTER_NONE;

struct ErrorSink {
  char message[256] = {};
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* sink = static_cast<ErrorSink*>(png_get_error_ptr(png));
  std::snprintf(sink->message, sizeof sink->message, "%s", message != nullptr ? message : "?");
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

// Encodes `image` into the open file. Only trivially destructible locals live in this frame, as
// libpng reports errors by longjmp. Returns false with sink.message set on failure.
bool encode(std::FILE* file, const Image& image, ErrorSink& sink) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink, on_png_error,
                                            on_png_warning);
  if (png == nullptr) {
    std::snprintf(sink.message, sizeof sink.message, "libpng: out of memory");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    if (sink.message[0] == '\0') std::snprintf(sink.message, sizeof sink.message, "libpng failed");
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width),
               static_cast<png_uint_32>(image.height), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, k_zlib_level);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, k_png_filters);
  png_write_info(png, info);
  const std::size_t stride = 3u * static_cast<std::size_t>(image.width);
  for (int y = 0; y < image.height; ++y) {
    png_write_row(png, const_cast<png_bytep>(image.pixels.data() + stride * static_cast<std::size_t>(y)));
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

// write_png: image of width x height > 0 with 3 * width * height bytes (RGB8, rows top to bottom),
// else std::runtime_error naming the path. Encodes into "<path>.tmp" in the same folder and renames
// it over `path` (atomic on POSIX within one file system); on any failure the temporary file is
// removed and std::runtime_error names the path and the reason.
void write_png(const std::filesystem::path& path, const Image& image) {
  const auto expected = static_cast<std::size_t>(image.width > 0 ? image.width : 0) *
                        static_cast<std::size_t>(image.height > 0 ? image.height : 0) * 3u;
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != expected) {
    throw std::runtime_error("write_png: invalid image (" + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + ", " +
                             std::to_string(image.pixels.size()) + " bytes) for " + path.string());
  }
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  const auto fail = [&](const std::string& why) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error("write_png: cannot write " + path.string() + ": " + why);
  };
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (file == nullptr) fail(std::strerror(errno));
  ErrorSink sink;
  const bool encoded = encode(file, image, sink);
  const bool flushed = std::fflush(file) == 0;
  const int flush_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (!encoded) fail(sink.message);
  if (!flushed || !closed) fail(std::strerror(flush_errno));
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) fail("cannot rename " + tmp.string() + ": " + ec.message());
}

struct PngWriter::Impl {
  struct Job {
    std::filesystem::path path;
    Image image;
  };
  int max_in_flight;
  mutable std::mutex mutex;
  std::condition_variable work_ready;  // a job was queued, or stop
  std::condition_variable slot_free;   // a job finished (or was dropped)
  std::deque<Job> queue;
  int in_flight = 0;  // queued + being encoded
  bool stopping = false;
  std::exception_ptr error;
  long long written = 0;
  std::vector<std::thread> workers;

  void run() {
    for (;;) {
      Job job;
      {
        std::unique_lock lock(mutex);
        work_ready.wait(lock, [&] { return stopping || !queue.empty(); });
        if (queue.empty()) return;
        job = std::move(queue.front());
        queue.pop_front();
        if (error) {  // after a failure, queued images are dropped
          --in_flight;
          slot_free.notify_all();
          continue;
        }
      }
      std::exception_ptr failure;
      try {
        write_png(job.path, job.image);
      } catch (...) {
        failure = std::current_exception();
      }
      std::lock_guard lock(mutex);
      if (failure && !error) error = failure;
      if (!failure) ++written;
      --in_flight;
      slot_free.notify_all();
    }
  }
};

PngWriter::PngWriter(int threads, int max_in_flight) : impl_(std::make_unique<Impl>()) {
  if (threads < 1 || threads > 16 || max_in_flight < threads) {
    throw std::invalid_argument("PngWriter: threads " + std::to_string(threads) +
                                " must be in [1, 16] and max_in_flight " +
                                std::to_string(max_in_flight) + " at least threads");
  }
  impl_->max_in_flight = max_in_flight;
  for (int i = 0; i < threads; ++i) impl_->workers.emplace_back([this] { impl_->run(); });
}

PngWriter::~PngWriter() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->work_ready.notify_all();
  for (std::thread& t : impl_->workers) t.join();
}

void PngWriter::write(std::filesystem::path path, Image image) {
  std::unique_lock lock(impl_->mutex);
  impl_->slot_free.wait(lock, [&] { return impl_->error || impl_->in_flight < impl_->max_in_flight; });
  if (impl_->error) std::rethrow_exception(impl_->error);
  impl_->queue.push_back({std::move(path), std::move(image)});
  ++impl_->in_flight;
  impl_->work_ready.notify_one();
}

void PngWriter::finish() {
  std::unique_lock lock(impl_->mutex);
  impl_->slot_free.wait(lock, [&] { return impl_->in_flight == 0; });
  if (impl_->error) std::rethrow_exception(impl_->error);
}

long long PngWriter::written() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->written;
}

// read_png: decodes any PNG stb_image reads, converted to 3 channels (RGB8, rows top to bottom).
// std::runtime_error naming the path and stb's failure reason if it cannot.
Image read_png(const std::filesystem::path& path) {
  int w = 0;
  int h = 0;
  int channels_in_file = 0;
  stbi_uc* data = stbi_load(path.c_str(), &w, &h, &channels_in_file, 3);
  if (data == nullptr) {
    const char* reason = stbi_failure_reason();
    throw std::runtime_error("read_png: cannot read " + path.string() + ": " +
                             (reason != nullptr ? reason : "unknown error"));
  }
  Image image;
  image.width = w;
  image.height = h;
  image.pixels.assign(data, data + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3u);
  stbi_image_free(data);
  return image;
}

}  // namespace cps::render
