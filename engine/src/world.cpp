// The step as the paper's stages (see world.h): each stage a function, in the paper's order.
#include "cps/world.h"

#include "broad_phase.h"
#include "buffers.h"
#include "push/push_method.h"
#include "step_context.h"
#include "system.h"
#include "warm_start.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace cps {
namespace {

// World::steps_in_process.
std::atomic<std::int64_t> steps_begun{0};

// Fewest bodies or manifolds a stage of the step shares among threads (count): below it waking them
// (microseconds, tens on a virtual machine) costs about what the work does.
constexpr std::size_t kMinParallelRows = 256;

// Candidate pairs in a chunk of the narrow phase on several threads (count): small enough that
// the threads' loads even out, large enough that taking a chunk costs nothing against it.
constexpr std::size_t kPairsPerChunk = 256;

// Every component finite and within +-limit (isfinite first: no exception on NaN).
bool within(const Vec3& v, double limit) {
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(v[k]) || std::abs(v[k]) > limit) return false;
  }
  return true;
}

}  // namespace

World::World(const WorldDef& def)
    : def_(def),
      ctx_(std::make_unique<StepContext>()),
      broad_phase_(std::make_unique<BroadPhase>()) {
  def_.validate();
}

World::World(const World& other)
    : def_(other.def_),
      bodies_(other.bodies_),
      distances_(other.distances_),
      apart_(other.apart_),
      ctx_(std::make_unique<StepContext>(other.settled_context())),
      broad_phase_(std::make_unique<BroadPhase>()),
      body_friction_(other.body_friction_),
      body_restitution_(other.body_restitution_) {}

World& World::operator=(const World& other) {
  if (this != &other) *this = World(other);
  return *this;
}

World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;
World::~World() = default;

const StepCounters& World::counters() const { return ctx_->counters; }
const ResidualStats& World::residual() const { return ctx_->residual; }
const StageTimes& World::stage_times() const { return ctx_->stage_times; }

void World::set_stage_timing(bool on) {
  if (on && !ctx_->time_stages) ctx_->stage_times = StageTimes{};
  ctx_->time_stages = on;
}
const std::vector<Manifold>& World::manifolds() const { return ctx_->manifolds; }
double World::deepest_contact() const { return ctx_->deepest_contact; }
const std::vector<ConstraintRow>& World::rows() const { return settled_context().rows; }

const StepContext& World::settled_context() const {
  StepContext::DeferredRows& deferred = ctx_->deferred_rows;
  if (deferred.pending) {
    // The bodies as they were when the step built its rows (only their positions have moved).
    deferred.bodies = bodies_;
    for (std::size_t i = 0; i < deferred.x.size(); ++i) deferred.bodies[i].x = deferred.x[i];
    write_contact_rows(deferred.bodies, deferred.params, deferred.warm, nullptr);
    deferred.pending = false;
  }
  if (ctx_->lambda_pending) {
    push_->write_lambda(*ctx_);
    ctx_->lambda_pending = false;
  }
  return *ctx_;
}
const std::vector<double>& World::lambda() const { return settled_context().lambda; }
const std::vector<double>& World::lambda_second() const { return ctx_->lambda_second; }

void World::set_def(const WorldDef& def) {
  def.validate();
  def_ = def;
}

int World::add_body(const BodyDef& def) {
  bodies_.push_back(make_body(def));  // make_body throws before anything is added
  body_friction_ = body_friction_ || !std::isnan(def.friction);
  body_restitution_ = body_restitution_ || (!std::isnan(def.restitution) && def.restitution > 0.0);
  return static_cast<int>(bodies_.size()) - 1;
}

void World::set_body_state(int i, const Vec3& x, const Quat& o, const Vec3& v, const Vec3& w) {
  if (i < 0 || i >= static_cast<int>(bodies_.size())) {
    throw std::invalid_argument("body " + std::to_string(i) + " does not exist (there are " +
                                std::to_string(bodies_.size()) + " bodies)");
  }
  const Body& old = bodies_[static_cast<std::size_t>(i)];
  BodyDef def;
  def.shape = old.shape;
  def.is_static = old.is_static();
  if (!def.is_static) def.mass = old.mass;
  def.position = x;
  def.orientation = o;
  def.velocity = v;
  def.angular_velocity = w;
  def.restitution = old.restitution;
  def.friction = old.friction;
  bodies_[static_cast<std::size_t>(i)] = make_body(def);  // throws before anything changes
}

