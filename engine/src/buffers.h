#pragma once
// Step buffers that keep their storage (internal to the engine).

#include <cstddef>
#include <vector>

namespace cps::detail {

/// Makes room for n elements in v with headroom: when n exceeds the capacity, it reserves 2n, so
/// that counts which wander around a level (contacts coming and going from step to step) stop
/// allocating once they have been seen, instead of allocating at every new largest count.
template <class T, class A>
void reserve_with_headroom(std::vector<T, A>& v, std::size_t n) {
  if (n > v.capacity()) v.reserve(2 * n);
}

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

}  // namespace cps::detail
