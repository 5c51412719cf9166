#pragma once
// Contact recycling (WorldDef::contact_recycle_distance), after Box3D (erincatto/box3d
// src/physics_world.c, b3CollideTask: "contact recycling optimization", and Box2D v3.2): while
// two bodies have barely moved relative to each other since their manifold was last made by the
// narrow phase, the collide stage keeps that manifold (its normal, feature ids and anchors: the
// world vectors from each body's centre to its points when it was made, which do not turn with
// the bodies) and only updates each point's depth, as the soft step's substeps do, instead of
// clipping again. The clipped points of resting boxes whose faces are exactly aligned
// otherwise change their feature ids from step to step (a vertex on a side plane is kept or clipped
// by round-off), and each change starts the point's warm start from 0.

#include "cps/body.h"
#include "cps/collision.h"

#include "buffers.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace cps {

/// The manifolds of the last step that may be recycled, in pair order, each with the bodies'
/// poses when the narrow phase made it.
class ContactRecycler {
 public:
  /// No entry of the last step (Cursor::found).
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  /// Where a run of ascending lookups stands in the last step's manifolds: `at`, the first entry
  /// not below the pair looked up last; `found`, the entry the last recycle() used, or kNone.
  /// Each thread of the collide stage keeps its own.
  struct Cursor {
    std::size_t at = 0;
    std::size_t found = kNone;
  };

  /// Starts a step's cache (keep()). No errors.
  void begin_step();

  /// A cursor for lookups that start at the pair (a, b), a < b. No errors.
  Cursor cursor_at(int a, int b) const;

  /// For the pair (a, b) of the collide stage (a < b, ascending over the lookups of `cursor`):
  /// when the last step had a manifold for it and the bodies have moved relative to its cached
  /// poses by less than `distance` (m, > 0) at every point within their bounding radius, and
  /// neither has turned by more than about 10 degrees, writes the recycled manifold into `out`
  /// (each body's anchors as cached: a point is a's anchor, b's lies out.anchor_shift from it;
  /// its depth changed by their relative motion along the cached normal), sets cursor.found and returns true; else returns
  /// false with cursor.found = kNone and `out` untouched. Reads only the last step's cache, so
  /// threads may look up at once. No errors.
  bool recycle(int a, int b, const std::vector<Body>& bodies, double distance, Manifold& out,
               Cursor& cursor) const;

  /// Caches the manifold `m` the narrow phase has made for its pair at the bodies' current poses
  /// (m.count > 0), or carries over the last step's entry `found` that recycle() used for it
  /// (kNone: none); call once per manifold of the step, in the collide stage's order. No errors.
  void keep(const Manifold& m, const std::vector<Body>& bodies, std::size_t found);

  /// Makes room for `count` manifolds of this step at once, each then cached by keep_at() (from
  /// any thread, each i once) in place of keep(). No errors.
  void resize_kept(std::size_t count);
  /// keep() for the step's manifold `at` (its place in the collide stage's order, < the count of
  /// resize_kept()). No errors.
  void keep_at(std::size_t at, const Manifold& m, const std::vector<Body>& bodies, std::size_t found);

  /// Ends the step: this step's cache replaces the last one. No errors.
  void end_step();

 private:
  struct CachedPoint {
    Vec3 r_a = Vec3::Zero();  // m: the point relative to a's centre, world frame, at caching
    Vec3 r_b = Vec3::Zero();  // m: relative to b's centre
    double depth = 0.0;       // m: at caching
    std::uint32_t feature = 0;
  };
  struct Cached {
    int a = -1;
    int b = -1;
    Vec3 normal = Vec3::UnitY();
    Vec3 x_a = Vec3::Zero();  // m: the centres at caching
    Vec3 x_b = Vec3::Zero();
    Quat o_a = Quat::Identity();  // the orientations at caching
    Quat o_b = Quat::Identity();
    int count = 0;
    std::array<CachedPoint, kMaxManifoldPoints> points{};
  };

  // Copies an entry's pair, poses, normal and its `count` points (the rest are never read), so
  // that a copy moves only what is used.
  static void copy_used(const Cached& from, Cached& to);

  detail::KeptBuffer<Cached> last_;  // the last step's, in pair order
  // This step's: its first next_count_ entries. The vector only grows (its entries are made once
  // and then written over), so a step builds no entries it already has storage for.
  detail::KeptBuffer<Cached> next_;
  std::size_t next_count_ = 0;
};

}  // namespace cps