int World::add_distance(const DistanceConstraint& d) {
  const int n = static_cast<int>(bodies_.size());
  std::ostringstream why;
  if (d.body_a < 0 || d.body_a >= n) {
    why << "body_a " << d.body_a << " does not exist (there are " << n << " bodies)";
  } else if (bodies_[static_cast<std::size_t>(d.body_a)].is_static()) {
    why << "body_a " << d.body_a << " is static; it must be movable";
  } else if (d.body_b != kWorldBody && (d.body_b < 0 || d.body_b >= n)) {
    why << "body_b " << d.body_b << " does not exist (there are " << n
        << " bodies; use kWorldBody for a fixed point)";
  } else if (d.body_b == d.body_a) {
    why << "body_a and body_b are both " << d.body_a;
  } else if (!within(d.local_a, kMaxCoordinate) || !within(d.local_b, kMaxCoordinate)) {
    why << "the end points must be finite and within +-" << kMaxCoordinate << " m";
  } else if (!(std::isfinite(d.length) && d.length >= 0.0 && d.length <= kMaxCoordinate)) {
    why << "length " << d.length << " m must be in [0, " << kMaxCoordinate << "] m";
  }
  if (!why.str().empty()) throw std::invalid_argument("distance constraint: " + why.str());
  distances_.push_back(d);
  if (!d.collide && d.body_b != kWorldBody) {
    const std::pair<int, int> pair = std::minmax(d.body_a, d.body_b);
    const auto at = std::lower_bound(apart_.begin(), apart_.end(), pair);
    if (at == apart_.end() || *at != pair) apart_.insert(at, pair);
  }
  return static_cast<int>(distances_.size()) - 1;
}

void World::set_solve_observer(SolveObserver observer, SolveFilter wants) {
  ctx_->observer = std::move(observer);
  ctx_->observe_filter = std::move(wants);
}

void World::set_solve_override(SolveOverride override) { ctx_->override_solve = std::move(override); }

std::size_t World::persisting_contacts() const {
  return ctx_->warm_start && def_.warm_start > 0.0 ? ctx_->warm_start->matched_points() : 0;
}

std::int64_t World::steps_in_process() { return steps_begun.load(std::memory_order_relaxed); }

void World::step() {
  steps_begun.fetch_add(1, std::memory_order_relaxed);
  StepContext& ctx = *ctx_;
  ctx.def = &def_;
  ctx.bodies = &bodies_;
  ctx.distances = &distances_;
  if (!push_ || push_mode_ != def_.push) {
    push_ = push_traits(def_.push).make();
    push_mode_ = def_.push;
  }
  ctx.solves_this_step = 0;
  if (ctx.lambda_pending) {  // the last step's, unwritten: this step writes its own
    ctx.lambda_pending = false;
    ctx.lambda.clear();
  }
  ctx.update_workers();
  {
    StageTimer timer(ctx, &StageTimes::collide);
    external_forces();  // Sec. 6.1: f_ext
    try {
      collide();  // Sec. 4: manifolds
    } catch (...) {
      // The manifolds are no longer those of the rows left to write: the last step's rows go.
      if (ctx.deferred_rows.pending) {
        ctx.deferred_rows.pending = false;
        ctx.rows.clear();
        ctx.lambda.clear();
      }
      throw;
    }
  }
  {
    StageTimer timer(ctx, &StageTimes::rows);
    build_rows();  // Sec. 5: rows of J, targets, limits
  }
  if (push_traits(def_.push).solves_system) ctx.prepare();  // Sec. 6: A or the packed rows
  // The push method's time in the stages it times itself; the rest of it is `other`.
  StageTimes& times = ctx.stage_times;
  const double staged_before = times.total() - times.other;
  {
    StageTimer timer(ctx, &StageTimes::other);
    push_->step(ctx);  // Secs. 7, 8.1 and 3.2, as the push method does them (push/)
  }
  times.other -= times.total() - times.other - staged_before;
  ++ctx.counters.steps;
}

// Stage 0, Sec. 6.1: f_ext (6n) = [m g, 0] per movable body, into a buffer that keeps its size.
void World::external_forces() { gravity_forces(bodies_, def_.gravity, ctx_->f_ext); }

