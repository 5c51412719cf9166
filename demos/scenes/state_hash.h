#pragma once
// A 64-bit hash of a world's state, to tell in one number whether two runs ended in the same
// state to the last bit (as Box2D's determinism test and Jolt's -validate_hash do).

#include "cps/world.h"

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace cps::scenes {

/// XXH3-64 (Debian's libxxhash) of the IEEE-754 bytes of every body's state, in body order: per
/// body its position x (3 doubles, m), orientation o (w, x, y, z), linear momentum p (3, N s) and
/// angular momentum l (3, N m s): 13 doubles, 104 bytes a body, in the host's byte order (x86-64
/// and every other little-endian host agree). Static bodies are included. Raises nothing.
std::uint64_t state_hash(std::span<const Body> bodies);

/// state_hash of world.bodies().
std::uint64_t state_hash(const World& world);

/// The hash as 16 lower-case hex digits ("00ab..."), the form `cps simulate --json` prints.
std::string format_hash(std::uint64_t hash);

/// Parses 16 hex digits (either case, an optional "0x" prefix) into a hash; std::nullopt for
/// anything else (another length, a non-hex character).
std::optional<std::uint64_t> parse_hash(std::string_view text);

}  // namespace cps::scenes
