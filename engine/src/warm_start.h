#pragma once
// Warm starting (paper Sec. 6.2.3: "the initial guess for lambda can be 0, but the value from the
// previous frame can be used by caching the constraint information"). Internal to the engine:
// World keeps one cache, fills it after its solves and reads it when it builds the next step's
// rows. A contact persists when the next step finds a contact with the same body pair and the
// same feature id (collision.h, ContactFeatureKind; the idea of Box2D's b2ContactFeature and of
// Catto, "Iterative Dynamics with Temporal Coherence", GDC 2005); a rod persists always (it is
// kept by index).

#include "cps/collision.h"
#include "cps/constraint.h"
#include "cps/parameters.h"
#include "buffers.h"
#include "workers.h"

#include <cstdint>
#include <vector>

namespace cps {

/// How a cached lambda becomes a row's initial guess.
enum class WarmStartRule {
  /// The smaller of the last two lambdas, friction within its row's limits (the class comment).
  sustained,
  /// Box3D's warm start (b3UpdateContact, b3PrepareContacts, b3StoreImpulses), which the soft
  /// step runs: each point's normal lambda of the last step as it is, found by its feature id,
  /// and the friction force (a vector) and twist of the last step's manifold of the same body
  /// pair, kept with the pair whichever points it has. The method reads them itself
  /// (last_normal(), last_friction(), last_rod()) and stores them (begin_store()); it calls
  /// neither initial_guesses() nor store().
  manifold,
};

/// The contacts and rods of the last step with their lambdas, and this step's matches to them.
///
/// The guess is the factor times the smaller of a row's lambdas of the last two steps (for a rod,
/// the one of smaller magnitude if both have the same sign, else 0), not of the last step alone:
/// a lambda that has just jumped is an impulse (an impact, a landing), not a force that lasts,
/// and starting the next step from it pushes the bodies apart harder than they need; with a fixed
/// number of sweeps PGS does not take all of it back, and the step gains energy (Catto,
/// erincatto/solver2d issue 8: "errors in warm starting energy can grow unbounded"). So a contact
/// starts from a cached value in its third step, once it has two. Measured per step against the energy bound of
/// tests/physics/test_stress.cpp (the largest dE - dW - dR over the run, tolerance in brackets), factor
/// 0.8, last lambda only / smaller of the last two: stack landing 0.080 / 0.011 J (0.0106 J),
/// stack_dt_0.1 1.75 / -0.039 J (0.013 J), mass_ratio_10 0.0087 / -0.0028 J (0.0036 J).
/// The step's rows must be laid out as World::build_rows lays them out: one contact row per
/// point of the manifolds (manifolds in order, points in order), then, when friction rows are
/// built, two friction rows per point in the same order, then one row per rod. Every buffer
/// keeps its storage, so after warm-up nothing is allocated.
class WarmStartCache {
 public:
  /// Matches the points of this step's manifolds (in pair order, as the collide stage lists
  /// them) to the cached ones: same body pair and same feature id, each cached point used at
  /// most once. For each point it also picks the friction direction t1 (unit, perpendicular to
  /// the point's normal): for a matched point the cached t1 projected onto the new contact plane
  /// and normalised, so that the friction lambdas carry over (if the normal turned so far that
  /// the projection is shorter than 1/2, tangent_basis instead); for a new point tangent_basis's
  /// t1 (the paper's choice, Sec. 5.4). Shared among `workers`' threads (nullptr: the calling
  /// thread; the same result for every count), as initial_guesses() and store() are.
  /// counted: per manifold, the points of the manifolds before it, as the collide stage counted
  /// them (StepContext::first_points); null or of another size: counted here. So for store()
  /// and begin_store().
  void match(const std::vector<Manifold>& manifolds, Workers* workers = nullptr,
             const std::vector<std::size_t>* counted = nullptr);

  /// The t1 picked by match() for the points of one manifold, m.count of them, for
  /// append_friction_rows; first_point: the number of points in the manifolds before it. Valid
  /// until the next match().
  const Vec3* tangents(std::size_t first_point) const { return tangents_.data() + first_point; }

  /// The initial guesses (N) of this step's rows (c = rows.size(), laid out as the class says,
  /// `rods` rod rows at the end): `factor` (dimensionless, [0, 1]) times the smaller of the last
  /// two cached lambdas of a matched point's contact row, its friction rows' cached force scaled
  /// alike and re-expressed along this step's t1, t2, and each rod's (class comment); 0 for new
  /// rows. Each guess lies within its
  /// row's limits: a contact's in [0, inf), a friction row's in [c_min, c_max] (fixed model) or
  /// within +-mu times its contact row's guess (coupled model). `first` is for the solve with the
  /// push (Sec. 7), `second` for the solve without it (Sec. 8.1), each from the cached lambda of
  /// the same solve; `second` is left empty when the cache holds no second solve.
  void initial_guesses(const std::vector<Manifold>& manifolds,
                       const std::vector<ConstraintRow>& rows, std::size_t rods, double factor,
                       FrictionModel friction, std::vector<double>& first,
                       std::vector<double>& second,
                       Workers* workers = nullptr) const;

  /// Replaces the cache by this step's points (features, t1, t2) and lambdas: `first` (c, N)
  /// from the solve with the push, `second` (c, N, or empty) from the solve without it (Sec.
  /// 8.1). The rows are laid out as the class says with `rods` rod rows at the end; after this
  /// step's match(), its friction rows along tangents() (World::build_rows).
  void store(const std::vector<Manifold>& manifolds, const std::vector<ConstraintRow>& rows,
             std::size_t rods, const std::vector<double>& first,
             const std::vector<double>& second, Workers* workers = nullptr,
             const std::vector<std::size_t>* counted = nullptr);

