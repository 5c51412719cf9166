// The step: collide, build rows, assemble, solve, integrate (see world.h).
#include "cps/world.h"

#include "buffers.h"

#include "cps/integrator.h"
#include "cps/solver.h"
#include "cps/system.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cps {
namespace {

[[noreturn]] void bad_parameter(const char* name, double value, const char* allowed) {
  std::ostringstream s;
  s << "world parameter " << name << " = " << value << " is not allowed: " << allowed;
  throw std::invalid_argument(s.str());
}

}  // namespace

void WorldDef::validate() const {
  if (!all_finite(gravity)) bad_parameter("gravity", gravity.norm(), "it must be finite (m/s^2)");
  if (!(std::isfinite(dt) && dt > 0.0)) bad_parameter("dt", dt, "it must be finite and > 0 s");
  if (iterations < 1) bad_parameter("iterations", iterations, "it must be >= 1");
  if (!(beta >= 0.0 && beta <= 1.0)) bad_parameter("beta", beta, "it must be in [0, 1]");
  if (!(std::isfinite(friction) && friction >= 0.0)) {
    bad_parameter("friction", friction, "it must be finite and >= 0");
  }
  if (!(restitution >= 0.0 && restitution <= 1.0)) {
    bad_parameter("restitution", restitution, "it must be in [0, 1]");
  }
  if (!(std::isfinite(contact_margin) && contact_margin >= 0.0)) {
    bad_parameter("contact_margin", contact_margin, "it must be finite and >= 0 m");
  }
  if (!(std::isfinite(restitution_threshold) && restitution_threshold >= 0.0)) {
    bad_parameter("restitution_threshold", restitution_threshold, "it must be finite and >= 0 m/s");
  }
}

World::World(const WorldDef& def) : def_(def) { def_.validate(); }

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
  } else if (!all_finite(d.local_a) || !all_finite(d.local_b)) {
    why << "the end points must be finite";
  } else if (!(std::isfinite(d.length) && d.length >= 0.0)) {
    why << "length " << d.length << " m must be finite and >= 0";
  }
  if (!why.str().empty()) throw std::invalid_argument("distance constraint: " + why.str());
  distances_.push_back(d);
  return static_cast<int>(distances_.size()) - 1;
}

void World::step() {
  collide();
  build_rows();
  solve_and_integrate();
  ++counters_.steps;
}

