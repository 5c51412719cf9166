// encode_png (a PNG file assembled here around a zlib stream from Intel's ISA-L, or from zlib when
// the build has no ISA-L), PngWriter (encoding on worker threads, files written by its sink) and
// read_png through libpng.

#include "cps/render/renderer.h"

#include <png.h>
#include <zlib.h>
#if CPS_PNG_ISAL
#include <isa-l/igzip_lib.h>
#endif

#include <array>
#include <cerrno>
#include <condition_variable>
#include <cstdint>
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
#include <vector>

namespace cps::render {
namespace {

// Speed over size: a frame is drawn in 15-300 ms and its encoding runs beside the drawing of the
// next frame on the same two cores, so every millisecond of encoder CPU slows the pipeline down.
// Measured on 8-16 real 1280x720 frames of each of the five paper scenes (Debian 12 on the
// 2-core host, median thread CPU ms per frame, encoding to memory; mean KiB per frame;
// pendulum_wave / the four others; an earlier note found stb_image_write slower still):
//   libpng 1.6, zlib 1.2.13 level 1, filter none          5.7 / 11-14   55 / 251-269 KiB
//   libpng, zlib level 1, Z_RLE + filter up or sub        6.6 / 12-18   47 / 236-482 KiB
//   libpng, zlib level 1, Z_FILTERED + filter up or sub   6.9 / 13-16   52 / 256-359 KiB
//   libdeflate 1.14 level 1, filter none                  3.7 / 6.3-7   43 / 212-232 KiB
//   ISA-L 2.30 igzip level 1, filter none                 0.8 / 2.4-2.7 55 / 243-262 KiB
//   ISA-L igzip level 2, filter none (chosen)             0.8 / 2.5-2.8 55 / 240-259 KiB
//   ISA-L igzip level 1, filter up or sub                 1.5 / 3.4-4.9 52 / 235-369 KiB
// The renders are mostly flat colour, which deflate compresses well without row prediction, and
// a row filter costs more than it saves here. Every row therefore uses PNG filter type 0 (none),
// and the zlib stream of the whole image is made in one call (ISA-L's stateless mode).
#if CPS_PNG_ISAL
constexpr int k_isal_level = 2;                            // igzip level, 0..3; typical 1-2
constexpr std::uint32_t k_isal_level_buf = ISAL_DEF_LVL2_DEFAULT;  // bytes of work space
#else
constexpr int k_zlib_level = 1;  // zlib level, 0..9 (fallback without ISA-L); typical 1
#endif

void put_be32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}

/// Writes a chunk's CRC-32 of its type and data (4 + length bytes from `type`) at `type` + 4 +
/// length (PNG specification, 3rd ed., 5.3: CRC-32 of ISO 3309, as in zlib's crc32).
void put_crc(std::uint8_t* type, std::size_t length) {
  put_be32(type + 4 + length,
           static_cast<std::uint32_t>(crc32(0L, type, static_cast<uInt>(length + 4))));
}

/// One PNG encoder's buffers, kept between images so that a stream of frames allocates (and
/// clears) nothing after the first. Not thread-safe: one encoder per thread.
struct PngEncoder {
  std::vector<std::uint8_t> scanlines;  // height rows of (filter byte 0, 3 * width bytes RGB)
  std::vector<std::uint8_t> file;       // the PNG file in its first `size` bytes
  std::size_t size = 0;
#if CPS_PNG_ISAL
  std::vector<std::uint8_t> level_buf;  // ISA-L's work space for k_isal_level
#endif

  /// Encodes `image` (checked by the caller: sizes > 0, 3 * width * height bytes) into
  /// file[0, size): an 8-bit RGB, non-interlaced PNG with chunks IHDR, one IDAT and IEND.
  /// Throws std::runtime_error if the compressor fails.
  void encode(const Image& image) {
    const std::size_t row = 3u * static_cast<std::size_t>(image.width);
    const auto height = static_cast<std::size_t>(image.height);
    if (scanlines.size() != (row + 1u) * height) scanlines.resize((row + 1u) * height);
    for (std::size_t y = 0; y < height; ++y) {
      std::uint8_t* line = scanlines.data() + (row + 1u) * y;
      line[0] = 0;  // filter type: none
      std::memcpy(line + 1, image.pixels.data() + row * y, row);
    }

    // Layout: signature (8), IHDR (12 + 13), IDAT (12 + n), IEND (12). The IDAT data, the zlib
    // stream, is compressed straight into place, with room for the worst case: incompressible
    // data sent in stored blocks, 5 bytes per block of at most 65535 bytes (RFC 1951) plus the
    // zlib header and Adler-32 (RFC 1950); 1/1024 + 1 KiB covers both.
    constexpr std::size_t k_ihdr = 8;
    constexpr std::size_t k_idat = k_ihdr + 12 + 13;
    const std::size_t room = scanlines.size() + scanlines.size() / 1024u + 1024u;
    if (file.size() < k_idat + 12 + room + 12) file.resize(k_idat + 12 + room + 12);
    std::uint8_t* out = file.data();

    static constexpr std::array<std::uint8_t, 8> k_signature = {0x89, 'P', 'N', 'G',
                                                                 0x0D, 0x0A, 0x1A, 0x0A};
    std::memcpy(out, k_signature.data(), k_signature.size());
    put_be32(out + k_ihdr, 13);
    std::memcpy(out + k_ihdr + 4, "IHDR", 4);
    put_be32(out + k_ihdr + 8, static_cast<std::uint32_t>(image.width));
    put_be32(out + k_ihdr + 12, static_cast<std::uint32_t>(image.height));
    out[k_ihdr + 16] = 8;  // bits per sample
    out[k_ihdr + 17] = 2;  // colour type: RGB
    out[k_ihdr + 18] = 0;  // compression method: zlib deflate
    out[k_ihdr + 19] = 0;  // filter method 0 (five filter types; every row uses type 0, none)
    out[k_ihdr + 20] = 0;  // no interlace
    put_crc(out + k_ihdr + 4, 13);

    std::memcpy(out + k_idat + 4, "IDAT", 4);
    const std::size_t length = deflate_into(out + k_idat + 8, room);
    put_be32(out + k_idat, static_cast<std::uint32_t>(length));
    put_crc(out + k_idat + 4, length);

    const std::size_t iend = k_idat + 12 + length;
    put_be32(out + iend, 0);
    std::memcpy(out + iend + 4, "IEND", 4);
    put_crc(out + iend + 4, 0);
    size = iend + 12;
  }

