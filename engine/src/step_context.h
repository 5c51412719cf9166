#pragma once
// The step context: what the stages of one World::step share (after Box2D v3's b2StepContext,
// erincatto/box2d src/solver.h): the world's parameters and bodies, the manifolds, rows, lambdas
// and forces the stages make, the solver of A lambda = b, the warm-start cache and the counters.
// World owns one; the push method of the step (push/push_method.h) reads and writes it in the
// solve and integrate stages.

#include "constraint_solver.h"
#include "contact_recycling.h"
#include "system.h"
#include "warm_start.h"

#include "cps/body.h"
#include "cps/collision.h"
#include "cps/constraint.h"
#include "cps/parameters.h"
#include "cps/step_system.h"
#include "cps/world.h"

#include <Eigen/Core>

#include <chrono>
#include <memory>
#include <vector>

namespace cps {

struct StepContext;

/// Where each kind of row sits in StepContext::rows (World::build_rows, Sec. 5): one contact row
/// per contact point, the manifolds' points in order; then, when the world has friction, two
/// friction rows per point in the same order; then one row per rod. Indices are row numbers
/// (0-based, < size()).
struct RowLayout {
  std::size_t points = 0;  ///< contact points, so contact rows
  bool friction = false;   ///< whether two friction rows a point follow the contact rows
  std::size_t rods = 0;    ///< distance rows
  /// The first of point p's two friction rows (friction only).
  std::size_t friction_row(std::size_t p) const { return points + 2 * p; }
  std::size_t first_rod() const { return points * (friction ? 3 : 1); }
  std::size_t rod_row(std::size_t r) const { return first_rod() + r; }
  std::size_t size() const { return first_rod() + rods; }
};

/// Adds the wall-clock time from its construction to its destruction to one stage of
/// ctx.stage_times (s), when ctx.time_stages and `active` are on (a method on several threads
/// times on one of them); otherwise reads no clock. No errors.
class StageTimer {
 public:
  StageTimer(StepContext& ctx, double StageTimes::*stage, bool active = true);
  ~StageTimer();
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  double* sum_ = nullptr;
  std::chrono::steady_clock::time_point start_;
};

/// What one step's stages share. n bodies, c rows. Forces are 6n vectors: force and torque per
/// body (N, N m). Buffers keep their storage from step to step (no allocation once grown).
struct StepContext {
  StepContext() = default;
  /// Copies the last step's results (manifolds, rows, both lambdas; each with the original's
  /// capacity, so that the copy's next steps grow them when the original's would), the
  /// warm-start cache, the recycled contacts, the counters and the stage timing; the buffers and
  /// the solver start empty (nothing in them outlives a step). Throws std::bad_alloc.
  StepContext(const StepContext& other);
  StepContext& operator=(const StepContext&) = delete;
  StepContext(StepContext&&) noexcept = default;
  StepContext& operator=(StepContext&&) noexcept = default;
  ~StepContext();

  // Set by World::step before the first stage.
  const WorldDef* def = nullptr;
  std::vector<Body>* bodies = nullptr;
  const std::vector<DistanceConstraint>* distances = nullptr;