// Stage 1, Sec. 4. Broad phase: sort and sweep along x over axis-aligned bounds (grown by the
// contact margin), every plane against every movable body; the candidate pairs are then sorted
// by index, so the narrow phase, the manifolds and the rows come in the same order as testing
// every pair would give (Baraff 1992; Ericson 2005, Sec. 7.5).
void World::collide() {
  manifolds_.clear();
  if (!def_.collision) return;
  const int n = static_cast<int>(bodies_.size());
  bounds_.resize(bodies_.size());
  sweep_order_.clear();
  planes_.clear();
  pairs_.clear();
  const double grow = 0.5 * def_.contact_margin;
  for (int i = 0; i < n; ++i) {
    const Body& b = bodies_[static_cast<std::size_t>(i)];
    Vec3 half = Vec3::Zero();
    switch (b.shape.kind) {
      case ShapeKind::plane:
        planes_.push_back(i);
        continue;
      case ShapeKind::box:
        half = b.rotation().cwiseAbs() * b.shape.half_extents;
        break;
      case ShapeKind::sphere:
        half = Vec3::Constant(b.shape.radius);
        break;
    }
    bounds_[static_cast<std::size_t>(i)] = {b.x - half - Vec3::Constant(grow),
                                            b.x + half + Vec3::Constant(grow)};
    sweep_order_.push_back(i);
  }
  std::sort(sweep_order_.begin(), sweep_order_.end(), [this](int a, int b) {
    const double xa = bounds_[static_cast<std::size_t>(a)].lo.x();
    const double xb = bounds_[static_cast<std::size_t>(b)].lo.x();
    return xa < xb || (xa == xb && a < b);
  });
  for (std::size_t k = 0; k < sweep_order_.size(); ++k) {
    const int a = sweep_order_[k];
    const Bounds& ba = bounds_[static_cast<std::size_t>(a)];
    for (std::size_t m = k + 1; m < sweep_order_.size(); ++m) {
      const int b = sweep_order_[m];
      const Bounds& bb = bounds_[static_cast<std::size_t>(b)];
      if (bb.lo.x() > ba.hi.x()) break;
      if (bb.lo.y() > ba.hi.y() || ba.lo.y() > bb.hi.y() || bb.lo.z() > ba.hi.z() ||
          ba.lo.z() > bb.hi.z()) {
        continue;
      }
      if (bodies_[static_cast<std::size_t>(a)].is_static() && bodies_[static_cast<std::size_t>(b)].is_static()) continue;
      pairs_.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  for (const int p : planes_) {
    for (const int i : sweep_order_) {
      if (!bodies_[static_cast<std::size_t>(i)].is_static()) pairs_.emplace_back(std::min(p, i), std::max(p, i));
    }
  }
  std::sort(pairs_.begin(), pairs_.end());
  detail::reserve_with_headroom(manifolds_, pairs_.size());
  for (const auto& [a, b] : pairs_) {
    ++counters_.pairs_tested;
    Manifold m;
    m.body_a = a;
    m.body_b = b;
    if (cps::collide(bodies_[static_cast<std::size_t>(a)], bodies_[static_cast<std::size_t>(b)], m,
                     def_.contact_margin) > 0) {
      counters_.contacts += m.count;
      manifolds_.push_back(m);
    }
  }
}

// Stage 2, Sec. 5: contact and friction rows, then distance rows.
void World::build_rows() {
  rows_.clear();
  // The row count is known from the manifolds: make room once, with headroom (no allocation in
  // steady state).
  std::size_t contact_points = 0;
  for (const Manifold& m : manifolds_) contact_points += static_cast<std::size_t>(m.count);
  detail::reserve_with_headroom(
      rows_, contact_points * (def_.friction > 0.0 ? 3 : 1) + distances_.size());
  const RowParams params{def_.beta,    def_.dt,          def_.friction,
                         def_.gravity, def_.restitution, def_.restitution_threshold};
  for (const Manifold& m : manifolds_) append_contact_rows(m, bodies_, params, rows_);
  for (const DistanceConstraint& d : distances_) append_distance_row(d, bodies_, params, rows_);
  counters_.rows += static_cast<std::int64_t>(rows_.size());
}

void World::count_residual(double max, double sum_squares, std::int64_t rows) {
  residual_.max = std::max(residual_.max, max);
  residual_.sum_squares += sum_squares;
  residual_.rows += rows;
}

Eigen::VectorXd World::solve(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                             const RowLimits& limits) {
  ++counters_.solves;
  Eigen::VectorXd lambda = solve_lcp(A, b, limits, def_.friction_model, def_.solver, def_.iterations);
  if (def_.measure_residual) {
    const Eigen::VectorXd r = lcp_residual(A, b, limits, def_.friction_model, lambda);
    count_residual(r.size() > 0 ? r.maxCoeff() : 0.0, r.squaredNorm(), r.size());
  }
  return lambda;
}

// Stages 3-5, Secs. 6, 7, 3.2.
void World::solve_and_integrate() {
  gravity_forces(bodies_, def_.gravity, f_ext_);  // f_ext (6n), into a buffer that keeps its size
  lambda0_.clear();
  if (rows_.empty()) {
    lambda_.clear();
    integrate(bodies_, f_ext_, f_ext_, def_.dt, def_.rotation);
    return;
  }
  if (def_.assembly == Assembly::explicit_matrices) {
    solve_explicit();
  } else {
    solve_matrix_free();
  }
  // Positions move with f_cv; the stored momenta with f_c0 (Sec. 8.1), or f_cv for Baumgarte.
  integrate(bodies_, f_cv_, def_.push == PushMode::split ? f_c0_ : f_cv_, def_.dt, def_.rotation);
}

void World::solve_explicit() {
  const Eigen::VectorXd v1 = system_velocity(bodies_);
  const System sys =
      assemble_system(rows_, bodies_, v1, f_ext_, def_.dt, TargetTerms::push_and_bias);
  const Eigen::VectorXd lambda = solve(sys.A, sys.b, sys.limits);
  lambda_.assign(lambda.data(), lambda.data() + lambda.size());
  // f = f_ext + f_c with f_c = J^T lambda (Eq. 6.2.1).
  f_cv_ = f_ext_ + sys.J.transpose() * lambda;
  if (def_.push == PushMode::baumgarte) return;
  // Sec. 8.1: solve again with v holding only the bias (restitution), not the push.
  const Eigen::VectorXd b0 =
      assemble_rhs(rows_, sys.J, sys.M_inv, v1, f_ext_, def_.dt, TargetTerms::bias_only);
  const Eigen::VectorXd lambda0 = solve(sys.A, b0, sys.limits);
  lambda0_.assign(lambda0.data(), lambda0.data() + lambda0.size());
  f_c0_ = f_ext_ + sys.J.transpose() * lambda0;
}

void World::solve_matrix_free() {
  prepare(mf_, rows_, bodies_);
  const auto solve_once = [this](TargetTerms terms, std::vector<double>& lambda, Eigen::VectorXd& f) {
    rhs(mf_, rows_, bodies_, def_.gravity, def_.dt, terms);
    cps::solve(mf_, rows_, def_.friction_model, def_.solver, def_.iterations, lambda);
    ++counters_.solves;
    if (def_.measure_residual) {
      double max;
      double sum_squares;
      cps::residual(mf_, rows_, def_.friction_model, lambda, max, sum_squares);
      count_residual(max, sum_squares, static_cast<std::int64_t>(rows_.size()));
    }
    f = f_ext_;  // same size every step: no allocation
    add_constraint_forces(rows_, lambda, f);
  };
  solve_once(TargetTerms::push_and_bias, lambda_, f_cv_);
  if (def_.push == PushMode::split) solve_once(TargetTerms::bias_only, lambda0_, f_c0_);
}

}  // namespace cps
