// The step as the paper's stages (see world.h): each stage a function, in the paper's order.
#include "cps/world.h"

#include "broad_phase.h"
#include "buffers.h"
#include "constraint_solver.h"
#include "integrator.h"
#include "ngs.h"
#include "soft_step.h"
#include "split_impulse.h"
#include "system.h"
#include "warm_start.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

namespace cps {
namespace {

// Every component finite and within +-limit (isfinite first: no exception on NaN).
bool within(const Vec3& v, double limit) {
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(v[k]) || std::abs(v[k]) > limit) return false;
  }
  return true;
}

}  // namespace

World::World(const WorldDef& def) : def_(def), broad_phase_(std::make_unique<BroadPhase>()) {
  def_.validate();
}

World::World(const World& other)
    : def_(other.def_),
      bodies_(other.bodies_),
      distances_(other.distances_),
      manifolds_(other.manifolds_),
      rows_(other.rows_),
      lambda_(other.lambda_),
      lambda0_(other.lambda0_),
      broad_phase_(std::make_unique<BroadPhase>()),
      warm_start_(other.warm_start_ ? std::make_unique<WarmStartCache>(*other.warm_start_)
                                    : nullptr),
      counters_(other.counters_),
      residual_(other.residual_) {}

World& World::operator=(const World& other) {
  if (this != &other) *this = World(other);
  return *this;
}

World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;
World::~World() = default;

void World::set_def(const WorldDef& def) {
  def.validate();
  def_ = def;
}

int World::add_body(const BodyDef& def) {
  bodies_.push_back(make_body(def));  // make_body throws before anything is added
  return static_cast<int>(bodies_.size()) - 1;
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
  return static_cast<int>(distances_.size()) - 1;
}

std::size_t World::persisting_contacts() const {
  return warm_start_ && def_.warm_start > 0.0 ? warm_start_->matched_points() : 0;
}

void World::step() {
  // Warm starting (Sec. 6.2.3) is on when its factor is above 0; at 0 every solve starts from
  // lambda = 0 as in the paper's Sec. 7.2 and the cache is not kept.
  const bool warm = def_.warm_start > 0.0;
  external_forces();                                  // Sec. 6.1: f_ext
  collide();                                          // Sec. 4: manifolds
  build_rows();                                       // Sec. 5: rows of J, targets, limits
  prepare();                                          // Sec. 6: A or the packed rows
  switch (def_.push) {
    case PushMode::baumgarte:
    case PushMode::split:
      // Sec. 7: lambda, f_cv. With the single frame push factor (Sec. 8.1) both solves are warm
      // started, each from its own lambda of the previous step: they solve for different
      // targets (with and without the push), and a persisting contact's lambda of one solve is
      // the guess closest to that solve's answer. Starting the second from the first's lambda
      // would begin from the push's correction, which Sec. 8.1 keeps out of the stored momenta;
      // with a fixed number of sweeps some of it would stay there.
      solve(TargetTerms::push_and_bias, lambda_, f_cv_, warm ? &initial_ : nullptr);
      if (def_.push == PushMode::split) {
        // Sec. 8.1: lambda_0, f_c0
        solve(TargetTerms::bias_only, lambda0_, f_c0_,
              warm && !initial_second_.empty() ? &initial_second_ : nullptr);
      } else {
        lambda0_.clear();
      }
      if (warm) warm_start_->store(manifolds_, rows_, distances_.size(), lambda_, lambda0_);
      integrate();                                    // Sec. 3.2
      break;
    case PushMode::split_impulse:
      step_split_impulse(warm);
      break;
    case PushMode::soft:
      step_soft(warm);
      break;
    case PushMode::ngs:
      step_ngs(warm);
      break;
  }
  ++counters_.steps;
}

// Split impulse (split_impulse.h): the velocity solve without the push (f_c0 for the momenta),
// then the push on pseudo-velocities from rest; positions move with both.
void World::step_split_impulse(bool warm) {
  lambda0_.clear();
  solve(TargetTerms::bias_only, lambda_, f_c0_, warm ? &initial_ : nullptr);
  if (warm) warm_start_->store(manifolds_, rows_, distances_.size(), lambda_, lambda0_);
  if (!split_impulse_) split_impulse_ = std::make_unique<SplitImpulse>();
  if (!rows_.empty()) {
    split_impulse_->solve(rows_, bodies_, def_.assembly, settings(def_.dt), f_c0_, f_cv_);
    ++counters_.solves;
  } else {
    f_cv_ = f_c0_;
  }
  cps::integrate(bodies_, f_cv_, f_c0_, def_.dt, def_.rotation);
}

// Non-linear Gauss-Seidel (ngs.h): the velocity solve without the push moves positions and
// momenta; then the positions are projected.
void World::step_ngs(bool warm) {
  lambda0_.clear();
  solve(TargetTerms::bias_only, lambda_, f_cv_, warm ? &initial_ : nullptr);
  if (warm) warm_start_->store(manifolds_, rows_, distances_.size(), lambda_, lambda0_);
  if (!ngs_) ngs_ = std::make_unique<NgsProjection>();
  ngs_->capture(manifolds_, bodies_);  // the contact points where the step found them
  cps::integrate(bodies_, f_cv_, f_cv_, def_.dt, def_.rotation);
  ngs_->project(distances_, def_, bodies_);
}

