// The broad phase (Sec. 4): a uniform grid of cells, rebuilt every step (see broad_phase.h).
#include "broad_phase.h"

#include "buffers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cps {
namespace {

// Broad phase grid. Bodies wider than this many times the median width (dimensionless) are not
// put in the grid but tested against every body, so that one large body (a static slab, say)
// does not make every cell large. Typical: 8.
constexpr double kOversizeFactor = 8.0;
// Cell edge = widest gridded body times this (dimensionless, > 1): the margin keeps two
// overlapping bounds in neighbouring cells despite the rounding of lo / edge.
constexpr double kCellGrowth = 1.001;
// The grid numbers its cells densely when their box holds at most this many cells per gridded
// body (dimensionless; memory: 4 bytes a cell), else it hashes its rows. Typical: 16.
constexpr double kDenseCells = 16.0;
// Cell coordinates are clamped to +-2^30 (about 1e9 cells): far out, or not finite, bodies
// share the edge cells, which can only add candidates, never lose one.
constexpr double kMaxCell = 1073741824.0;
// Worlds with at most this many bodies that are not planes skip the grid and test every pair of
// bounds (count; typical 32): below it the n^2 / 2 tests cost less than building the grid
// (measured on the paper's scenes, 6 to 31 bodies).
constexpr std::size_t kAllPairsMax = 32;
// Fewest bodies whose pairs the threads share (count; typical 512): below it waking them costs
// about what listing the pairs does.
constexpr std::size_t kMinParallelPairs = 512;

// Closed intervals overlap on all three axes: no axis separates them (evaluated without
// branches: | not ||).
template <class B>
bool bounds_overlap(const B& a, const B& b) {
  return !((b.lo.x() > a.hi.x()) | (a.lo.x() > b.hi.x()) | (b.lo.y() > a.hi.y()) |
           (a.lo.y() > b.hi.y()) | (b.lo.z() > a.hi.z()) | (a.lo.z() > b.hi.z()));
}


// Throws once the pairs listed so far pass the limit (see find_pairs).
void check_pair_count(std::size_t count, std::size_t max_pairs, std::size_t bodies) {
  if (count <= max_pairs) return;
  throw std::length_error("the broad phase listed more than " + std::to_string(max_pairs) +
                          " candidate pairs (" + std::to_string(count) + " so far, among " +
                          std::to_string(bodies) +
                          " bodies): the bodies are too crowded for one step; spread them out");
}

}  // namespace

bool BroadPhase::reaches_plane(std::size_t body, std::size_t plane) const {
  const Plane& p = plane_[plane];
  const Bounds& b = bounds_[body];
  const Vec3 centre = 0.5 * (b.lo + b.hi);
  const Vec3 half = 0.5 * (b.hi - b.lo);
  const double centre_height = p.normal.dot(centre) - p.offset;
  const double reach = p.normal.cwiseAbs().dot(half);
  // Round-off of the bounds and of the narrow phase's vertices, relative to the coordinates.
  const double slack = 1e-9 * (1.0 + std::abs(centre_height) + std::abs(p.offset) + reach);
  // Not `>`: a NaN height keeps the pair, as the grid keeps bodies with non-finite positions.
  return !(centre_height - reach > grow_ + slack);
}

