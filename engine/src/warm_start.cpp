// The warm start cache (see warm_start.h).
#include "warm_start.h"

#include "buffers.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace cps {
namespace {

// Pair order of the manifolds (a, then b), as the collide stage lists them.
bool pair_less(int a1, int b1, int a2, int b2) { return a1 < a2 || (a1 == a2 && b1 < b2); }

// The number of points in all manifolds.
std::size_t point_count(const std::vector<Manifold>& manifolds) {
  std::size_t n = 0;
  for (const Manifold& m : manifolds) n += static_cast<std::size_t>(m.count);
  return n;
}

// Fewest manifolds a pass over them shares among threads (count): below it waking them
// (microseconds, tens on a virtual machine) costs about what the work does.
constexpr std::size_t kMinParallel = 256;

// Per manifold, the points of the manifolds before it, into first (no allocation once grown);
// returns the number of points in all manifolds.
std::size_t first_points(const std::vector<Manifold>& manifolds, std::vector<std::size_t>& first) {
  detail::resize_with_headroom(first, manifolds.size());
  std::size_t n = 0;
  for (std::size_t k = 0; k < manifolds.size(); ++k) {
    first[k] = n;
    n += static_cast<std::size_t>(manifolds[k].count);
  }
  return n;
}

// first_points(manifolds, first), copied from the collide stage's count `given` where that has
// one entry per manifold (no pass over the manifolds).
std::size_t first_points(const std::vector<Manifold>& manifolds, const std::vector<std::size_t>* given,
                         std::vector<std::size_t>& first) {
  if (given == nullptr || given->size() != manifolds.size()) return first_points(manifolds, first);
  detail::reserve_with_headroom(first, given->size());
  first.assign(given->begin(), given->end());
  return manifolds.empty() ? 0 : first.back() + static_cast<std::size_t>(manifolds.back().count);
}

// Whether the rows hold two friction rows per point (rows = points + 2 points + rods).
bool rows_have_friction(std::size_t points, std::size_t rows, std::size_t rods) {
  return points > 0 && rows == 3 * points + rods;
}

}  // namespace

void WarmStartCache::match(const std::vector<Manifold>& manifolds, Workers* workers,
                           const std::vector<std::size_t>* counted) {
  // Every entry is written below, by its manifold.
  const std::size_t points = first_points(manifolds, counted, first_point_);
  detail::resize_with_headroom(match_, points);
  detail::resize_with_headroom(tangents_, points);
  detail::resize_with_headroom(same_points_, manifolds.size());
  detail::resize_with_headroom(pair_match_, manifolds.size());
  std::atomic<std::size_t> matched_points{0};
  parallel_blocks(workers, manifolds.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
    if (begin == end) return;
    std::size_t matched = 0;
    // Both lists are in pair order: walk the cached one along (a missing or extra pair, or any
    // other order, only means fewer matches), a later share from the first cached manifold not
    // below its first pair.
    const auto below = [](const CachedManifold& c, const Manifold& m) {
      return pair_less(c.body_a, c.body_b, m.body_a, m.body_b);
    };
    std::size_t j = begin == 0 ? 0
                               : static_cast<std::size_t>(
                                     std::lower_bound(manifolds_.begin(), manifolds_.end(),
                                                      manifolds[begin], below) -
                                     manifolds_.begin());
    for (std::size_t index = begin; index < end; ++index) {
      const Manifold& m = manifolds[index];
      std::size_t k = first_point_[index];  // this step's point
      while (j < manifolds_.size() &&
             pair_less(manifolds_[j].body_a, manifolds_[j].body_b, m.body_a, m.body_b)) {
        ++j;
      }
      const bool same_pair = j < manifolds_.size() && manifolds_[j].body_a == m.body_a &&
                             manifolds_[j].body_b == m.body_b;
      pair_match_[index] = same_pair ? static_cast<int>(j) : -1;
      unsigned used = 0;  // cached points of this pair already matched (at most 8: one bit each)
      int matched_here = 0;
      for (int i = 0; i < m.count; ++i, ++k) {
        const Contact& c = m.contacts[static_cast<std::size_t>(i)];
        bool kept = false;  // t1 the cached one's
        Vec3 t1;
        match_[k] = -1;
        if (same_pair) {
          const CachedManifold& cm = manifolds_[j];
          for (int q = 0; q < cm.count; ++q) {
            const CachedPoint& p = points_[static_cast<std::size_t>(cm.first + q)];
            if ((used >> q) & 1u || p.feature != c.feature) continue;
            used |= 1u << q;
            match_[k] = cm.first + q;
            ++matched;
            ++matched_here;
            // The cached t1 in the new contact plane: the friction rows keep their directions.
            const Vec3 projected = p.t1 - p.t1.dot(c.normal) * c.normal;
            if (projected.norm() > 0.5) {
              t1 = projected.normalized();
              kept = true;
            }
            break;
          }
        }
        if (!kept) {
          Vec3 t2;
          tangent_basis(c.normal, t1, t2);  // the paper's directions for a new point
        }
        tangents_[k] = t1;
      }
      same_points_[index] = same_pair && matched_here == m.count && manifolds_[j].count == m.count;
    }
    matched_points.fetch_add(matched, std::memory_order_relaxed);
  });
  matched_ = matched_points.load(std::memory_order_relaxed);
  tangents_fresh_ = true;
}