// The soft step (soft_step.h): per substep a soft solve that moves the positions, then a relax
// solve that sets the momenta; lambda carried from each solve to the next.
void World::step_soft(bool warm) {
  if (rows_.empty()) {  // nothing to solve: substeps of free flight under f_ext
    const double h = def_.dt / static_cast<double>(def_.soft_substeps);
    for (int k = 0; k < def_.soft_substeps; ++k) cps::integrate(bodies_, f_ext_, f_ext_, h, def_.rotation);
    lambda_.clear();
    lambda0_.clear();
    return;
  }
  if (!soft_) soft_ = std::make_unique<SoftStep>();
  soft_->begin(rows_, manifolds_, bodies_, def_);
  const double h = soft_->substep();
  zero_force_.setZero(f_ext_.size());  // no allocation once it has the size
  const std::vector<double>* start = warm ? &initial_ : nullptr;
  for (int k = 0; k < def_.soft_substeps; ++k) {
    // 1. soft solve (lambda0_) from the last relaxed lambda
    soft_->set_targets(rows_, distances_, bodies_, /*soft=*/true, /*last=*/false);
    SolveSettings soft_settings = settings(h);
    soft_settings.softness = &soft_->softness();
    solve_with(soft_settings, TargetTerms::push_and_bias, lambda0_, f_cv_, start);
    // 2. positions with f_s; momenta kept
    cps::integrate(bodies_, f_cv_, zero_force_, h, def_.rotation);
    // 3. relax solve (lambda_), rigid, without the push, from the last relaxed lambda (not
    //    lambda_s, which carries the push: soft_step.h); it sets the momenta
    soft_->set_targets(rows_, distances_, bodies_, /*soft=*/false,
                       /*last=*/k + 1 == def_.soft_substeps);
    detail::reserve_with_headroom(relax_start_, lambda_.size());
    relax_start_.assign(lambda_.begin(), lambda_.end());
    solve_with(settings(h), TargetTerms::bias_only, lambda_, f_c0_,
               k > 0 ? &relax_start_ : (warm ? &initial_ : nullptr));
    add_momenta(bodies_, f_c0_, h);
    start = &lambda_;
  }
  lambda0_.clear();
  if (warm) warm_start_->store(manifolds_, rows_, distances_.size(), lambda_, lambda0_);
}

// Stage 0, Sec. 6.1: f_ext (6n) = [m g, 0] per movable body, into a buffer that keeps its size.
void World::external_forces() { gravity_forces(bodies_, def_.gravity, f_ext_); }