  std::vector<Manifold> manifolds;    ///< Sec. 4: the manifolds of this step's collide stage
  /// Per manifold: the contact points of the manifolds before it (World::collide, with them).
  std::vector<std::size_t> first_points;
  std::size_t contact_points = 0;  ///< the contact points of all manifolds (World::collide)
  double deepest_contact = 0.0;    ///< m: the largest contact depth, 0 when none is positive
  std::vector<ConstraintRow> rows;    ///< Sec. 5: c rows: contacts, friction, rods
  RowLayout layout;                   ///< where each kind of row sits in `rows`
  std::vector<double> lambda;         ///< c, N: the solve that sets the step's result (see lambda_pending)
  std::vector<double> lambda_second;  ///< c, N: the second solve of Sec. 8.1 (split only)
  Eigen::VectorXd f_ext;              ///< 6n: f_ext = [m g, 0] per movable body (Sec. 6.1)
  Eigen::VectorXd f_cv;               ///< 6n: f_ext + J^T lambda, the force that moves positions
  Eigen::VectorXd f_c0;               ///< 6n: the force of the stored momenta (Sec. 8.1)
  std::unique_ptr<ConstraintSolver> solver;  ///< for def->assembly, made by prepare()
  /// def->threads threads for the stages that share their work (workers.h); null for one thread.
  /// Kept from step to step (update_workers); not copied with the context.
  std::unique_ptr<Workers> pool;
  Assembly solver_assembly = Assembly::matrix_free;
  /// Warm starting (Sec. 6.2.3): the last step's contacts and lambdas (made when first needed),
  /// and this step's initial guesses of the two solves (c each, N).
  std::unique_ptr<WarmStartCache> warm_start;
  std::vector<double> initial;
  std::vector<double> initial_second;
  /// Contact recycling (WorldDef::contact_recycle_distance > 0): the manifolds that may be kept.
  std::unique_ptr<ContactRecycler> recycler;
  /// One chunk of the narrow phase (World::collide on several threads): the manifolds of the
  /// touching pairs of its consecutive pairs, in pair order, and for each the last step's
  /// recycled entry (ContactRecycler::kNone: made anew).
  struct NarrowShare {
    std::vector<Manifold> manifolds;  ///< the first `used` are this step's; the rest storage
    std::size_t used = 0;
    std::vector<std::size_t> found;
    std::size_t first = 0;   ///< its first manifold's place in the step's manifolds
    std::size_t points = 0;  ///< contact points in its manifolds
    std::size_t first_point = 0;  ///< its first manifold's first point in the step's
    double deepest = 0.0;         ///< m: its deepest contact, 0 when none is positive
  };
  std::vector<NarrowShare> narrow_shares;  ///< per chunk; not copied with the context
  /// Coloured PGS: the rows' stretches on the same two bodies in row order (World::build_rows:
  /// each manifold's contact rows, each one's friction rows, each rod's row), from which
  /// prepare() cuts the runs without reading every row; empty for the other solvers.
  std::vector<RowSpan> row_spans;
  /// The contact and friction rows of `rows` that World::build_rows left unwritten for a push
  /// method that does not read them (PushMethod::reads_contact_rows), for World::rows to write
  /// when they are asked for: the row parameters, whether the warm start chose the friction
  /// directions, and the bodies' positions x (n, m) at the start of the step; `bodies` is
  /// World::rows' copy of the bodies with those positions, kept so that it allocates only to
  /// grow. Not copied with the context (a world writes its rows before it is copied).
  struct DeferredRows {
    bool pending = false;
    bool warm = false;
    RowParams params;
    std::vector<Vec3> x;
    std::vector<Body> bodies;
  };
  DeferredRows deferred_rows;
  /// Whether the push method left `lambda` to be written when it is asked for (World::lambda
  /// calls PushMethod::write_lambda); cleared when the next step begins.
  bool lambda_pending = false;
  /// Whether some pair of the step may have restitution (WorldDef::restitution or a body's own
  /// above 0; World::build_rows): the rows' and the soft step's restitution targets.
  bool may_bounce = false;
  StepCounters counters;
  ResidualStats residual;
  /// World::set_solve_observer's callback, or empty (the usual case: one branch a solve). Not
  /// copied with the context: a copy of a world starts unobserved.
  SolveObserver observer;
  /// World::set_solve_observer's choice of solves, or empty (every solve is observed).
  SolveFilter observe_filter;
  /// World::set_solve_override's callback, or empty (the usual case). Not copied either.
  SolveOverride override_solve;
  int solves_this_step = 0;  ///< solves made in the current step (StepSystem::solve)
  bool time_stages = false;  ///< World::set_stage_timing
  StageTimes stage_times;    ///< s, summed while time_stages is on

  /// Makes or drops `pool` to match def->threads (World::step calls it first). Throws
  /// std::system_error when a thread cannot be started.
  void update_workers();
  /// The step's threads, or nullptr for one thread.
  Workers* workers() const { return pool.get(); }

  /// Warm starting is on (WorldDef::warm_start > 0).
  bool warm() const { return def->warm_start > 0.0; }
  /// The first solve's initial guess: the warm start's (c, N), or nullptr for lambda = 0.
  const std::vector<double>* warm_guess() const { return warm() ? &initial : nullptr; }
  /// The settings of a solve over dt (s): def's sweeps, solver and friction model, rigid rows.
  SolveSettings settings(double dt) const;

  /// Builds what the step's solves share (Sec. 6: A, or the packed rows), with a new solver when
  /// def->assembly changed. Nothing without rows.
  void prepare();
  /// Solves A lambda = b (Sec. 7) with settings `s` for the `terms` of the targets from `start`
  /// (c, N; nullptr: from 0) into `out` (c, N), then f = f_ext + J^T out (Eq. 6.2.1, 6n),
  /// counting the solve and, with def->measure_residual, its residual. Without rows: out empty,
  /// f = f_ext. No errors.
  void solve(const SolveSettings& s, TargetTerms terms, std::vector<double>& out,
             Eigen::VectorXd& f, const std::vector<double>* start);
  /// solve() over the whole step (dt).
  void solve(TargetTerms terms, std::vector<double>& out, Eigen::VectorXd& f,
             const std::vector<double>* start) {
    solve(settings(def->dt), terms, out, f, start);
  }
  /// Writes out the system of the solve that just gave `out` (c, N) from `start` (c, N, or
  /// nullptr for 0) with settings `s` and hands it to the observer, then to the override, whose
  /// lambda replaces `out` (cps/step_system.h). Throws std::invalid_argument when the override
  /// leaves a lambda of another size.
  void notify_observer(const SolveSettings& s, TargetTerms terms, std::vector<double>& out,
                       const std::vector<double>* start) const;
  /// With warm starting on, stores this step's lambda and lambda_second for the next step.
  void store_warm_start();
  /// Sec. 3.2 over h (s): positions with f_position, stored momenta with f_momentum (6n each).
  void integrate(const Eigen::VectorXd& f_position, const Eigen::VectorXd& f_momentum, double h);
};

}  // namespace cps

namespace cps {

inline StageTimer::StageTimer(StepContext& ctx, double StageTimes::*stage, bool active) {
  if (!ctx.time_stages || !active) return;
  sum_ = &(ctx.stage_times.*stage);
  start_ = std::chrono::steady_clock::now();
}

inline StageTimer::~StageTimer() {
  if (sum_ != nullptr) {
    *sum_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
}

}  // namespace cps