// Broad phase: axis-aligned bounds grown by the contact margin; a pair is a candidate when its
// bounds overlap (closed intervals on x, y and z) and not both bodies are static; a plane is a
// candidate with every movable body whose bounds come within half the margin of it. Bounds go into a uniform grid of cubic cells a little
// wider than the widest body (Ericson 2005, Sec. 7.1), put in order of their cell's bucket by a
// counting sort, so the cost grows with the body count and the pairs, not with their square or
// a sort. Two overlapping bounds have lower corners at most one cell apart, so each body looks
// in the 27 cells around its own (9 rows of 3) for bodies of higher index; the few candidates
// of one body are sorted, so the pairs come out in index order without a global sort. Bodies
// more than kOversizeFactor times wider than the median are kept out of the grid and tested
// against every body, so that one large body does not make every cell large.
void BroadPhase::find_pairs(const std::vector<Body>& bodies, const std::vector<Mat3>& rotations,
                            double contact_margin, std::size_t max_pairs,
                            std::vector<std::pair<int, int>>& pairs, Workers* workers) {
  const std::size_t n = bodies.size();
  pairs.clear();
  classify(bodies, rotations, contact_margin);
  if (widths_.size() <= kAllPairsMax) {
    // A small world: every body is tested against every other, as the oversize ones are.
    for (std::size_t i = 0; i < n; ++i) {
      if (broad_class_[i] != BroadClass::plane) broad_class_[i] = BroadClass::oversize;
    }
    for (std::size_t i = 0; i < n; ++i) pairs_of_ungridded(bodies, i, pairs);
    check_pair_count(pairs.size(), max_pairs, n);
    return;
  }
  build_grid(bodies);
  const auto threads = static_cast<std::size_t>(
      workers != nullptr && n >= kMinParallelPairs ? workers->count() : 1);
  if (candidates_.size() < threads) candidates_.resize(threads);
  if (lists_.size() < threads) lists_.resize(threads);
  for (std::size_t t = 0; t < threads; ++t) {
    detail::resize_with_headroom(candidates_[t], n + planes_.size());
  }
  // Each thread lists its share of the bodies in order (the first into `pairs`), and stops once
  // its list passes the limit (at most n pairs past it); the lists are joined in order.
  parallel_for(threads > 1 ? workers : nullptr, n, kMinParallelPairs, [&](int t, std::size_t begin, std::size_t end) {
    const auto k = static_cast<std::size_t>(t);
    std::vector<std::pair<int, int>>& out = k == 0 ? pairs : lists_[k];
    out.clear();
    for (std::size_t ia = begin; ia < end && out.size() <= max_pairs; ++ia) {
      if (broad_class_[ia] != BroadClass::gridded) {
        pairs_of_ungridded(bodies, ia, out);
      } else {
        pairs_of_gridded(bodies, ia, out, candidates_[k]);
      }
    }
  });
  std::size_t count = pairs.size();
  for (std::size_t t = 1; t < threads; ++t) count += lists_[t].size();
  check_pair_count(count, max_pairs, n);
  for (std::size_t t = 1; t < threads; ++t) pairs.insert(pairs.end(), lists_[t].begin(), lists_[t].end());
}

void BroadPhase::classify(const std::vector<Body>& bodies, const std::vector<Mat3>& rotations,
                          double contact_margin) {
  const std::size_t n = bodies.size();
  bounds_.resize(n);
  broad_class_.resize(n);
  cell_.resize(n);
  bucket_of_.resize(n);
  plane_.resize(n);
  planes_.clear();
  oversize_.clear();
  widths_.clear();
  detail::reserve_with_headroom(widths_, n);
  detail::reserve_with_headroom(planes_, n);
  detail::reserve_with_headroom(oversize_, n);
  const double grow = 0.5 * contact_margin;
  grow_ = grow;
  for (std::size_t i = 0; i < n; ++i) {
    const Body& b = bodies[i];
    Vec3 half = Vec3::Zero();
    switch (b.shape.kind) {
      case ShapeKind::plane: {
        broad_class_[i] = BroadClass::plane;
        planes_.push_back(static_cast<int>(i));
        Plane& p = plane_[i];  // as the narrow phase places it (collision.cpp)
        p.normal = rotations[i] * b.shape.normal;
        p.offset = b.shape.offset + p.normal.dot(b.x);
        continue;
      }
      case ShapeKind::box:
        half = rotations[i].cwiseAbs() * b.shape.half_extents;
        break;
      case ShapeKind::sphere:
        half = Vec3::Constant(b.shape.radius);
        break;
    }
    bounds_[i] = {b.x - half - Vec3::Constant(grow), b.x + half + Vec3::Constant(grow)};
    broad_class_[i] = BroadClass::gridded;
    const double width = (bounds_[i].hi - bounds_[i].lo).maxCoeff();
    widths_.push_back(std::isfinite(width) ? width : 0.0);
  }
}

std::int32_t BroadPhase::GridShape::cell_coordinate(double x) const {
  double q = std::floor(x * inv_edge);
  if (!(q >= -kMaxCell)) q = -kMaxCell;  // also NaN
  if (q > kMaxCell) q = kMaxCell;
  return static_cast<std::int32_t>(q);
}

