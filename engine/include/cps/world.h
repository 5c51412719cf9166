#pragma once
// The world and its step. One step reads as the paper's stages, in order:
//   1. collide          Sec. 4    uniform grid broad phase, then manifolds for every pair
//                                 that can touch (skipped when the world has collision off)
//   2. build rows       Sec. 5    contact, friction (only with mu > 0) and distance rows
//   3. assemble         Sec. 6    J, M^-1, A and b of Eq. 6.2.9 (explicit), or per-row
//                                 M^-1 j^T, A_jj and b (matrix-free, the default)
//   4. solve            Sec. 7    lambda by PGS (or Jacobi); with the single frame push factor a
//                                 second solve with the push left out of v (Sec. 8.1)
//   5. integrate        Sec. 3.2  f = f_ext + J^T lambda, semi-implicit Euler

#include "cps/body.h"
#include "cps/collision.h"
#include "cps/constraint.h"
#include "cps/integrator.h"
#include "cps/matrix_free.h"
#include "cps/parameters.h"
#include "cps/solver.h"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace cps {

/// Work done by the steps so far, summed over the run.
struct StepCounters {
  std::int64_t steps = 0;
  std::int64_t pairs_tested = 0;  ///< body pairs handed to the narrow phase
  std::int64_t contacts = 0;      ///< contact points found
  std::int64_t rows = 0;          ///< constraint rows built
  std::int64_t solves = 0;        ///< solves of A lambda = b
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

  /// Adds a body and returns its index. Throws std::invalid_argument (see make_body) and leaves
  /// the world unchanged on bad input.
  int add_body(const BodyDef& def);

  /// Adds a distance constraint (Sec. 5.2) and returns its index. Throws std::invalid_argument
  /// naming the value, leaving the world unchanged, for a body index that does not exist or is
  /// static (body_a must be movable; body_b may be kWorldBody), equal bodies, non-finite points,
  /// or a length that is negative or not finite (m).
  int add_distance(const DistanceConstraint& d);

  /// Advances the world by def().dt (s).
  void step();

  const WorldDef& def() const { return def_; }
  const std::vector<Body>& bodies() const { return bodies_; }
  const Body& body(int i) const { return bodies_.at(static_cast<std::size_t>(i)); }
  const std::vector<DistanceConstraint>& distances() const { return distances_; }
  /// Simulated time (s): steps taken times dt.
  double time() const { return static_cast<double>(counters_.steps) * def_.dt; }
  const StepCounters& counters() const { return counters_; }
  const ResidualStats& residual() const { return residual_; }
  /// Manifolds found by the last step's collision stage (normals from a to b, depths in m).
  const std::vector<Manifold>& manifolds() const { return manifolds_; }
  /// Rows built by the last step (c of them) and lambda of its first solve (c, N).
  const std::vector<ConstraintRow>& rows() const { return rows_; }
  const std::vector<double>& lambda() const { return lambda_; }
  /// lambda of the last step's second solve (c, N; Sec. 8.1, push split only; empty otherwise).
  const std::vector<double>& lambda_second() const { return lambda0_; }

  /// Replaces the parameters (validated first: throws std::invalid_argument and keeps the old
  /// ones on a bad value). The bodies and constraints stay as they are.
  void set_def(const WorldDef& def);

 private:
  void collide();
  void broad_phase();
  void pairs_of_ungridded(std::size_t body);
  void build_rows();
  void solve_and_integrate();
  void solve_explicit();
  void solve_matrix_free();
  Eigen::VectorXd solve(const SparseRowMatrix& A, const Eigen::VectorXd& b, const RowLimits& l);
  void count_residual(double max, double sum_squares, std::int64_t rows);

  WorldDef def_;
  std::vector<Body> bodies_;
  std::vector<DistanceConstraint> distances_;
  std::vector<Manifold> manifolds_;
  std::vector<ConstraintRow> rows_;
  std::vector<double> lambda_;
  std::vector<double> lambda0_;
  // Buffers reused from step to step (the matrix-free path allocates nothing once they are big
  // enough): external and constraint forces per body (6n), the matrix-free system.
  Eigen::VectorXd f_ext_;
  Eigen::VectorXd f_cv_;
  Eigen::VectorXd f_c0_;
  MatrixFreeSystem mf_;
  // Broad phase (collide()): a uniform grid of cubic cells numbered into buckets, rebuilt every
  // step by a counting sort, so its cost grows linearly with the body count.
  struct Bounds {
    Vec3 lo;
    Vec3 hi;
  };
  enum class BroadClass : unsigned char { plane, gridded, oversize };
  // A gridded body as the grid stores it, by bucket: what the pair test needs, side by side.
  struct GridEntry {
    int body;                          // index
    bool is_static;
    std::array<std::int32_t, 3> cell;  // grid cell of the lower corner
    Bounds bounds;
  };
  std::vector<Bounds> bounds_;                       // per body, grown by the contact margin (m)
  std::vector<Mat3> rotations_;                      // per box or plane: R, for the narrow phase
  std::vector<BroadClass> broad_class_;              // per body
  std::vector<std::array<std::int32_t, 3>> cell_;    // per body: grid cell (gridded only)
  std::vector<std::uint32_t> bucket_of_;             // per body: its cell's bucket (gridded only)
  std::vector<int> bucket_start_;                    // buckets + 2: k is [start[k], start[k+1])
  std::vector<GridEntry> grid_;                      // gridded bodies by bucket, then index
  std::vector<double> widths_;                       // scratch: widths (m) for the median
  std::vector<int> planes_;                          // plane bodies, by index
  std::vector<int> oversize_;                        // bodies too wide for the grid, by index
  std::vector<int> candidates_;                      // scratch (n + planes): b > a near a
  std::vector<std::pair<int, int>> pairs_;           // candidate pairs (a < b), in index order
  // build_rows(): body velocities of this step (n), and which of them are computed.
  std::vector<BodyVelocity> velocities_;
  std::vector<unsigned char> velocity_known_;
  StepCounters counters_;
  ResidualStats residual_;
};

}  // namespace cps
