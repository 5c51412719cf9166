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
}

World::World(const WorldDef& def) : def_(def) { def_.validate(); }

int World::add_body(const BodyDef& def) {
  bodies_.push_back(make_body(def));  // make_body throws before anything is added
  return static_cast<int>(bodies_.size()) - 1;
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
      if (cps::collide(ba, bb, m) > 0) {
        counters_.contacts += m.count;
        manifolds_.push_back(m);
      }
    }
  }
}

// Stage 2, Sec. 5: contact and friction rows.
void World::build_rows() {
  rows_.clear();
  const RowParams params{def_.beta, def_.dt, def_.friction, def_.gravity};
  for (const Manifold& m : manifolds_) append_contact_rows(m, bodies_, params, rows_);
}

// Stages 3-5, Secs. 6, 7, 3.2.
void World::solve_and_integrate() {
  const Eigen::VectorXd f_ext = gravity_forces(bodies_, def_.gravity);
  if (rows_.empty()) {
    lambda_.resize(0);
    integrate(bodies_, f_ext, f_ext, def_.dt);
    return;
  }
  const Eigen::VectorXd v1 = system_velocity(bodies_);
  const System sys =
      assemble_system(rows_, bodies_, v1, f_ext, def_.dt, TargetTerms::push_and_bias);
  lambda_ = solve_pgs(sys.A, sys.b, sys.c_min, sys.c_max, def_.iterations);
  ++counters_.solves;
  counters_.rows += static_cast<std::int64_t>(rows_.size());
  // f = f_ext + f_c with f_c = J^T lambda (Eq. 6.2.1).
  const Eigen::VectorXd f = f_ext + sys.J.transpose() * lambda_;
  integrate(bodies_, f, f, def_.dt);
}

}  // namespace cps