inline std::uint64_t BroadPhase::GridShape::key(std::int32_t x, std::int32_t y,
                                                std::int32_t z) const {
  // x - low + 1, y - low + 1 and z - low + 1 are in [0, size) for the cells a body looks at.
  const auto rx = static_cast<std::uint64_t>(static_cast<std::int64_t>(x) - low[0] + 1);
  const auto ry = static_cast<std::uint64_t>(static_cast<std::int64_t>(y) - low[1] + 1);
  const auto rz = static_cast<std::uint64_t>(static_cast<std::int64_t>(z) - low[2] + 1);
  const std::uint64_t row =
      dense ? size_x * (ry + size_y * rz) : (ry * 19349663u) ^ (rz * 83492791u);
  return (rx + row) & mask;
}

namespace {

// The smallest power of two >= count, and >= 4 (the three buckets of a row range are distinct).
std::uint64_t power_of_two_from(std::uint64_t count) {
  std::uint64_t p = 4;
  while (p < count) p *= 2;
  return p;
}

}  // namespace

void BroadPhase::build_grid(const std::vector<Body>& bodies) {
  const std::size_t n = bodies.size();
  // Bodies much wider than the median go to the oversize list; the rest set the cell edge.
  double limit = kInfinity;
  if (!widths_.empty()) {
    const auto middle = widths_.begin() + static_cast<std::ptrdiff_t>(widths_.size() / 2);
    std::nth_element(widths_.begin(), middle, widths_.end());
    limit = kOversizeFactor * *middle;
  }
  double widest = 0.0;
  std::size_t gridded = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (broad_class_[i] != BroadClass::gridded) continue;
    const double width = (bounds_[i].hi - bounds_[i].lo).maxCoeff();
    if (width > limit) {
      broad_class_[i] = BroadClass::oversize;
      oversize_.push_back(static_cast<int>(i));
    } else {
      widest = std::max(widest, width);
      ++gridded;
    }
  }
  GridShape& g = shape_;
  const double edge = widest > 0.0 && std::isfinite(widest) ? kCellGrowth * widest : 1.0;
  g.inv_edge = 1.0 / edge;
  // Cells of the gridded bodies and the box of cells they span.
  std::array<std::int32_t, 3> high{0, 0, 0};
  g.low = {0, 0, 0};
  bool first = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (broad_class_[i] != BroadClass::gridded) continue;
    const Vec3& lo = bounds_[i].lo;
    cell_[i] = {g.cell_coordinate(lo.x()), g.cell_coordinate(lo.y()), g.cell_coordinate(lo.z())};
    for (int k = 0; k < 3; ++k) {
      g.low[k] = first ? cell_[i][k] : std::min(g.low[k], cell_[i][k]);
      high[k] = first ? cell_[i][k] : std::max(high[k], cell_[i][k]);
    }
    first = false;
  }
  // Dense when the box of cells is at most kDenseCells times the body count.
  g.size_x = static_cast<std::uint64_t>(high[0] - g.low[0]) + 3;
  g.size_y = static_cast<std::uint64_t>(high[1] - g.low[1]) + 3;
  const std::uint64_t size_z = static_cast<std::uint64_t>(high[2] - g.low[2]) + 3;
  const double box_cells = static_cast<double>(g.size_x) * static_cast<double>(g.size_y) *
                           static_cast<double>(size_z);
  g.dense = box_cells <= kDenseCells * static_cast<double>(gridded);
  g.buckets = power_of_two_from(g.dense ? static_cast<std::uint64_t>(box_cells) : 2 * gridded);
  g.mask = g.buckets - 1;
  // Room for the most buckets this body count can ask for, so that bodies spreading out (a
  // larger box of cells) do not make a step allocate.
  detail::reserve_with_headroom(
      bucket_start_, static_cast<std::size_t>(power_of_two_from(
                         static_cast<std::uint64_t>(kDenseCells) * gridded)) + 2);
  // Counting sort of the gridded bodies by bucket (index order within a bucket).
  detail::assign_with_headroom(bucket_start_, static_cast<std::size_t>(g.buckets) + 2, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (broad_class_[i] != BroadClass::gridded) continue;
    bucket_of_[i] = static_cast<std::uint32_t>(g.key(cell_[i][0], cell_[i][1], cell_[i][2]));
    ++bucket_start_[bucket_of_[i] + 2];
  }
  for (std::size_t k = 2; k < bucket_start_.size(); ++k) bucket_start_[k] += bucket_start_[k - 1];
  detail::resize_with_headroom(grid_, gridded);
  for (std::size_t i = 0; i < n; ++i) {
    if (broad_class_[i] != BroadClass::gridded) continue;
    grid_[static_cast<std::size_t>(bucket_start_[bucket_of_[i] + 1]++)] = {
        static_cast<int>(i), bodies[i].is_static(), cell_[i], bounds_[i]};
  }
}

