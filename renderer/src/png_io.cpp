// encode_png (a PNG file written by stb_image_write around a zlib stream from Intel's ISA-L, or
// from zlib when the build has no ISA-L), PngWriter (encoding on worker threads, files written by
// its sink) and read_png through libpng.

#include "cps/render/renderer.h"

#include <png.h>
#include <zlib.h>
#if CPS_PNG_ISAL
#include <isa-l/igzip_lib.h>
#endif

#include <algorithm>
#include <array>
#include <cstddef>
#include <cerrno>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
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
// Measured on 17 real 1280x720 frames of each of the five paper scenes (cps render SCENE
// --seconds 2 --fps 8, checkered ground; Debian 12 on the 2-core host, shared with builds; thread
// CPU ms per frame encoding to memory, the median of 3-9 repeats, then the median over frames;
// mean KiB per frame; pendulum_wave / the four others):
//   stb_image_write 1.16, ISA-L 2.30 level 2, no filter (chosen)  1.6 / 3.4-6.9   55 / 231-457
//   the PNG file formerly assembled here around that ISA-L stream  1.5 / 3.4-6.6   the same bytes
//   the chosen, but stb's blocks from std::malloc on every call    3.2 / 6.9 (stack)
//   stb_image_write's own deflate (its level 8), no filter         45 / 72 (stack) 63 / 448 (stack)
//   stb_image_write, zlib 1.2.13 level 1 (build without ISA-L)     9.4 / 17-30     55 / 237-475
// stb_image_write with ISA-L is 2-7 % slower than the file assembled here (it copies each row
// twice and the finished file once more) and writes the same bytes. An earlier measurement, on
// frames of an earlier look (240-269 KiB), found libpng with zlib level 1 (7x) and libdeflate 1.14
// level 1 (4.6x) slower than ISA-L, ISA-L's level 1 about as fast as its level 2, and the row
// filters up or sub 1.4-1.9x slower for files 0-5 % smaller.
// The renders are mostly flat colour, which deflate compresses well without row prediction, and
// a row filter costs more than it saves here. Every row therefore uses PNG filter type 0 (none),
// and the zlib stream of the whole image is made in one call (ISA-L's stateless mode).
#if CPS_PNG_ISAL
constexpr int k_deflate_level = 2;  // igzip level, 0..3; typical 1-2
#else
constexpr int k_deflate_level = 1;  // zlib level, 0..9 (fallback without ISA-L); typical 1
#endif

/// The memory of stb_image_write (STBIW_MALLOC, STBIW_REALLOC, STBIW_FREE) and of deflate_zlib's
/// result, which stb frees. stb allocates the same few large blocks for every image (the filtered
/// rows, 3 width + 1 bytes a row; a line; the zlib stream; the file) and frees them before it
/// returns. From std::malloc, blocks of megabytes are mapped afresh and returned to the system on
/// every call (glibc's malloc trims them), and touching their new pages took more CPU than the
/// deflate itself (see the measurements above). So each thread keeps up to k_kept_blocks freed
/// blocks and hands out the smallest one that is large enough: a stream of frames of one size
/// allocates nothing after the first. Each block starts with a header giving its capacity.
/// Not shared between threads (each encoder thread has its own).
class BlockCache {
 public:
  BlockCache() = default;
  BlockCache(const BlockCache&) = delete;
  BlockCache& operator=(const BlockCache&) = delete;
  ~BlockCache() {
    for (std::size_t i = 0; i < count_; ++i) std::free(kept_[i]);
  }

  /// A block of at least `bytes` bytes (aligned as std::malloc's), or nullptr if memory runs out.
  void* allocate(std::size_t bytes) {
    std::size_t best = count_;
    for (std::size_t i = 0; i < count_; ++i) {
      const std::size_t c = capacity(kept_[i]);
      if (c >= bytes && (best == count_ || c < capacity(kept_[best]))) best = i;
    }
    if (best < count_) {
      Header* block = kept_[best];
      kept_[best] = kept_[--count_];
      return block + 1;
    }
    if (bytes > SIZE_MAX - sizeof(Header)) return nullptr;
    auto* block = static_cast<Header*>(std::malloc(sizeof(Header) + bytes));
    if (block == nullptr) return nullptr;
    block->capacity = bytes;
    return block + 1;
  }

  /// Keeps the block at `p` (from allocate; nullptr is ignored) for later calls: if k_kept_blocks
  /// are kept already, the smallest of them and this one goes back to std::free.
  void release(void* p) {
    if (p == nullptr) return;
    Header* block = static_cast<Header*>(p) - 1;
    if (count_ < k_kept_blocks) {
      kept_[count_++] = block;
      return;
    }
    std::size_t smallest = 0;
    for (std::size_t i = 1; i < count_; ++i) {
      if (capacity(kept_[i]) < capacity(kept_[smallest])) smallest = i;
    }
    if (capacity(kept_[smallest]) < capacity(block)) std::swap(kept_[smallest], block);
    std::free(block);
  }