 private:
  /// Compresses `scanlines` into out[0, room) as one zlib stream; returns its length in bytes.
  std::size_t deflate_into(std::uint8_t* out, std::size_t room) {
#if CPS_PNG_ISAL
    if (level_buf.size() != k_isal_level_buf) level_buf.assign(k_isal_level_buf, 0);
    isal_zstream z;
    isal_deflate_stateless_init(&z);
    z.gzip_flag = IGZIP_ZLIB;
    z.level = k_isal_level;
    z.level_buf = level_buf.data();
    z.level_buf_size = static_cast<std::uint32_t>(level_buf.size());
    z.flush = NO_FLUSH;
    z.end_of_stream = 1;
    z.next_in = scanlines.data();
    z.avail_in = static_cast<std::uint32_t>(scanlines.size());
    z.next_out = out;
    z.avail_out = static_cast<std::uint32_t>(room);
    const int status = isal_deflate_stateless(&z);
    if (status != COMP_OK) {
      throw std::runtime_error("ISA-L deflate failed (status " + std::to_string(status) + ")");
    }
    return z.total_out;
#else
    z_stream z{};
    if (deflateInit(&z, k_zlib_level) != Z_OK) throw std::runtime_error("zlib: deflateInit failed");
    z.next_in = scanlines.data();
    z.avail_in = static_cast<uInt>(scanlines.size());
    z.next_out = out;
    z.avail_out = static_cast<uInt>(room);
    const int status = deflate(&z, Z_FINISH);
    const std::size_t length = z.total_out;
    deflateEnd(&z);
    if (status != Z_STREAM_END) {
      throw std::runtime_error("zlib deflate failed (status " + std::to_string(status) + ")");
    }
    return length;
#endif
  }
};

}  // namespace

// encode_png: image of width x height > 0 with 3 * width * height bytes (RGB8, rows top to
// bottom), else std::invalid_argument. Encodes into this thread's buffers (kept for the next call:
// about 2 x 3 x width x height bytes) and returns a view of the file's bytes in them.
std::span<const std::uint8_t> encode_png(const Image& image) {
  const auto expected = static_cast<std::size_t>(image.width > 0 ? image.width : 0) *
                        static_cast<std::size_t>(image.height > 0 ? image.height : 0) * 3u;
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != expected) {
    throw std::invalid_argument("encode_png: invalid image (" + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + ", " +
                                std::to_string(image.pixels.size()) + " bytes)");
  }
  thread_local PngEncoder encoder;
  encoder.encode(image);
  return {encoder.file.data(), encoder.size};
}

struct PngWriter::Impl {
  struct Job {
    std::filesystem::path path;
    Image image;
  };
  FileSink sink;
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
      std::span<const std::uint8_t> bytes;
      try {
        bytes = encode_png(job.image);
      } catch (const std::exception& e) {
        failure = std::make_exception_ptr(
            std::runtime_error("cannot write " + job.path.string() + ": " + e.what()));
      }
      if (!failure) {
        try {
          sink(job.path, bytes);
        } catch (...) {
          failure = std::current_exception();
        }
      }
      std::lock_guard lock(mutex);
      if (failure && !error) error = failure;
      if (!failure) ++written;
      --in_flight;
      slot_free.notify_all();
    }
  }
};

PngWriter::PngWriter(FileSink sink, int threads, int max_in_flight)
    : impl_(std::make_unique<Impl>()) {
  if (!sink) throw std::invalid_argument("PngWriter: no sink to write the files");
  if (threads < 1 || threads > 16 || max_in_flight < threads) {
    throw std::invalid_argument("PngWriter: threads " + std::to_string(threads) +
                                " must be in [1, 16] and max_in_flight " +
                                std::to_string(max_in_flight) + " at least threads");
  }
  impl_->sink = std::move(sink);
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

// read_png: decodes any PNG libpng reads (its simplified API, which checks every chunk's CRC and
// the zlib stream's Adler-32), converted to RGB8, rows top to bottom; an alpha channel is
// composited onto black. std::runtime_error naming the path and libpng's message if it cannot.
Image read_png(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  const auto fail = [&]() -> Image {
    const std::string why = png.message[0] != '\0' ? png.message : "unknown error";
    png_image_free(&png);
    throw std::runtime_error("read_png: cannot read " + path.string() + ": " + why);
  };
  if (png_image_begin_read_from_file(&png, path.c_str()) == 0) return fail();
  png.format = PNG_FORMAT_RGB;
  Image image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.pixels.resize(PNG_IMAGE_SIZE(png));
  if (png_image_finish_read(&png, nullptr, image.pixels.data(), 0, nullptr) == 0) return fail();
  return image;
}

}  // namespace cps::render