void BroadPhase::pairs_of_gridded(const std::vector<Body>& bodies, std::size_t ia,
                                  std::vector<std::pair<int, int>>& pairs,
                                  std::vector<int>& candidates) const {
  const GridShape& g = shape_;
  const int a = static_cast<int>(ia);
  const bool a_static = bodies[ia].is_static();
  // Bodies of higher index in the 27 cells around a's: per neighbour row one range of
  // buckets. The test is without branches; a hit is kept by advancing the count.
  std::size_t count = 0;
  const Bounds& ba = bounds_[ia];
  const std::array<std::int32_t, 3> c = cell_[ia];
  const auto scan = [&](int begin, int end, std::int32_t y, std::int32_t z) {
    for (int k = begin; k < end; ++k) {
      const GridEntry& e = grid_[static_cast<std::size_t>(k)];
      // The row test keeps a body that shares its bucket with another row from being taken
      // twice; cells of this row beyond x +- 1 can only be there by wrapping (hashed rows)
      // and fail the bounds test.
      const bool hit = (e.body > a) & (e.cell[1] == y) & (e.cell[2] == z) &
                       !(a_static & e.is_static) & bounds_overlap(ba, e.bounds);
      candidates[count] = e.body;
      count += hit ? 1 : 0;
    }
  };
  for (std::int32_t y = c[1] - 1; y <= c[1] + 1; ++y) {
    for (std::int32_t z = c[2] - 1; z <= c[2] + 1; ++z) {
      const auto first_bucket = static_cast<std::size_t>(g.key(c[0] - 1, y, z));
      if (first_bucket + 3 <= g.buckets) {
        scan(bucket_start_[first_bucket], bucket_start_[first_bucket + 3], y, z);
      } else {  // the three buckets wrap around the end of the table
        for (std::int32_t x = c[0] - 1; x <= c[0] + 1; ++x) {
          const auto bucket = static_cast<std::size_t>(g.key(x, y, z));
          scan(bucket_start_[bucket], bucket_start_[bucket + 1], y, z);
        }
      }
    }
  }
  for (const int b : oversize_) {
    const auto ib = static_cast<std::size_t>(b);
    if (b > a && !(a_static && bodies[ib].is_static()) && bounds_overlap(ba, bounds_[ib])) {
      candidates[count++] = b;
    }
  }
  if (!a_static) {
    for (const int p : planes_) {
      if (p > a && reaches_plane(ia, static_cast<std::size_t>(p))) candidates[count++] = p;
    }
  }
  std::sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(count));
  for (std::size_t k = 0; k < count; ++k) pairs.emplace_back(a, candidates[k]);
}

// The pairs (ia, b), b > ia, in order, of a body kept out of the grid: a plane pairs with every
// movable body whose bounds reach it; an oversize body with every plane it reaches (when it is
// movable) and every body whose bounds overlap its own, not both static.
void BroadPhase::pairs_of_ungridded(const std::vector<Body>& bodies, std::size_t ia,
                                    std::vector<std::pair<int, int>>& pairs) const {
  const std::size_t n = bodies.size();
  const int a = static_cast<int>(ia);
  const bool a_static = bodies[ia].is_static();
  if (broad_class_[ia] == BroadClass::plane) {
    for (std::size_t ib = ia + 1; ib < n; ++ib) {
      if (broad_class_[ib] != BroadClass::plane && !bodies[ib].is_static() && reaches_plane(ib, ia)) {
        pairs.emplace_back(a, static_cast<int>(ib));
      }
    }
    return;
  }
  for (std::size_t ib = ia + 1; ib < n; ++ib) {
    if (broad_class_[ib] == BroadClass::plane) {
      if (!a_static && reaches_plane(ia, ib)) pairs.emplace_back(a, static_cast<int>(ib));
    } else if (!(a_static && bodies[ib].is_static()) && bounds_overlap(bounds_[ia], bounds_[ib])) {
      pairs.emplace_back(a, static_cast<int>(ib));
    }
  }
}


}  // namespace cps
