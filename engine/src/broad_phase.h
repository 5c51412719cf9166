#pragma once
// The broad phase of collision detection (Sec. 4): which pairs of bodies may touch this step.
// Internal to the engine: World's collide stage calls it, the narrow phase then builds a manifold
// for each pair it lists.

#include "cps/body.h"
#include "workers.h"

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace cps {

/// Lists the candidate pairs of a step. Bodies get axis-aligned bounds grown by half the contact
/// margin; a pair is a candidate when its bounds overlap (closed intervals on x, y and z) and not
/// both bodies are static; a plane is a candidate with every movable body whose bounds come
/// within half the margin of it (the bounds' lowest point along its normal). Worlds of at most
/// 32 bodies test every pair of bounds; larger ones sort the bounds into a uniform grid of cubic
/// cells a little wider than the widest body (Ericson, "Real-Time Collision Detection", 2005,
/// Sec. 7.1) by a counting sort, so the cost grows with the bodies and the pairs, not with their
/// square. Bodies more than 8 times wider than the median stay out of the grid and are tested
/// against every body. The pairs come out in index order (a < b, sorted by a then b): the order
/// of testing every pair, so the manifolds and rows after it do not depend on how the pairs
/// were found. Its buffers keep their storage, so a step allocates nothing once they have
/// reached their working size.
class BroadPhase {
 public:
  /// Writes the candidate pairs into `pairs` (cleared first). bodies: n; rotations: n rotation
  /// matrices R of the bodies' orientations (3 x 3, body to world), read for boxes only;
  /// contact_margin (m, >= 0): the speculative contact distance. Bodies far out or with
  /// non-finite positions share the grid's edge cells (more candidates, never fewer). Throws
  /// std::length_error naming the count once more than max_pairs pairs have been listed (it
  /// stops there, so the storage stays bounded). workers: the step's threads, or nullptr: the
  /// threads list the pairs of their shares of the bodies, joined in order (the same pairs).
  void find_pairs(const std::vector<Body>& bodies, const std::vector<Mat3>& rotations,
                  double contact_margin, std::size_t max_pairs,
                  std::vector<std::pair<int, int>>& pairs, Workers* workers = nullptr);

 private:
  struct Bounds {
    Vec3 lo;  ///< m
    Vec3 hi;  ///< m
  };
  enum class BroadClass : unsigned char { plane, gridded, oversize };
  // A plane body in world space, {x : normal . x = offset}, as the narrow phase places it.
  struct Plane {
    Vec3 normal = Vec3::UnitY();  ///< unit
    double offset = 0.0;          ///< m
  };
  // A gridded body as the grid stores it, by bucket: what the pair test needs, side by side.
  struct GridEntry {
    int body;                          // index
    bool is_static;
    std::array<std::int32_t, 3> cell;  // grid cell of the lower corner
    Bounds bounds;
  };
  // The grid's cells: where the box of cells starts, its size, and how a cell maps to a bucket.
  // Bucket of a cell: x + row(y, z), so that the cells x - 1, x, x + 1 of a row are three
  // consecutive buckets (one range of the sorted bodies). A dense grid numbers the rows of the
  // box; a hashed one hashes (y, z) (Teschner et al. 2003), and a bucket may also hold other
  // cells, which the row test of the pair scan skips.
  struct GridShape {
    double inv_edge = 1.0;                    // 1 / cell edge (1/m)
    std::array<std::int32_t, 3> low{0, 0, 0};  // lowest cell of the gridded bodies
    std::uint64_t size_x = 0;                 // cells of the box along x and y (+ 2 margin)
    std::uint64_t size_y = 0;
    bool dense = false;
    std::uint64_t buckets = 0;                // a power of two >= 4
    std::uint64_t mask = 0;                   // buckets - 1
    std::int32_t cell_coordinate(double x) const;
    std::uint64_t key(std::int32_t x, std::int32_t y, std::int32_t z) const;
  };

  // Stage 1: bounds grown by half the contact margin and the class of every body; planes listed.
  void classify(const std::vector<Body>& bodies, const std::vector<Mat3>& rotations,
                double contact_margin);
  // Stage 2: the oversize bodies out of the grid, the cell edge, each gridded body's cell, the
  // shape of the grid and its buckets, and the counting sort of the gridded bodies by bucket.
  void build_grid(const std::vector<Body>& bodies);
  // Stage 3: the pairs (ia, b), b > ia, in order, of a gridded body, from the 27 cells around
  // its own, the oversize bodies and the planes. candidates: scratch of n + planes entries.
  void pairs_of_gridded(const std::vector<Body>& bodies, std::size_t ia,
                        std::vector<std::pair<int, int>>& pairs, std::vector<int>& candidates) const;
  // Whether the bounds of `body` (not a plane) come within the contact margin of the plane body
  // `plane`: false only when no point of the body can (a superset of the narrow phase's
  // contacts, with a relative slack of 1e-9 for round-off).
  bool reaches_plane(std::size_t body, std::size_t plane) const;
  // The pairs (ia, b), b > ia, in order, of a body kept out of the grid.
  void pairs_of_ungridded(const std::vector<Body>& bodies, std::size_t ia,
                          std::vector<std::pair<int, int>>& pairs) const;

  GridShape shape_;

  std::vector<Bounds> bounds_;                     // per body, grown by the contact margin (m)
  std::vector<BroadClass> broad_class_;            // per body
  std::vector<std::array<std::int32_t, 3>> cell_;  // per body: grid cell (gridded only)
  std::vector<std::uint32_t> bucket_of_;           // per body: its cell's bucket (gridded only)
  std::vector<int> bucket_start_;                  // buckets + 2: k is [start[k], start[k+1])
  std::vector<GridEntry> grid_;                    // gridded bodies by bucket, then index
  std::vector<double> widths_;                     // scratch: widths (m) for the median
  std::vector<int> planes_;                        // plane bodies, by index
  std::vector<Plane> plane_;                       // per body: its plane (planes only)
  double grow_ = 0.0;                              // m: half the contact margin
  std::vector<int> oversize_;                      // bodies too wide for the grid, by index
  std::vector<std::vector<int>> candidates_;       // per thread, scratch (n + planes): b > a near a
  std::vector<std::vector<std::pair<int, int>>> lists_;  // per thread past the first: its pairs
};

}  // namespace cps
