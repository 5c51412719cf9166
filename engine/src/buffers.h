#pragma once
// Step buffers that keep their storage, and asking for them ahead of a sweep (internal to the
// engine).

#include <cstddef>
#include <iterator>
#include <type_traits>
#include <vector>

namespace cps::detail {

/// Bytes from which a step buffer asks for huge pages (8 MiB; a typical value: four 2 MiB pages,
/// so that little of it lies outside whole ones).
inline constexpr std::size_t kHugePagesFrom = std::size_t{8} << 20;

/// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with huge pages
/// (Linux's madvise(MADV_HUGEPAGE); nothing elsewhere): a hint, which changes no result. A page
/// not yet touched then costs one fault per 2 MiB instead of 512, where a fault costs
/// microseconds (a virtual machine's can cost 15 us). No errors (a refusal is ignored).
void advise_huge_pages(const void* data, std::size_t bytes);

/// Makes room for n elements in v with headroom: when n exceeds the capacity, it reserves 2n, so
/// that counts which wander around a level (contacts coming and going from step to step) stop
/// allocating once they have been seen, instead of allocating at every new largest count. From
/// kHugePagesFrom bytes the new storage asks for huge pages before anything is written to it.
template <class T, class A>
void reserve_with_headroom(std::vector<T, A>& v, std::size_t n) {
  if (n <= v.capacity()) return;
  if (2 * n * sizeof(T) < kHugePagesFrom) {
    v.reserve(2 * n);
    return;
  }
  std::vector<T, A> bigger(v.get_allocator());
  bigger.reserve(2 * n);
  advise_huge_pages(bigger.data(), bigger.capacity() * sizeof(T));
  if constexpr (std::is_nothrow_move_constructible_v<T> || !std::is_copy_constructible_v<T>) {
    bigger.insert(bigger.end(), std::make_move_iterator(v.begin()), std::make_move_iterator(v.end()));
  } else {  // as reserve does: v stays whole if a copy throws
    bigger.insert(bigger.end(), v.begin(), v.end());
  }
  v.swap(bigger);
}

/// A copy of v with v's capacity (a plain copy has room for its contents only), on huge pages
/// from kHugePagesFrom bytes as reserve_with_headroom's storage: a copied step buffer then grows,
/// in the copy's steps, when the original's would. Errors: std::bad_alloc.
template <class T, class A>
std::vector<T, A> copy_with_capacity(const std::vector<T, A>& v) {
  std::vector<T, A> out(v.get_allocator());
  out.reserve(v.capacity());
  if (out.capacity() * sizeof(T) >= kHugePagesFrom) advise_huge_pages(out.data(), out.capacity() * sizeof(T));
  out.assign(v.begin(), v.end());
  return out;
}

/// A std::vector whose copies keep its capacity (copy_with_capacity): for the caches that a step
/// reuses, so that a copied world (a bench repeat) does not grow them again in its first steps.
template <class T>
class KeptBuffer : public std::vector<T> {
 public:
  KeptBuffer() = default;
  KeptBuffer(const KeptBuffer& other) : std::vector<T>(copy_with_capacity(other.as_vector())) {}
  KeptBuffer(KeptBuffer&&) noexcept = default;
  KeptBuffer& operator=(const KeptBuffer& other) {
    if (this != &other) std::vector<T>::operator=(copy_with_capacity(other.as_vector()));
    return *this;
  }
  KeptBuffer& operator=(KeptBuffer&&) noexcept = default;
  ~KeptBuffer() = default;

 private:
  const std::vector<T>& as_vector() const { return *this; }
};

/// resize(n) after reserve_with_headroom(n): new elements are value-initialised, old ones kept.
template <class T, class A>
void resize_with_headroom(std::vector<T, A>& v, std::size_t n) {
  reserve_with_headroom(v, n);
  v.resize(n);
}

/// v = n copies of value, after reserve_with_headroom(n).
template <class T, class A>
void assign_with_headroom(std::vector<T, A>& v, std::size_t n, const T& value) {
  reserve_with_headroom(v, n);
  v.assign(n, value);
}

/// Bytes of a sweep's stream from which it prefetches (1 MiB): fewer stay in a core's cache from
/// sweep to sweep (its L2 cache holds 1 MiB on the machines measured), and asking for them again
/// only costs instructions (docs/benchmarks.md, "Prefetching the sweeps' streams").
inline constexpr std::size_t kPrefetchFrom = std::size_t{1} << 20;

/// Asks for the cache lines (64 bytes) of [start, start + bytes), to be read or, with kWrite,
/// written: a hint, which changes no result.
template <bool kWrite>
[[gnu::always_inline]] inline void prefetch_lines(const void* start, std::size_t bytes) {
  const char* p = static_cast<const char*>(start);
  for (std::size_t off = 0; off < bytes; off += 64) __builtin_prefetch(p + off, kWrite ? 1 : 0, 3);
}

}  // namespace cps::detail
