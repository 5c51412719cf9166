// The step: collide, build rows, assemble, solve, integrate (see world.h).
#include "cps/world.h"

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
  if (!gravity.allFinite()) bad_parameter("gravity", gravity.norm(), "it must be finite (m/s^2)");
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
  } else if (!d.local_a.allFinite() || !d.local_b.allFinite()) {
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

// Stage 1, Sec. 4: every pair with at least one movable body, in index order.
void World::collide() {
  manifolds_.clear();
  if (!def_.collision) return;
  const int n = static_cast<int>(bodies_.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const Body& ba = bodies_[static_cast<std::size_t>(a)];
      const Body& bb = bodies_[static_cast<std::size_t>(b)];
      if (ba.is_static() && bb.is_static()) continue;
      ++counters_.pairs_tested;
      Manifold m;
      m.body_a = a;
      m.body_b = b;
      if (cps::collide(ba, bb, m, def_.contact_margin) > 0) {
        counters_.contacts += m.count;
        manifolds_.push_back(m);
      }
    }
  }
}

// Stage 2, Sec. 5: contact and friction rows, then distance rows.
void World::build_rows() {
  rows_.clear();
  const RowParams params{def_.beta,    def_.dt,          def_.friction,
                         def_.gravity, def_.restitution, def_.restitution_threshold};
  for (const Manifold& m : manifolds_) append_contact_rows(m, bodies_, params, rows_);
  for (const DistanceConstraint& d : distances_) append_distance_row(d, bodies_, params, rows_);
  counters_.rows += static_cast<std::int64_t>(rows_.size());
}

Eigen::VectorXd World::solve(const SparseRowMatrix& A, const Eigen::VectorXd& b,
                             const RowLimits& limits) {
  ++counters_.solves;
  Eigen::VectorXd lambda = solve_lcp(A, b, limits, def_.friction_model, def_.solver, def_.iterations);
  if (def_.measure_residual) {
    const Eigen::VectorXd r = lcp_residual(A, b, limits, def_.friction_model, lambda);
    residual_.max = std::max(residual_.max, r.size() > 0 ? r.maxCoeff() : 0.0);
    residual_.sum_squares += r.squaredNorm();
    residual_.rows += r.size();
  }
  return lambda;
}

// Stages 3-5, Secs. 6, 7, 3.2.
void World::solve_and_integrate() {
  const Eigen::VectorXd f_ext = gravity_forces(bodies_, def_.gravity);
  if (rows_.empty()) {
    lambda_.resize(0);
    integrate(bodies_, f_ext, f_ext, def_.dt, def_.rotation);
    return;
  }
  const Eigen::VectorXd v1 = system_velocity(bodies_);
  const System sys =
      assemble_system(rows_, bodies_, v1, f_ext, def_.dt, TargetTerms::push_and_bias);
  lambda_ = solve(sys.A, sys.b, sys.limits);
  // f = f_ext + f_c with f_c = J^T lambda (Eq. 6.2.1).
  const Eigen::VectorXd f_cv = f_ext + sys.J.transpose() * lambda_;
  if (def_.push == PushMode::baumgarte) {
    integrate(bodies_, f_cv, f_cv, def_.dt, def_.rotation);
    return;
  }
  // Sec. 8.1: solve again with v holding only the bias (restitution), not the push; positions
  // move with f_cv, the stored momenta with f_c0.
  const Eigen::VectorXd b0 =
      assemble_rhs(rows_, sys.J, sys.M_inv, v1, f_ext, def_.dt, TargetTerms::bias_only);
  const Eigen::VectorXd lambda0 = solve(sys.A, b0, sys.limits);
  const Eigen::VectorXd f_c0 = f_ext + sys.J.transpose() * lambda0;
  integrate(bodies_, f_cv, f_c0, def_.dt, def_.rotation);
}

}  // namespace cps
