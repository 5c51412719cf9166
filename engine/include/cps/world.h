#pragma once
// The world and its step. One step reads as the paper's stages, in order:
//   1. collide          Sec. 4    manifolds for every pair that can touch
//   2. build rows       Sec. 5    contact and friction rows per contact point
//   3. assemble         Sec. 6    J, M^-1, A and b of Eq. 6.2.9
//   4. solve            Sec. 7    projected Gauss-Seidel for lambda
//   5. integrate        Sec. 3.2  f = f_ext + J^T lambda, semi-implicit Euler

#include "cps/body.h"
#include "cps/collision.h"
#include "cps/constraint.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace cps {

/// World parameters, each with its unit and a typical value. Validate with validate().
struct WorldDef {
  Vec3 gravity = Vec3(0.0, -10.0, 0.0);  ///< m/s^2; the paper uses (0, -10, 0)
  double dt = 1.0 / 60.0;                ///< time step (s), > 0; the paper uses 1/60
  int iterations = 25;                   ///< PGS sweeps per solve, >= 1; the paper uses 25
  double beta = 0.2;                     ///< push factor constant (dimensionless) in [0, 1]; 0.2
  double friction = 0.5;                 ///< friction coefficient mu (dimensionless) >= 0; 0.5

  /// Throws std::invalid_argument naming the parameter, its value and what is allowed.
  void validate() const;
};

/// Work done by the steps so far, summed over the run.
struct StepCounters {
  std::int64_t steps = 0;
  std::int64_t pairs_tested = 0;  ///< body pairs handed to the narrow phase
  std::int64_t contacts = 0;      ///< contact points found
  std::int64_t rows = 0;          ///< constraint rows solved (counted once per solve)
  std::int64_t solves = 0;        ///< PGS solves
};

/// A set of bodies stepped by the constraint solver. Bodies are referred to by index, in the
/// order they were added; the order of every loop depends on indices only.
class World {
 public:
  /// Throws std::invalid_argument if def is invalid (see WorldDef::validate).
  explicit World(const WorldDef& def = {});

  /// Adds a body and returns its index. Throws std::invalid_argument (see make_body) and leaves
  /// the world unchanged on bad input.
  int add_body(const BodyDef& def);

  /// Advances the world by def().dt (s).
  void step();

  const WorldDef& def() const { return def_; }
  const std::vector<Body>& bodies() const { return bodies_; }
  const Body& body(int i) const { return bodies_.at(static_cast<std::size_t>(i)); }
  /// Simulated time (s): steps taken times dt.
  double time() const { return static_cast<double>(counters_.steps) * def_.dt; }
  const StepCounters& counters() const { return counters_; }
  /// Manifolds found by the last step's collision stage (normals from a to b, depths in m).
  const std::vector<Manifold>& manifolds() const { return manifolds_; }
  /// Rows built by the last step (c of them) and their lambda (c, N).
  const std::vector<ConstraintRow>& rows() const { return rows_; }
  const Eigen::VectorXd& lambda() const { return lambda_; }

 private:
  void collide();
  void build_rows();
  void solve_and_integrate();

  WorldDef def_;
  std::vector<Body> bodies_;
  std::vector<Manifold> manifolds_;
  std::vector<ConstraintRow> rows_;
  Eigen::VectorXd lambda_;
  StepCounters counters_;
};

}  // namespace cps