void WarmStartCache::initial_guesses(const std::vector<Manifold>& manifolds,
                                     const std::vector<ConstraintRow>& rows, std::size_t rods,
                                     double factor, FrictionModel friction,
                                     std::vector<double>& first,
                                     std::vector<double>& second, Workers* workers) const {
  const std::size_t c = rows.size();
  // Each manifold writes only its own rows: a share starts at its first manifold's first point
  // (match()'s first_point_; without a match() of these manifolds, one share from point 0).
  const bool matched = first_point_.size() == manifolds.size();
  const std::size_t points =
      matched && !manifolds.empty()
          ? first_point_.back() + static_cast<std::size_t>(manifolds.back().count)
          : point_count(manifolds);
  const bool friction_rows = rows_have_friction(points, c, rods);
  const bool coupled = friction == FrictionModel::coupled;
  // Laid out as the class says, every row is written below (0 for a new one); else the rows
  // past the layout stay 0.
  const bool laid_out = c == (friction_rows ? 3 * points : points) + rods;
  const auto make_room = [&](std::vector<double>& out) {
    if (laid_out) {
      detail::resize_with_headroom(out, c);
    } else {
      detail::assign_with_headroom(out, c, 0.0);
    }
  };
  make_room(first);
  if (has_second_) {
    make_room(second);
  } else {
    second.clear();
  }
  for (int solve = 0; solve < (has_second_ ? 2 : 1); ++solve) {
    std::vector<double>& out = solve == 0 ? first : second;
    parallel_for(matched ? workers : nullptr, manifolds.size(), kMinParallel,
                 [&](int, std::size_t begin, std::size_t end) {
      std::size_t k = matched && begin < end ? first_point_[begin] : 0;
      for (std::size_t index = begin; index < end; ++index) {
        const Manifold& m = manifolds[index];
        for (int i = 0; i < m.count; ++i, ++k) {
          if (k >= match_.size() || match_[k] < 0) {  // a new point: 0
            out[k] = 0.0;
            if (friction_rows) out[points + 2 * k] = out[points + 2 * k + 1] = 0.0;
            continue;
          }
          const auto cached_index = static_cast<std::size_t>(match_[k]);
          const CachedPoint& p = points_[cached_index];
          const CachedRows* more = has_rows_ ? &rows_[cached_index] : nullptr;
          // Its contact row's last lambda and the one before (0 where not kept).
          const double last = solve == 0 ? p.normal : (more != nullptr ? more->second[0] : 0.0);
          const double older = more != nullptr ? more->older[solve] : 0.0;
          // Contact row k: the smaller of its last two lambdas (see the class comment).
          const double sustained = std::max(0.0, std::min(last, older));
          out[k] = factor * sustained;
          if (!friction_rows) continue;
          if (!has_friction_ || more == nullptr) {
            out[points + 2 * k] = out[points + 2 * k + 1] = 0.0;
            continue;
          }
          // The cached friction force, scaled as the contact's, along this step's directions (t1
          // is the cached t1 in the new plane, so this is close to a copy), within the row's limits.
          const double* tangential = solve == 0 ? more->first : more->second + 1;
          const double scale = last > 0.0 ? sustained / last : 0.0;
          const Vec3 force = scale * (tangential[0] * p.t1 + tangential[1] * more->t2);
          const Vec3& t1 = tangents_[k];
          const Vec3 t2 = m.contacts[static_cast<std::size_t>(i)].normal.cross(t1);
          for (int r = 0; r < 2; ++r) {
            const std::size_t row = points + 2 * k + static_cast<std::size_t>(r);
            double lo = rows[row].c_min;
            double hi = rows[row].c_max;
            if (coupled) {
              hi = rows[row].mu * out[k];
              lo = -hi;
            }
            out[row] = std::clamp(factor * force.dot(r == 0 ? t1 : t2), lo, hi);
          }
        }
      }
    });
    // Rods: kept by index, always the same rows at the end; the smaller of the last two lambdas
    // when they have the same sign, else 0.
    const std::vector<double>& cached_rods = solve == 0 ? rods_first_ : rods_second_;
    const std::vector<double>& older_rods = solve == 0 ? rods_older_first_ : rods_older_second_;
    for (std::size_t r = 0; r < rods; ++r) {
      if (r >= cached_rods.size()) {  // a new rod
        out[c - rods + r] = 0.0;
        continue;
      }
      const double a = cached_rods[r];
      const double b = older_rods[r];
      out[c - rods + r] = (a > 0.0) == (b > 0.0) ? factor * (std::abs(a) < std::abs(b) ? a : b) : 0.0;
    }
  }
}

