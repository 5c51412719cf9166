#include "state_hash.h"

#include <xxhash.h>

#include <array>
#include <cstdio>

namespace cps::scenes {

std::uint64_t state_hash(std::span<const Body> bodies) {
  XXH3_state_t* state = XXH3_createState();
  XXH3_64bits_reset(state);
  for (const Body& b : bodies) {
    const std::array<double, 13> s = {b.x.x(), b.x.y(), b.x.z(), b.o.w(), b.o.x(),
                                      b.o.y(), b.o.z(), b.p.x(), b.p.y(), b.p.z(),
                                      b.l.x(), b.l.y(), b.l.z()};
    XXH3_64bits_update(state, s.data(), sizeof s);
  }
  const std::uint64_t hash = XXH3_64bits_digest(state);
  XXH3_freeState(state);
  return hash;
}

std::uint64_t state_hash(const World& world) { return state_hash(world.bodies()); }

std::string format_hash(std::uint64_t hash) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

std::optional<std::uint64_t> parse_hash(std::string_view text) {
  if (text.size() == 18 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) text.remove_prefix(2);
  if (text.size() != 16) return std::nullopt;
  std::uint64_t value = 0;
  for (const char c : text) {
    int digit;
    if (c >= '0' && c <= '9') {
      digit = c - '0';
    } else if (c >= 'a' && c <= 'f') {
      digit = c - 'a' + 10;
    } else if (c >= 'A' && c <= 'F') {
      digit = c - 'A' + 10;
    } else {
      return std::nullopt;
    }
    value = (value << 4) | static_cast<std::uint64_t>(digit);
  }
  return value;
}

}  // namespace cps::scenes