  /// WarmStartRule::manifold, after match(): the contact row's lambda (N) of the cached point
  /// that this step's point k (its contact row) matched, 0 for a new point.
  double last_normal(std::size_t k) const {
    return k < match_.size() && match_[k] >= 0 ? points_[static_cast<std::size_t>(match_[k])].normal : 0.0;
  }
  /// WarmStartRule::manifold, after match(): the friction force (N, a world vector; its last
  /// contact plane's) and twist (N m about its last normal) of the cached manifold with the body
  /// pair of this step's manifold m, 0 for a new pair. Where a step was stored by store(), both
  /// are 0.
  void last_friction(std::size_t m, Vec3& friction, double& twist) const {
    const int j = m < pair_match_.size() ? pair_match_[m] : -1;
    friction = j >= 0 ? manifolds_[static_cast<std::size_t>(j)].friction : Vec3::Zero();
    twist = j >= 0 ? manifolds_[static_cast<std::size_t>(j)].twist : 0.0;
  }
  /// Rod r's lambda (N) of the last step, 0 for a new rod.
  double last_rod(std::size_t r) const { return r < rods_first_.size() ? rods_first_[r] : 0.0; }

  /// WarmStartRule::manifold: replaces the cache by this step's manifolds (after this step's
  /// match()) in three calls: begin_store(), then store_manifold() once for each manifold (from
  /// any thread, each manifold its own), then end_store(). The cached points keep match()'s
  /// t1 (tangents()) and only their contact row's lambda; the sustained rule of another method
  /// finds no friction and, lacking an older lambda, starts the contacts from 0.
  void begin_store(const std::vector<Manifold>& manifolds,
                   const std::vector<std::size_t>* counted = nullptr);
  /// Manifold m of the step (`manifold`, as given to begin_store()) with its points' contact
  /// lambdas normal[0, manifold.count) (N), its friction force (N, a world vector) and twist
  /// (N m about its normal). No errors.
  void store_manifold(std::size_t m, const Manifold& manifold, const double* normal, const Vec3& friction,
                      double twist);
  /// The rods' lambdas rods[0, count) (N, in the order of the world's rods); ends the store.
  void end_store(const double* rods, std::size_t count);

  /// Forgets everything: the next step starts every row from 0.
  void clear();

  /// Cached contact points (count), for tests.
  std::size_t cached_points() const { return points_.size(); }
  /// Points of the last match() that found their cached point (count), for tests.
  std::size_t matched_points() const { return matched_; }
  /// Whether this step's manifold m (after match()) has the same points as its pair's manifold
  /// of the last step: as many, each matched. No errors (false for m out of range).
  bool same_points(std::size_t m) const { return m < same_points_.size() && same_points_[m] != 0; }

 private:
  struct CachedManifold {
    int body_a;
    int body_b;
    int first;  // first point in points_
    int count;
    Vec3 friction;  // N: the manifold's friction force (WarmStartRule::manifold; else 0)
    double twist;   // N m: its twist about the normal (the same)
  };
  // A cached point in two parts: what match() and WarmStartRule::manifold read (40 bytes, which
  // every step streams through), and the rest, which only the sustained rule reads.
  struct CachedPoint {
    std::uint32_t feature;
    Vec3 t1;        // friction direction of its first friction row (unit)
    double normal;  // lambda (N) of its contact row, first solve
  };
  struct CachedRows {
    Vec3 t2;            // friction direction of its second friction row (unit)
    double first[2];    // lambda (N) of its t1 and t2 rows, first solve
    double second[3];   // lambda (N) of its contact, t1 and t2 rows, second solve (Sec. 8.1)
    double older[2];    // its contact row's lambda (N) one step earlier (first, second solve);
                        // 0 if it is new
  };
  detail::KeptBuffer<CachedManifold> manifolds_;
  detail::KeptBuffer<CachedPoint> points_;
  detail::KeptBuffer<CachedPoint> next_points_;  // store() builds here, then swaps with points_
  // Per cached point, its CachedRows when store() kept them (has_rows_); after a store by the
  // manifold rule (end_store()) they are not kept and read as 0 (has_second_ and has_friction_
  // are false then).
  detail::KeptBuffer<CachedRows> rows_;
  detail::KeptBuffer<CachedRows> next_rows_;
  bool has_rows_ = false;
  detail::KeptBuffer<double> rods_first_;
  detail::KeptBuffer<double> rods_second_;
  detail::KeptBuffer<double> rods_older_first_;   // the rods' lambdas one step earlier (N)
  detail::KeptBuffer<double> rods_older_second_;
  bool has_second_ = false;
  bool has_friction_ = false;
  // This step: per point, the cached point it matched (-1: none) and its t1.
  detail::KeptBuffer<int> match_;
  detail::KeptBuffer<int> pair_match_;  // per manifold: its pair's cached manifold, or -1
  detail::KeptBuffer<Vec3> tangents_;
  bool tangents_fresh_ = false;  // match() has run since the last store(): tangents_ are the step's
  detail::KeptBuffer<unsigned char> same_points_;  // per manifold: same_points()
  std::size_t matched_ = 0;
  // Per manifold of the step: the points of the manifolds before it (match() and store()).
  detail::KeptBuffer<std::size_t> first_point_;
};

}  // namespace cps