  /// The block at `p` grown to at least `bytes` bytes, its first bytes kept (like std::realloc;
  /// nullptr: a new block); nullptr if memory runs out (then `p` is still valid).
  void* reallocate(void* p, std::size_t bytes) {
    if (p == nullptr) return allocate(bytes);
    const std::size_t old = capacity(static_cast<Header*>(p) - 1);
    if (old >= bytes) return p;
    void* grown = allocate(bytes);
    if (grown == nullptr) return nullptr;
    std::memcpy(grown, p, old);
    release(p);
    return grown;
  }

 private:
  struct alignas(std::max_align_t) Header {
    std::size_t capacity;  // bytes after the header
  };
  static std::size_t capacity(const Header* block) { return block->capacity; }
  // The blocks one image needs at once (the rows and the zlib stream, then the stream and the
  // file) plus the line and one spare; typical 4.
  static constexpr std::size_t k_kept_blocks = 4;
  std::array<Header*, k_kept_blocks> kept_{};
  std::size_t count_ = 0;
};

BlockCache& block_cache() {
  thread_local BlockCache cache;
  return cache;
}
void* stb_allocate(std::size_t bytes) { return block_cache().allocate(bytes); }
// Unused while STBIW_ZLIB_COMPRESS is set (only stb's own deflate grows its buffers), but stb
// requires it.
[[maybe_unused]] void* stb_reallocate(void* p, std::size_t bytes) {
  return block_cache().reallocate(p, bytes);
}
void stb_release(void* p) { block_cache().release(p); }

/// Why the last deflate_zlib call on this thread failed (empty if it did not): stb_image_write
/// only sees a null result, so encode_png reads the reason here.
thread_local std::string t_deflate_error;

/// stb_image_write's STBIW_ZLIB_COMPRESS hook: compresses data[0, data_len) into one zlib stream
/// (RFC 1950: 2-byte header, deflate data of RFC 1951, Adler-32 of the data) at `level` (stb's
/// stbi_write_png_compression_level, set to k_deflate_level by encode_png). Returns the stream in
/// memory from stb_allocate, which stb frees with STBIW_FREE (stb_release), its length in
/// *out_len; nullptr if the compressor fails (the reason in t_deflate_error) or memory runs out.
unsigned char* deflate_zlib(unsigned char* data, int data_len, int* out_len, int level) {
  t_deflate_error.clear();
  const auto in_size = static_cast<std::size_t>(data_len);
#if CPS_PNG_ISAL
  // Room for the worst case: incompressible data sent in stored blocks, 5 bytes per block of at
  // most 65535 bytes (RFC 1951) plus the zlib header and Adler-32 (RFC 1950); 1/1024 + 1 KiB
  // covers both.
  const std::size_t room = in_size + in_size / 1024u + 1024u;
  auto* out = static_cast<unsigned char*>(stb_allocate(room));
  if (out == nullptr) {
    t_deflate_error = "out of memory";
    return nullptr;
  }
  // ISA-L's work space for the level, kept per thread so that a stream of frames allocates it once.
  thread_local std::vector<std::uint8_t> level_buf;
  static constexpr std::uint32_t k_level_buf_bytes[] = {0, ISAL_DEF_LVL1_DEFAULT,
                                                        ISAL_DEF_LVL2_DEFAULT,
                                                        ISAL_DEF_LVL3_DEFAULT};
  const int isal_level = std::clamp(level, 0, 3);
  const std::uint32_t level_bytes = k_level_buf_bytes[isal_level];
  if (level_buf.size() < level_bytes) level_buf.assign(level_bytes, 0);
  isal_zstream z;
  isal_deflate_stateless_init(&z);
  z.gzip_flag = IGZIP_ZLIB;
  z.level = static_cast<std::uint32_t>(isal_level);
  z.level_buf = level_bytes > 0 ? level_buf.data() : nullptr;
  z.level_buf_size = level_bytes;
  z.flush = NO_FLUSH;
  z.end_of_stream = 1;
  z.next_in = data;
  z.avail_in = static_cast<std::uint32_t>(in_size);
  z.next_out = out;
  z.avail_out = static_cast<std::uint32_t>(room);
  const int status = isal_deflate_stateless(&z);
  if (status != COMP_OK) {
    stb_release(out);
    t_deflate_error = "ISA-L deflate failed (status " + std::to_string(status) + ")";
    return nullptr;
  }
  *out_len = static_cast<int>(z.total_out);
  return out;
#else
  uLongf length = compressBound(static_cast<uLong>(in_size));
  auto* out = static_cast<unsigned char*>(stb_allocate(length));
  if (out == nullptr) {
    t_deflate_error = "out of memory";
    return nullptr;
  }
  const int status = compress2(out, &length, data, static_cast<uLong>(in_size), level);
  if (status != Z_OK) {
    stb_release(out);
    t_deflate_error = "zlib compress2 failed (status " + std::to_string(status) + ")";
    return nullptr;
  }
  *out_len = static_cast<int>(length);
  return out;
#endif
}

}  // namespace
}  // namespace cps::render