// Stage 1, Sec. 4: the broad phase lists the pairs that may touch, in index order, then the
// narrow phase builds their manifolds. The order is that of testing every pair (a, b), a < b,
// so manifolds and rows do not depend on how the candidates were found.
void World::collide() {
  std::vector<Manifold>& manifolds = ctx_->manifolds;
  Workers* workers = ctx_->workers();
  // On threads the manifolds keep their storage and count until the join resizes them (so that
  // only those past last step's count are made, not every one); any error clears them first.
  const auto clear = [this, &manifolds] {
    manifolds.clear();
    ctx_->first_points.clear();
    ctx_->contact_points = 0;
    ctx_->deepest_contact = 0.0;
  };
  if (workers == nullptr || !def_.collision) clear();
  if (!def_.collision) return;
  try {
    collide_pairs(workers);
  } catch (...) {
    clear();
    throw;
  }
}

namespace {
// Copies a manifold's pair, count, anchor shift and its `count` contacts (the slots past them are
// never read).
void copy_used_contacts(const Manifold& from, Manifold& to) {
  to.body_a = from.body_a;
  to.body_b = from.body_b;
  to.count = from.count;
  to.anchor_shift = from.anchor_shift;
  std::copy_n(from.contacts.begin(), from.count, to.contacts.begin());
}

// The largest depth of m's contacts and `deepest` (m; a NaN depth is passed over).
double deeper(const Manifold& m, double deepest) {
  for (int i = 0; i < m.count; ++i) deepest = std::max(deepest, m.contacts[static_cast<std::size_t>(i)].depth);
  return deepest;
}
}  // namespace