void WarmStartCache::store(const std::vector<Manifold>& manifolds,
                           const std::vector<ConstraintRow>& rows, std::size_t rods,
                           const std::vector<double>& first, const std::vector<double>& second,
                           Workers* workers, const std::vector<std::size_t>* counted) {
  const std::size_t c = rows.size();
  const std::size_t points = first_points(manifolds, counted, first_point_);
  has_friction_ = rows_have_friction(points, c, rods);
  has_second_ = !second.empty();
  // The friction rows' directions: match()'s t1 and n x t1 when this step's match() chose them
  // (the same vectors, without reading the rows back), else the rows' own.
  const bool own_tangents = tangents_fresh_ && tangents_.size() >= points;
  detail::resize_with_headroom(manifolds_, manifolds.size());
  detail::resize_with_headroom(next_points_, points);
  detail::resize_with_headroom(next_rows_, points);
  // Each manifold writes only its own entry and points.
  parallel_blocks(workers, manifolds.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
    for (std::size_t index = begin; index < end; ++index) {
      const Manifold& m = manifolds[index];
      std::size_t k = first_point_[index];
      manifolds_[index] = {m.body_a, m.body_b, static_cast<int>(k), m.count, Vec3::Zero(), 0.0};
      for (int i = 0; i < m.count; ++i, ++k) {
        CachedPoint& p = next_points_[k];
        CachedRows& more = next_rows_[k];
        const bool matched = k < match_.size() && match_[k] >= 0;
        const auto before = matched ? static_cast<std::size_t>(match_[k]) : 0;
        more.older[0] = matched ? points_[before].normal : 0.0;
        more.older[1] = matched && has_rows_ ? rows_[before].second[0] : 0.0;
        const Contact& contact = m.contacts[static_cast<std::size_t>(i)];
        p.feature = contact.feature;
        p.normal = k < first.size() ? first[k] : 0.0;
        more.first[0] = has_friction_ ? first[points + 2 * k] : 0.0;
        more.first[1] = has_friction_ ? first[points + 2 * k + 1] : 0.0;
        more.second[0] = has_second_ && k < second.size() ? second[k] : 0.0;
        more.second[1] = has_second_ && has_friction_ ? second[points + 2 * k] : 0.0;
        more.second[2] = has_second_ && has_friction_ ? second[points + 2 * k + 1] : 0.0;
        if (has_friction_ && own_tangents) {
          p.t1 = tangents_[k];
          more.t2 = contact.normal.cross(p.t1);
        } else if (has_friction_) {
          // The directions of its friction rows: the linear part of body b's half of j is t.
          p.t1 = rows[points + 2 * k].j.segment<3>(6);
          more.t2 = rows[points + 2 * k + 1].j.segment<3>(6);
        } else {
          tangent_basis(contact.normal, p.t1, more.t2);
        }
      }
    }
  });
  points_.swap(next_points_);
  rows_.swap(next_rows_);
  has_rows_ = true;
  tangents_fresh_ = false;
  const std::size_t had_rods = rods_first_.size();
  rods_older_first_.swap(rods_first_);
  rods_older_second_.swap(rods_second_);
  detail::resize_with_headroom(rods_older_first_, rods);  // rods added since: 0
  detail::resize_with_headroom(rods_older_second_, rods);
  for (std::size_t r = had_rods; r < rods; ++r) rods_older_first_[r] = rods_older_second_[r] = 0.0;
  detail::resize_with_headroom(rods_first_, rods);
  detail::resize_with_headroom(rods_second_, rods);
  for (std::size_t r = 0; r < rods; ++r) {
    rods_first_[r] = first[c - rods + r];
    rods_second_[r] = has_second_ ? second[c - rods + r] : 0.0;
  }
}