// stb_image_write (Debian libstb-dev), compiled here with internal linkage: it lays out the PNG
// (signature, IHDR, one IDAT, IEND) and its filtered rows; the deflate is ISA-L's (or zlib's)
// through STBIW_ZLIB_COMPRESS and the chunk CRC-32 is zlib's crc32 through STBIW_CRC32 (PNG
// specification, 3rd ed., 5.3: the CRC of ISO 3309), faster than stb's byte-wise table; its
// memory comes from this thread's BlockCache.
#define STBIW_ZLIB_COMPRESS cps::render::deflate_zlib
#define STBIW_MALLOC(bytes) cps::render::stb_allocate(bytes)
#define STBIW_REALLOC(p, bytes) cps::render::stb_reallocate((p), (bytes))
#define STBIW_FREE(p) cps::render::stb_release(p)
#define STBIW_CRC32(buffer, len) \
  static_cast<unsigned int>(crc32(0L, (buffer), static_cast<uInt>(len)))
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include <stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace cps::render {
namespace {

/// stbi_write_png_to_func's callback: appends the file's bytes to the std::vector<std::uint8_t>
/// at `context` (stb calls it once, with the whole file).
void append_bytes(void* context, void* data, int size) {
  auto& file = *static_cast<std::vector<std::uint8_t>*>(context);
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  file.insert(file.end(), bytes, bytes + size);
}

// The most bytes of filtered rows, (3 width + 1) height, one PNG of cps may hold: 1 GiB.
// stb_image_write counts them in int; read_png takes no larger picture than encode_png writes.
constexpr std::uint64_t k_max_row_bytes = std::uint64_t{1} << 30;

// (3 width + 1) height in 64 bits: no wrap for any two 32-bit sides.
std::uint64_t filtered_row_bytes(std::uint64_t width, std::uint64_t height) {
  return (3u * width + 1u) * height;
}

}  // namespace

// encode_png: image of width x height > 0 with 3 * width * height bytes (RGB8, rows top to
// bottom), else std::invalid_argument. stb_image_write builds the file in memory it allocates and
// frees each call; the finished file is copied into this thread's buffer (kept for the next call)
// and a view of it returned.
std::span<const std::uint8_t> encode_png(const Image& image) {
  const auto expected = static_cast<std::size_t>(image.width > 0 ? image.width : 0) *
                        static_cast<std::size_t>(image.height > 0 ? image.height : 0) * 3u;
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != expected) {
    throw std::invalid_argument("encode_png: invalid image (" + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + ", " +
                                std::to_string(image.pixels.size()) + " bytes)");
  }
  // stb_image_write counts bytes in int: the filtered rows, (3 width + 1) height bytes, and the
  // file, about as large for noise, must stay below INT_MAX with room for the chunks.
  const std::uint64_t row_bytes = filtered_row_bytes(image.width, image.height);
  if (row_bytes > k_max_row_bytes) {
    throw std::invalid_argument("encode_png: image " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + " too large (" +
                                std::to_string(row_bytes) + " bytes of rows; at most " +
                                std::to_string(k_max_row_bytes) + ")");
  }
  // stb's settings are globals of this file: set once, before the first image, then only read.
  static const bool settings = [] {
    stbi_write_force_png_filter = 0;  // filter type 0 (none) on every row
    stbi_write_png_compression_level = k_deflate_level;  // handed to deflate_zlib
    return true;
  }();
  (void)settings;
  thread_local std::vector<std::uint8_t> file;
  file.clear();
  if (stbi_write_png_to_func(append_bytes, &file, image.width, image.height, 3,
                             image.pixels.data(), 3 * image.width) == 0) {
    throw std::runtime_error("encode_png: stb_image_write failed (" +
                             (t_deflate_error.empty() ? std::string("out of memory")
                                                      : t_deflate_error) +
                             ")");
  }
  return {file.data(), file.size()};
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
  // Only a regular file (after links): a FIFO or a device named .png would block or never end.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (ec) throw std::runtime_error("read_png: cannot read " + path.string() + ": " + ec.message());
  if (!std::filesystem::is_regular_file(status)) {
    throw std::runtime_error("read_png: cannot read " + path.string() + ": not a regular file");
  }
  if (png_image_begin_read_from_file(&png, path.c_str()) == 0) return fail();
  // The declared size, checked in 64 bits before any pixel is allocated.
  if (filtered_row_bytes(png.width, png.height) > k_max_row_bytes) {
    const std::string size = std::to_string(png.width) + "x" + std::to_string(png.height);
    png_image_free(&png);
    throw std::runtime_error("read_png: cannot read " + path.string() + ": it declares " + size +
                             " pixels, more than the " + std::to_string(k_max_row_bytes) +
                             " bytes of rows ((3 width + 1) height) a PNG of cps may hold");
  }
  // 16-bit samples without gAMA or sRGB are sRGB, as 8-bit ones are (PNG spec 11.3.3.2 leaves the
  // choice to the reader; libpng's simplified API would take them as linear light).
  png.flags |= PNG_IMAGE_FLAG_16BIT_sRGB;
  png.format = PNG_FORMAT_RGB;
  Image image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.pixels.resize(static_cast<std::size_t>(png.width) * png.height * 3u);
  if (png_image_finish_read(&png, nullptr, image.pixels.data(), 0, nullptr) == 0) return fail();
  return image;
}

}  // namespace cps::render
