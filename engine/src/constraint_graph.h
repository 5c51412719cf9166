#pragma once
// Graph colouring of constraints, after Box3D's and Box2D v3's constraint graph
// (erincatto/box3d src/constraint_graph.c, b3AssignJointColor and b3AddContactToGraph): the
// constraints of one colour share no moving body, so a sweep may update them in any order, or at
// once on several threads, with the same result. A constraint between two moving bodies takes the
// first free colour of the first kDynamicColours; one with a single moving body (against a static
// body or the world) takes the last free colour from kOverflow - 1 down to 1, so that such
// constraints are swept after most others in a sweep that goes by colour index. One that finds no
// free colour goes to the overflow, swept before the colours, in order. Static bodies belong to no
// colour (they are never written). StaticColours::first instead gives a constraint with one moving
// body the first free colour of all but the overflow, so that such constraints are swept early,
// about where Gauss-Seidel in the rows' order sweeps them.

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "buffers.h"

namespace cps {

/// Where a constraint with a single moving body goes: Box3D's last free colour from kOverflow - 1
/// down to 1 (`last`), or the first free colour below the overflow (`first`).
enum class StaticColours { last, first };

/// The colours of one step's constraints. Bodies are indices into the step's bodies, or -1 for
/// a static body or the world.
class ConstraintGraph {
 public:
  /// Colours, the overflow included (count; Box3D's B3_GRAPH_COLOR_COUNT).
  static constexpr int kColours = 24;
  /// The overflow's index.
  static constexpr int kOverflow = kColours - 1;
  /// The colours open to a constraint between two moving bodies (Box3D's B3_DYNAMIC_COLOR_COUNT).
  static constexpr int kDynamicColours = kColours - 4;
  static_assert(kColours <= 32, "a body's colours are the bits of a 32-bit mask");

  /// Starts a new colouring for `bodies` bodies (count), constraints with one moving body placed
  /// by `statics`. No errors; allocates only to grow.
  void reset(std::size_t bodies, StaticColours statics) {
    used_.assign(bodies, 0u);
    statics_ = statics;
  }

  /// The colour of a constraint between a and b (indices below the count given to reset, or -1
  /// for a static body or the world), in [0, kOverflow], marked used for its moving bodies. A
  /// constraint with no moving body gets the overflow.
  int add(int a, int b) {
    if (a < 0) std::swap(a, b);
    if (a < 0) return kOverflow;
    std::uint32_t& used_a = used_[static_cast<std::size_t>(a)];
    if (b >= 0) {
      std::uint32_t& used_b = used_[static_cast<std::size_t>(b)];
      const int colour = std::countr_one(used_a | used_b);
      if (colour >= kDynamicColours) return kOverflow;
      used_a |= 1u << colour;
      used_b |= 1u << colour;
      return colour;
    }
    if (statics_ == StaticColours::first) {
      const int colour = std::countr_one(used_a);
      if (colour >= kOverflow) return kOverflow;
      used_a |= 1u << colour;
      return colour;
    }
    // The highest free colour below the overflow, down to 1: the top set bit of the free ones.
    const std::uint32_t free = ~used_a & (((1u << kOverflow) - 1u) & ~1u);
    if (free == 0u) return kOverflow;
    const int colour = 31 - std::countl_zero(free);
    used_a |= 1u << colour;
    return colour;
  }

 private:
  std::vector<std::uint32_t> used_;  // per body: the colours it is in (bit k: colour k)
  StaticColours statics_ = StaticColours::last;
};

/// The first item of each colour in an order by colour: colour c's items are
/// order[start[c], start[c + 1]).
using ColourStarts = std::array<std::size_t, ConstraintGraph::kColours + 1>;

/// A counting sort of item indices by colour (colours: one per item, each in [0, kOverflow]):
/// order lists them colour by colour, each colour's in index order, and colour c's are
/// order[start[c], start[c + 1]). No errors; allocates only to grow.
inline void order_by_colour(const std::vector<int>& colours, ColourStarts& start,
                            std::vector<std::size_t>& order) {
  start.fill(0);
  for (const int c : colours) ++start[static_cast<std::size_t>(c) + 1];
  for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
  detail::resize_with_headroom(order, colours.size());
  ColourStarts next = start;
  for (std::size_t i = 0; i < colours.size(); ++i) order[next[static_cast<std::size_t>(colours[i])]++] = i;
}

/// The colour swept k-th (k in [0, kColours)): the overflow first, then colours 0 to
/// kOverflow - 1 (Box3D's order, b3SolverStep).
constexpr int sweep_colour(int k) { return k == 0 ? ConstraintGraph::kOverflow : k - 1; }

}  // namespace cps