void World::collide_pairs(Workers* workers) {
  std::vector<Manifold>& manifolds = ctx_->manifolds;
  // Counted with the manifolds, where they are at hand: each one's first point, all points and
  // the deepest contact (the later stages and the world's readers take them from here).
  std::vector<std::size_t>& first_points = ctx_->first_points;
  first_points.clear();
  double deepest = 0.0;
  StepCounters& counters = ctx_->counters;
  // The rotation matrix of each box and plane, once: the broad phase's bounds and the narrow
  // phase both read it (spheres need none).
  rotations_.resize(bodies_.size());
  parallel_blocks(workers, bodies_.size(), kMinParallelRows, [this](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (bodies_[i].shape.kind != ShapeKind::sphere) rotations_[i] = bodies_[i].rotation();
    }
  });
  // The push method may widen the speculative distance per body (push_method.h): the broad phase
  // then grows every bound by the largest, so that it lists a superset of the pairs.
  const bool per_body = push_->contact_margins(def_, bodies_, margins_);
  double broad_margin = def_.contact_margin;
  if (per_body) {
    double widest = 0.0;
    for (const double m : margins_) widest = std::max(widest, m);
    broad_margin += 2.0 * widest;
  }
  broad_phase_->find_pairs(bodies_, rotations_, broad_margin, kMaxCandidatePairs, pairs_, workers);
  if (!apart_.empty()) {  // the pairs joined by a rod that does not collide (both lists sorted)
    std::erase_if(pairs_, [this](const std::pair<int, int>& pair) {
      return std::binary_search(apart_.begin(), apart_.end(), pair);
    });
  }
  // Room for the manifolds a world of this size usually has (a body touches a few others, and
  // the pairs come and go as bodies approach: at least two a body); a crowded step grows it as
  // it finds them, never to a worst case of one per pair.
  detail::reserve_with_headroom(manifolds, std::min(std::max(pairs_.size(), 2 * bodies_.size()), 8 * bodies_.size()));
  // Contact recycling: a pair that barely moved keeps last step's manifold (contact_recycling.h).
  const double recycle = def_.contact_recycle_distance;
  if (recycle > 0.0) {
    if (!ctx_->recycler) ctx_->recycler = std::make_unique<ContactRecycler>();
    ctx_->recycler->begin_step();
  } else {
    ctx_->recycler.reset();
  }
  ContactRecycler* recycler = ctx_->recycler.get();
  using Cursor = ContactRecycler::Cursor;
  // The narrow phase of one pair into m: true when the pair touches (its manifold recycled, or
  // made and reduced as the world asks). Reads only: threads may run it at once.
  const auto narrow = [&](std::pair<int, int> pair, Manifold& m, Cursor& cursor) {
    const auto [a, b] = pair;
    m.body_a = a;
    m.body_b = b;
    const auto ia = static_cast<std::size_t>(a);
    const auto ib = static_cast<std::size_t>(b);
    const double margin =
        per_body ? def_.contact_margin + margins_[ia] + margins_[ib] : def_.contact_margin;
    if (recycler != nullptr && recycler->recycle(a, b, bodies_, recycle, m, cursor)) return true;
    cursor.found = ContactRecycler::kNone;
    m.anchor_shift = Vec3::Zero();
    if (cps::collide(bodies_[ia], rotations_[ia], bodies_[ib], rotations_[ib], m, margin) == 0) return false;
    if (def_.manifold_points == ManifoldPoints::four) reduce_manifold(m, def_.contact_margin);
    return true;
  };
  std::size_t points = 0;
  const auto too_many_points = [this] {
    throw std::length_error("the narrow phase found more than " +
                            std::to_string(kMaxContactPoints) + " contact points among " +
                            std::to_string(bodies_.size()) +
                            " bodies in one step: the bodies are too crowded; spread them out");
  };
  // A touching pair's manifold, in pair order: cached for recycling, counted and bounded.
  const auto accept = [&](const Manifold& m, std::size_t found) {
    if (recycler != nullptr) recycler->keep(m, bodies_, found);
    counters.recycled += found != ContactRecycler::kNone ? 1 : 0;
    counters.contacts += m.count;
    first_points.push_back(points);
    points += static_cast<std::size_t>(m.count);
    deepest = deeper(m, deepest);
    if (points > kMaxContactPoints) too_many_points();
  };
  counters.pairs_tested += static_cast<std::int64_t>(pairs_.size());
  if (workers == nullptr) {
    Cursor cursor;
    for (const std::pair<int, int>& pair : pairs_) {
      // Built in place (no copy of the 8 contact slots); dropped again if the pair does not touch.
      Manifold& m = manifolds.emplace_back();
      if (narrow(pair, m, cursor)) {
        accept(m, cursor.found);
      } else {
        manifolds.pop_back();
      }
    }
  } else {
    // The pairs in chunks of consecutive pairs. The calling thread makes the manifolds of the
    // first chunks, its even share of them, in place as on one thread; the rest the threads take
    // as they come free (the pairs' cost is uneven, and a plane's pairs come together), each
    // chunk into its own list. The lists are joined after the first chunks' manifolds in chunk
    // order, so the manifolds are those of one thread, in the same order. Which chunks go to the
    // lists depends only on their count, so a list's storage grows in the same steps on every
    // run: its manifolds are made once and written over from step to step (`used` of them this
    // step), and only their used contacts are copied.
    std::vector<StepContext::NarrowShare>& shares = ctx_->narrow_shares;
    const std::size_t chunks = (pairs_.size() + kPairsPerChunk - 1) / kPairsPerChunk;
    if (shares.size() < chunks) shares.resize(chunks);
    const std::size_t front_chunks = chunks / static_cast<std::size_t>(workers->count());
    std::atomic<std::size_t> next_chunk{front_chunks};  // the first chunk no thread has taken
    std::size_t front_used = 0;      // manifolds the calling thread made in place
    std::size_t front_points = 0;    // their contact points
    std::size_t front_recycled = 0;  // those of them recycled
    double front_deepest = 0.0;      // their deepest contact
    const auto front = [&] {
      Cursor cursor;
      for (std::size_t i = 0, end = front_chunks * kPairsPerChunk; i < end; ++i) {
        if (front_used == manifolds.size()) manifolds.emplace_back();
        Manifold& m = manifolds[front_used];
        m.count = 0;
        if (narrow(pairs_[i], m, cursor)) {
          if (recycler != nullptr) recycler->keep(m, bodies_, cursor.found);
          front_recycled += cursor.found != ContactRecycler::kNone ? 1 : 0;
          first_points.push_back(front_points);
          front_points += static_cast<std::size_t>(m.count);
          front_deepest = deeper(m, front_deepest);
          ++front_used;
        }
      }
    };
    const auto back_chunk = [&](std::size_t k) {
      const std::size_t begin = k * kPairsPerChunk;
      const std::size_t end = std::min(begin + kPairsPerChunk, pairs_.size());
      StepContext::NarrowShare& share = shares[k];
      share.used = 0;
      share.found.clear();
      Cursor cursor = recycler != nullptr ? recycler->cursor_at(pairs_[begin].first, pairs_[begin].second) : Cursor{};
      share.points = 0;
      share.deepest = 0.0;
      for (std::size_t i = begin; i < end; ++i) {
        if (share.used == share.manifolds.size()) share.manifolds.emplace_back();
        Manifold& m = share.manifolds[share.used];
        m.count = 0;
        if (narrow(pairs_[i], m, cursor)) {
          share.found.push_back(cursor.found);
          share.points += static_cast<std::size_t>(m.count);
          share.deepest = deeper(m, share.deepest);
          ++share.used;
        }
      }
    };
    auto take = [&](int t) {
      if (t == 0) front();
      for (std::size_t k = next_chunk.fetch_add(1, std::memory_order_relaxed); k < chunks;
           k = next_chunk.fetch_add(1, std::memory_order_relaxed)) {
        back_chunk(k);
      }
    };
    workers->run(take);
    // Counted and bounded in chunk order, then the lists' copied to their places (and cached
    // for recycling) on the threads.
    std::size_t count = front_used;
    points += front_points;
    deepest = front_deepest;
    counters.contacts += static_cast<std::int64_t>(front_points);
    counters.recycled += static_cast<std::int64_t>(front_recycled);
    for (std::size_t k = front_chunks; k < chunks; ++k) {
      StepContext::NarrowShare& share = shares[k];
      share.first = count;
      share.first_point = points;
      count += share.used;
      points += share.points;
      deepest = std::max(deepest, share.deepest);
      counters.contacts += static_cast<std::int64_t>(share.points);
      for (const std::size_t found : share.found) counters.recycled += found != ContactRecycler::kNone ? 1 : 0;
    }
    if (points > kMaxContactPoints) too_many_points();
    manifolds.resize(count);
    detail::resize_with_headroom(first_points, count);
    if (recycler != nullptr) recycler->resize_kept(count);
    parallel_chunks(workers, chunks - front_chunks, [&](std::size_t j) {
      const StepContext::NarrowShare& share = shares[front_chunks + j];
      for (std::size_t i = 0, p = share.first_point; i < share.used; ++i) {
        first_points[share.first + i] = p;
        p += static_cast<std::size_t>(share.manifolds[i].count);
        copy_used_contacts(share.manifolds[i], manifolds[share.first + i]);
        if (recycler != nullptr) recycler->keep_at(share.first + i, share.manifolds[i], bodies_, share.found[i]);
      }
    });
  }
  if (recycler != nullptr) recycler->end_step();
  ctx_->contact_points = points;
  ctx_->deepest_contact = deepest;
}

