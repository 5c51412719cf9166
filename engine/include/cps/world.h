#pragma once
// The world and its step. One step reads as the paper's stages, in order, each a function of
// World (engine/src/world.cpp) over the step context (engine/src/step_context.h):
//   external_forces   Sec. 6.1  f_ext = [m g, 0] per movable body
//   collide           Sec. 4    each box's and plane's rotation, the broad phase's candidate
//                               pairs (broad_phase.h), a manifold for each pair that touches
//                               (skipped when the world has collision off)
//   build_rows        Sec. 5    contact, friction (only with mu > 0) and distance rows; with
//                               warm starting, each row's initial guess (Sec. 6.2.3)
//   prepare           Sec. 6    J, M^-1 and A (explicit), or the packed rows (matrix-free)
//   push method       Secs. 7, 8.1, 3.2: the solves of A lambda = b and the integration, as the
//                               chosen method (WorldDef::push) does them, one file each in
//                               engine/src/push/: baumgarte (Sec. 5.3: one solve, f_cv moves
//                               positions and momenta), split (Sec. 8.1: a second solve without
//                               the push sets the momenta), and the methods compared with the
//                               paper's: split-impulse, soft, ngs, tgs, xpbd, avbd (the table:
//                               cps::parameter("push").choices).

#include "cps/body.h"
#include "cps/collision.h"
#include "cps/constraint.h"
#include "cps/parameters.h"
#include "cps/step_system.h"

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace cps {

// Internal to the engine (engine/src): the broad phase, the step context, the push method.
class BroadPhase;
struct StepContext;
class PushMethod;
class Workers;

/// The most candidate pairs the broad phase may list in one step (count). A pair costs 8 bytes;
/// the largest scaled scenes list about 10 per body. Beyond it World::step throws.
inline constexpr std::size_t kMaxCandidatePairs = 4'000'000;

/// The most contact points the narrow phase may find in one step (count). A point costs about
/// 1.2 kB of rows and solver storage (three rows with friction), so this bounds a step's contact
/// storage near 300 MB; the largest scaled scene (pyramid_20000) finds about 150,000. Beyond it
/// World::step throws.
inline constexpr std::size_t kMaxContactPoints = 250'000;

/// Work done by the steps so far, summed over the run.
struct StepCounters {
  std::int64_t steps = 0;
  std::int64_t pairs_tested = 0;  ///< body pairs handed to the narrow phase
  std::int64_t contacts = 0;      ///< contact points found
  std::int64_t recycled = 0;      ///< manifolds kept from the step before (contact recycling)
  std::int64_t rows = 0;          ///< constraint rows built
  std::int64_t solves = 0;        ///< solves of A lambda = b
};

/// Where the steps' time went, per stage (s of wall-clock time, steady clock, summed over the steps
/// taken while World::set_stage_timing is on). The stages are those of World::step and, inside
/// the push method, the ones it runs through the step context or times itself (the soft step
/// times each of its own); a method's time in none of them is `other`. Timing reads the clock
/// about twice per stage, so it adds well under a microsecond to a step.
struct StageTimes {
  double collide = 0.0;    ///< f_ext, the broad and the narrow phase (Secs. 6.1, 4)
  double rows = 0.0;       ///< the rows and the warm-start cache's matching (Secs. 5, 6.2.3)
  double prepare = 0.0;    ///< A or the packed rows (Sec. 6); the soft step's prepare
  double solve = 0.0;      ///< a step's first solve and every solve with the push (Sec. 7); the
                           ///< soft step's warm start and biased sweeps
  double relax = 0.0;      ///< later solves without the push (Sec. 8.1's second, TGS's last);
                           ///< the soft step's relax
  double integrate = 0.0;  ///< moving the bodies (Sec. 3.2); the soft step's velocity and
                           ///< position updates
  double store = 0.0;      ///< storing lambda for the warm start; the soft step's restitution
  double other = 0.0;      ///< the push method's time in none of the stages above
  /// The sum of the stages (s).
  double total() const { return collide + rows + prepare + solve + relax + integrate + store + other; }
};

/// LCP residuals (N) of the solves so far, when WorldDef::measure_residual is set: the largest
/// row residual, and the sum of squares and count of row residuals (for an RMS).
struct ResidualStats {
  double max = 0.0;
  double sum_squares = 0.0;
  std::int64_t rows = 0;
  double rms() const { return rows > 0 ? std::sqrt(sum_squares / static_cast<double>(rows)) : 0.0; }
};

/// A set of bodies and distance constraints stepped by the constraint solver. Bodies are
/// referred to by index, in the order they were added; the order of every loop depends on
/// indices only.
class World {
 public:
  /// Throws std::invalid_argument if def is invalid (see WorldDef::validate).
  explicit World(const WorldDef& def = {});
  /// A copy has the same parameters, bodies, constraints, last-step results (with the
  /// original's storage, so that they grow when the original's would), counters and warm start
  /// cache (so it steps on exactly as the original would); its step buffers start empty (they
  /// hold nothing from one step to the next) and grow in its first step. Throws std::bad_alloc.
  World(const World& other);
  World& operator=(const World& other);
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  ~World();

  /// Adds a body and returns its index. Throws std::invalid_argument (see make_body) and leaves
  /// the world unchanged on bad input.
  int add_body(const BodyDef& def);
  /// Replaces body i's state: position x (m, 3), orientation o (unit quaternion, body to world),
  /// linear velocity v (m/s, 3) and angular velocity w (rad/s, 3, world frame); a static body
  /// keeps p = l = 0 whatever v and w say. Its shape, mass and coefficients stay. The last
  /// step's manifolds, rows and warm-start cache stay too (the next step collides again).
  /// Throws std::invalid_argument for an index outside [0, bodies), or any value make_body
  /// refuses, and leaves the world unchanged.
  void set_body_state(int i, const Vec3& x, const Quat& o, const Vec3& v, const Vec3& w);

  /// Adds a distance constraint (Sec. 5.2) and returns its index. Throws std::invalid_argument
  /// naming the value, leaving the world unchanged, for a body index that does not exist or is
  /// static (body_a must be movable; body_b may be kWorldBody), equal bodies, non-finite points,
  /// or a length that is negative or not finite (m).
  int add_distance(const DistanceConstraint& d);

  /// Advances the world by def().dt (s). Throws std::length_error naming the count when the
  /// bodies are so crowded that a step would list more than kMaxCandidatePairs pairs or find
  /// more than kMaxContactPoints contact points (a pile of a thousand bodies in one spot); the
  /// bodies are then left as they were before the step.
  void step();
  /// The steps begun by every World of this process, on every thread (count), so that a
  /// program can say how much it stepped (cps's run.json does). Thread-safe; throws nothing.
  static std::int64_t steps_in_process();

  const WorldDef& def() const { return def_; }
  const std::vector<Body>& bodies() const { return bodies_; }
  const Body& body(int i) const { return bodies_.at(static_cast<std::size_t>(i)); }
  const std::vector<DistanceConstraint>& distances() const { return distances_; }
  /// Simulated time (s): steps taken times dt.
  double time() const { return static_cast<double>(counters().steps) * def_.dt; }
  const StepCounters& counters() const;
  const ResidualStats& residual() const;
  /// Turns the timing of the step's stages on or off; turning it on starts the sums from 0. Off
  /// (the default), a step reads no clock. A copy of the world keeps the flag and the sums. No
  /// errors.
  void set_stage_timing(bool on);
  /// The stage times summed since timing was turned on (all 0 while it was never on).
  const StageTimes& stage_times() const;
  /// Manifolds found by the last step's collision stage (normals from a to b, depths in m).
  const std::vector<Manifold>& manifolds() const;
  /// The largest depth (m) of the contacts in manifolds(): how far the bodies overlapped where
  /// the last step found them (Sec. 4); 0 before the first step and when no depth is positive
  /// (a speculative contact's is negative). Counted while colliding, so it reads no manifold.
  /// No errors.
  double deepest_contact() const;
  /// Rows built by the last step (c of them) and lambda of its first solve (c, N). Under a push
  /// method that does not read its contact and friction rows (the soft step), those are written
  /// at the first call after the step, from the bodies as they were at its start: the same rows;
  /// the soft step's lambda likewise, from its impulses. Not to be called from two threads at
  /// once.
  const std::vector<ConstraintRow>& rows() const;
  const std::vector<double>& lambda() const;
  /// lambda of the last step's second solve (c, N; Sec. 8.1, push split only; empty otherwise).
  const std::vector<double>& lambda_second() const;
  /// With warm starting on (WorldDef::warm_start > 0): the contact points of the last step that
  /// persisted from the step before it (same body pair and contact feature), whose rows started
  /// from the cached lambdas (count). 0 with warm starting off.
  std::size_t persisting_contacts() const;

  /// Calls `observer` after every solve of A lambda = b in the following steps, with the system
  /// that solve solved written out (cps/step_system.h: A, b, the limits, the rows' kinds, the
  /// guess and the lambda it returned); an empty function stops it. One solve a step with the
  /// paper's push factor, two with the single frame push factor (Sec. 8.1), more with the
  /// substeps of the soft step. The observer runs inside World::step and must not touch the
  /// world. A copy of the world is not observed. Unobserved, a step does nothing more than test
  /// that the function is empty. `wants`, if not empty, chooses the solves observed before their
  /// system is written out (cps/step_system.h, SolveFilter; an exception it throws leaves step).
  /// No errors of its own.
  void set_solve_observer(SolveObserver observer, SolveFilter wants = {});
  /// Hands each solve of the following steps to `override` after the engine's own sweeps (and
  /// after the observer): the lambda it leaves is the one the step uses (its forces, the warm
  /// start; the residual of measure_residual with the explicit assembly, while the matrix-free
  /// path's stays that of its own sweeps), so that a step can be taken with another solve of the same system,
  /// e.g. an exact one; an empty function stops it. Runs inside World::step and must not touch
  /// the world; a copy of the world has none. Unset, a solve tests that the function is empty.
  /// A lambda of another size than the system's rows throws std::invalid_argument from step().
  void set_solve_override(SolveOverride override);

  /// Replaces the parameters (validated first: throws std::invalid_argument and keeps the old
  /// ones on a bad value). The bodies and constraints stay as they are.
  void set_def(const WorldDef& def);

 private:
  void external_forces();
  void collide();
  void collide_pairs(Workers* workers);  // collide()'s broad and narrow phase
  void build_rows();
  void write_contact_rows(const std::vector<Body>& bodies, const RowParams& params, bool warm,
                          Workers* workers) const;
  // The context with the last step's rows and lambda all written (StepContext::DeferredRows,
  // StepContext::lambda_pending).
  const StepContext& settled_context() const;

  WorldDef def_;
  std::vector<Body> bodies_;
  std::vector<DistanceConstraint> distances_;
  // Pairs (a < b) that get no contacts: the bodies of rods with collide = false, sorted, unique.
  std::vector<std::pair<int, int>> apart_;
  // What the stages share and keep (step_context.h): manifolds, rows, lambdas, forces, the
  // solver, the warm-start cache, the counters.
  std::unique_ptr<StepContext> ctx_;
  // The method of def_.push (made when first needed, again when def_.push changes).
  std::unique_ptr<PushMethod> push_;
  PushMode push_mode_ = PushMode::baumgarte;
  // The collide and build stages' buffers, reused from step to step (nothing is allocated once
  // they are big enough): rotation matrices per body, candidate pairs, body velocities for the
  // rows and which of them are computed.
  std::unique_ptr<BroadPhase> broad_phase_;
  std::vector<Mat3> rotations_;
  std::vector<std::pair<int, int>> pairs_;
  std::vector<double> margins_;  // per body (m), when the push method asks for them
  std::vector<BodyVelocity> velocities_;
  std::vector<unsigned char> velocity_known_;
  // Whether some body has its own friction coefficient (Body::friction, RowParams::body_friction).
  bool body_friction_ = false;
  // Whether some body has its own coefficient of restitution above 0 (Body::restitution).
  bool body_restitution_ = false;
};

}  // namespace cps