// Stage 1, Sec. 4: the broad phase lists the pairs that may touch, in index order, then the
// narrow phase builds their manifolds. The order is that of testing every pair (a, b), a < b,
// so manifolds and rows do not depend on how the candidates were found.
void World::collide() {
  manifolds_.clear();
  if (!def_.collision) return;
  // The rotation matrix of each box and plane, once: the broad phase's bounds and the narrow
  // phase both read it (spheres need none).
  rotations_.resize(bodies_.size());
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_[i].shape.kind != ShapeKind::sphere) rotations_[i] = bodies_[i].rotation();
  }
  broad_phase_->find_pairs(bodies_, rotations_, def_.contact_margin, kMaxCandidatePairs, pairs_);
  // Room for the manifolds a world of this size usually has (a body touches a few others); a
  // crowded step grows it as it finds them, never to a worst case of one per pair.
  detail::reserve_with_headroom(manifolds_, std::min(pairs_.size(), 8 * bodies_.size()));
  std::size_t points = 0;
  for (const auto& [a, b] : pairs_) {
    ++counters_.pairs_tested;
    // Built in place (no copy of the 8 contact slots); dropped again if the pair does not touch.
    Manifold& m = manifolds_.emplace_back();
    m.body_a = a;
    m.body_b = b;
    const auto ia = static_cast<std::size_t>(a);
    const auto ib = static_cast<std::size_t>(b);
    if (cps::collide(bodies_[ia], rotations_[ia], bodies_[ib], rotations_[ib], m,
                     def_.contact_margin) > 0) {
      counters_.contacts += m.count;
      points += static_cast<std::size_t>(m.count);
      if (points > kMaxContactPoints) {
        throw std::length_error("the narrow phase found more than " +
                                std::to_string(kMaxContactPoints) + " contact points among " +
                                std::to_string(bodies_.size()) +
                                " bodies in one step: the bodies are too crowded; spread them out");
      }
    } else {
      manifolds_.pop_back();
    }
  }
}
// Stage 2, Sec. 5: contact rows, friction rows, then distance rows.
void World::build_rows() {
  rows_.clear();
  // The row count is known from the manifolds: make room once, with headroom (no allocation in
  // steady state).
  std::size_t contact_points = 0;
  for (const Manifold& m : manifolds_) contact_points += static_cast<std::size_t>(m.count);
  detail::reserve_with_headroom(
      rows_, contact_points * (def_.friction > 0.0 ? 3 : 1) + distances_.size());
  RowParams params{def_.beta,        def_.dt,
                   def_.friction,    def_.gravity,
                   def_.restitution, def_.restitution_threshold,
                   def_.penetration_slop};
  // Split impulse: shallow contacts keep their push in the velocity (split_impulse.h).
  if (def_.push == PushMode::split_impulse) params.velocity_push_depth = def_.split_impulse_threshold;
  // Each body's v and w (w needs I^-1 = R I_body^-1 R^T) once, for the bodies in a manifold;
  // a body typically sits in several.
  velocity_known_.assign(bodies_.size(), 0);  // n bytes: no allocation once grown
  velocities_.resize(bodies_.size());
  const auto velocity = [this](int i) -> const BodyVelocity& {
    const auto k = static_cast<std::size_t>(i);
    if (!velocity_known_[k]) {
      velocities_[k] = body_velocity(bodies_[k]);
      velocity_known_[k] = 1;
    }
    return velocities_[k];
  };
  // Warm starting: which contacts persist from the last step, and the friction directions that
  // carry their lambdas over (warm_start.h). Without it the cache is dropped.
  const bool warm = def_.warm_start > 0.0;
  if (warm) {
    if (!warm_start_) warm_start_ = std::make_unique<WarmStartCache>();
    warm_start_->match(manifolds_);
  } else if (warm_start_) {
    warm_start_->clear();
  }
  // The contact rows of every manifold first, then their friction rows, then the rods. PGS with
  // a fixed number of sweeps leaves its residual mostly in the rows it updated first; the rows
  // updated last hold at the end of the solve. Sliding velocity left over is never corrected
  // (no push acts along a tangent), while a normal row's residual is a small sink the push
  // factor takes back. With the friction rows after all contact rows, the contact rows updated
  // later in a sweep no longer disturb the sliding velocity the friction rows set (README, "Why
  // the paper's stack drifts": the stack slid 2.4 m in 600 s with each point's friction rows
  // right after its contact row).
  for (const Manifold& m : manifolds_) {
    append_normal_rows(m, bodies_, velocity(m.body_a), velocity(m.body_b), params, rows_);
  }
  int first_normal_row = 0;
  for (const Manifold& m : manifolds_) {
    append_friction_rows(m, bodies_, params, first_normal_row, rows_,
                         warm ? warm_start_->tangents(static_cast<std::size_t>(first_normal_row))
                              : nullptr);
    first_normal_row += m.count;
  }
  for (const DistanceConstraint& d : distances_) append_distance_row(d, bodies_, params, rows_);
  counters_.rows += static_cast<std::int64_t>(rows_.size());
  if (warm) {
    warm_start_->initial_guesses(manifolds_, rows_, distances_.size(), def_.warm_start,
                                 def_.friction_model, initial_, initial_second_);
  }
}

void World::count_residual(double max, double sum_squares, std::int64_t rows) {
  residual_.max = std::max(residual_.max, max);
  residual_.sum_squares += sum_squares;
  residual_.rows += rows;
}

// Stage 3, Sec. 6: what the solves of this step share (a new solver when the assembly changed).
void World::prepare() {
  if (rows_.empty()) return;
  if (!solver_ || solver_assembly_ != def_.assembly) {
    solver_ = make_constraint_solver(def_.assembly);
    solver_assembly_ = def_.assembly;
  }
  solver_->prepare(rows_, bodies_);
}

SolveSettings World::settings(double dt) const {
  return SolveSettings{dt, def_.iterations, def_.solver, def_.friction_model};
}

// Stage 4, Sec. 7 (and the second solve of Sec. 8.1): lambda from `initial` (warm starting) or
// from 0, then f = f_ext + J^T lambda (Eq. 6.2.1). A step without rows solves nothing: f = f_ext.
void World::solve(TargetTerms terms, std::vector<double>& lambda, Eigen::VectorXd& f,
                  const std::vector<double>* initial) {
  solve_with(settings(def_.dt), terms, lambda, f, initial);
}

void World::solve_with(const SolveSettings& settings, TargetTerms terms,
                       std::vector<double>& lambda, Eigen::VectorXd& f,
                       const std::vector<double>* initial) {
  if (rows_.empty()) {
    lambda.clear();
    f = f_ext_;
    return;
  }
  solver_->solve(rows_, bodies_, f_ext_, terms, settings, lambda, initial);
  ++counters_.solves;
  if (def_.measure_residual) {
    double max;
    double sum_squares;
    solver_->residual(rows_, def_.friction_model, lambda, max, sum_squares);
    count_residual(max, sum_squares, static_cast<std::int64_t>(rows_.size()));
  }
  add_constraint_forces(rows_, lambda, f_ext_, f);
}

// Stage 5, Sec. 3.2: positions move with f_cv; the stored momenta with f_c0 (Sec. 8.1), or f_cv
// for Baumgarte.
void World::integrate() {
  cps::integrate(bodies_, f_cv_, def_.push == PushMode::split ? f_c0_ : f_cv_, def_.dt,
                 def_.rotation);
}

}  // namespace cps