// The contact and friction rows of every manifold of the step (build_rows' layout), from
// `bodies` (the step's, or a copy with their positions at its start), velocities_ (where some
// pair may bounce; no other row reads them) and the warm start's friction directions.
void World::write_contact_rows(const std::vector<Body>& bodies, const RowParams& params, bool warm,
                               Workers* workers) const {
  StepContext& ctx = *ctx_;
  const bool friction = ctx.layout.friction;
  ConstraintRow* rows = ctx.rows.data();
  const BodyVelocity unread{};
  const auto velocity = [&](int body) -> const BodyVelocity& {
    return ctx.may_bounce ? velocities_[static_cast<std::size_t>(body)] : unread;
  };
  parallel_blocks(workers, ctx.manifolds.size(), kMinParallelRows, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const Manifold& m = ctx.manifolds[k];
      const std::size_t first = ctx.first_points[k];
      write_normal_rows(m, bodies, velocity(m.body_a), velocity(m.body_b), params, rows + first);
      if (!friction) continue;
      write_friction_rows(m, bodies, params, static_cast<int>(first), rows + ctx.layout.friction_row(first),
                          warm ? ctx.warm_start->tangents(first) : nullptr);
    }
  });
}

// Stage 2, Sec. 5: contact rows, friction rows, then distance rows.
void World::build_rows() {
  StepContext& ctx = *ctx_;
  std::vector<ConstraintRow>& rows = ctx.rows;
  RowParams params{.beta = def_.beta,
                   .dt = def_.dt,
                   .friction = def_.friction,
                   .gravity = def_.gravity,
                   .restitution = def_.restitution,
                   .restitution_threshold = def_.restitution_threshold,
                   .penetration_slop = def_.penetration_slop,
                   .body_friction = body_friction_};
  push_->adjust_rows(def_, params);  // the paper's methods leave params as they are
  // The row count is known from the manifolds: make room once, with headroom (no allocation in
  // steady state).
  const std::size_t points = ctx.contact_points;
  // Two friction rows a point (write_friction_rows).
  const bool friction = params.friction > 0.0 || params.body_friction;
  ctx.layout = RowLayout{.points = points, .friction = friction, .rods = distances_.size()};
  detail::reserve_with_headroom(rows, ctx.layout.size());
  // Each body's v and w (w needs I^-1 = R I_body^-1 R^T) once, for the bodies in a manifold
  // (velocity_known_ marks them); a body typically sits in several. Only the restitution reads
  // them (write_normal_rows).
  Workers* workers = ctx.workers();
  ctx.may_bounce = def_.restitution > 0.0 || body_restitution_;
  if (ctx.may_bounce) {
    velocity_known_.assign(bodies_.size(), 0);  // n bytes: no allocation once grown
    velocities_.resize(bodies_.size());
    for (const Manifold& m : ctx.manifolds) {
      velocity_known_[static_cast<std::size_t>(m.body_a)] = 1;
      velocity_known_[static_cast<std::size_t>(m.body_b)] = 1;
    }
    parallel_blocks(workers, bodies_.size(), kMinParallelRows, [this](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) {
        if (velocity_known_[k]) velocities_[k] = body_velocity(bodies_[k]);
      }
    });
  }
  // Warm starting: which contacts persist from the last step, and the friction directions that
  // carry their lambdas over (warm_start.h). Without it the cache is dropped.
  const bool warm = def_.warm_start > 0.0;
  if (warm) {
    if (!ctx.warm_start) ctx.warm_start = std::make_unique<WarmStartCache>();
    ctx.warm_start->match(ctx.manifolds, ctx.workers(), &ctx.first_points);
  } else if (ctx.warm_start) {
    ctx.warm_start->clear();
  }
  // The contact rows of every manifold first, then their friction rows, then the rods. PGS with
  // a fixed number of sweeps leaves its residual mostly in the rows it updated first; the rows
  // updated last hold at the end of the solve. Sliding velocity left over is never corrected
  // (no push acts along a tangent), while a normal row's residual is a small sink the push
  // factor takes back. With the friction rows after all contact rows, the contact rows updated
  // later in a sweep no longer disturb the sliding velocity the friction rows set
  // (docs/findings.md, "Why the paper's stack drifts": the stack slid 2.4 m in 600 s with each
  // point's friction rows right after its contact row).
  // Manifold k's contact rows start at its first point, its friction rows at points plus twice
  // that: each manifold writes only its own rows, so the threads share the manifolds.
  // Coloured PGS cuts its runs from the same layout as spans of rows on one pair (row_colours.h).
  // (ctx.first_points: counted by the collide stage.)
  std::vector<RowSpan>& spans = ctx.row_spans;
  const bool with_spans = def_.solver == SolverKind::coloured_pgs;
  const std::size_t manifolds = ctx.manifolds.size();
  detail::resize_with_headroom(spans, with_spans ? manifolds * (friction ? 2 : 1) + distances_.size() : 0);
  if (with_spans) {
    // Each manifold writes its own spans.
    parallel_blocks(workers, manifolds, kMinParallelRows, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) {
        const Manifold& m = ctx.manifolds[k];
        spans[k] = RowSpan{m.body_a, m.body_b, m.count};
        if (friction) spans[manifolds + k] = RowSpan{m.body_a, m.body_b, 2 * m.count};
      }
    });
    for (std::size_t r = 0, first = manifolds * (friction ? 2 : 1); r < distances_.size(); ++r) {
      spans[first + r] = RowSpan{distances_[r].body_a, distances_[r].body_b, 1};
    }
  }
  rows.resize(ctx.layout.first_rod());  // rows left from the last step are written whole
  // A method that does not read them (the soft step) leaves them to World::rows.
  StepContext::DeferredRows& deferred = ctx.deferred_rows;
  deferred.pending = !push_->reads_contact_rows(def_);
  if (deferred.pending) {
    deferred.warm = warm;
    deferred.params = params;
    detail::resize_with_headroom(deferred.x, bodies_.size());
    for (std::size_t i = 0; i < bodies_.size(); ++i) deferred.x[i] = bodies_[i].x;
  } else {
    write_contact_rows(bodies_, params, warm, workers);
  }
  for (const DistanceConstraint& d : distances_) append_distance_row(d, bodies_, params, rows);
  ctx.counters.rows += static_cast<std::int64_t>(rows.size());
  // Box3D's warm start is the method's own (WarmStartRule::manifold).
  if (warm && push_->warm_start_rule(def_) == WarmStartRule::sustained) {
    ctx.warm_start->initial_guesses(ctx.manifolds, rows, distances_.size(), def_.warm_start,
                                    def_.friction_model, ctx.initial, ctx.initial_second, workers);
  }
}

}  // namespace cps