void WarmStartCache::begin_store(const std::vector<Manifold>& manifolds,
                                 const std::vector<std::size_t>* counted) {
  const std::size_t points = first_points(manifolds, counted, first_point_);
  has_friction_ = false;
  has_second_ = false;
  detail::resize_with_headroom(manifolds_, manifolds.size());
  detail::resize_with_headroom(next_points_, points);
}

void WarmStartCache::store_manifold(std::size_t m, const Manifold& manifold, const double* normal,
                                    const Vec3& friction, double twist) {
  std::size_t k = first_point_[m];
  manifolds_[m] = {manifold.body_a, manifold.body_b, static_cast<int>(k), manifold.count, friction, twist};
  const bool own_tangents = tangents_fresh_ && k + static_cast<std::size_t>(manifold.count) <= tangents_.size();
  for (int i = 0; i < manifold.count; ++i, ++k) {
    const Contact& contact = manifold.contacts[static_cast<std::size_t>(i)];
    CachedPoint& p = next_points_[k];
    p.feature = contact.feature;
    if (own_tangents) {
      p.t1 = tangents_[k];
    } else {
      Vec3 t2;
      tangent_basis(contact.normal, p.t1, t2);
    }
    p.normal = normal[i];
  }
}

void WarmStartCache::end_store(const double* rods, std::size_t count) {
  points_.swap(next_points_);
  has_rows_ = false;  // the sustained rule's parts read as 0
  tangents_fresh_ = false;
  detail::resize_with_headroom(rods_first_, count);
  std::copy_n(rods, count, rods_first_.begin());
  detail::assign_with_headroom(rods_second_, count, 0.0);
  detail::assign_with_headroom(rods_older_first_, count, 0.0);
  detail::assign_with_headroom(rods_older_second_, count, 0.0);
}

void WarmStartCache::clear() {
  manifolds_.clear();
  points_.clear();
  rows_.clear();
  has_rows_ = false;
  rods_first_.clear();
  rods_second_.clear();
  rods_older_first_.clear();
  rods_older_second_.clear();
  has_second_ = false;
  has_friction_ = false;
  match_.clear();
  pair_match_.clear();
  tangents_fresh_ = false;
  same_points_.clear();
  matched_ = 0;
}

}  // namespace cps
