#pragma once
// The matrix-free form of the solve of Sec. 6-7. A = J M^-1 J^T is never built: each body keeps
// w = M^-1 J^T lambda (6 numbers), so that sum_i A_ji lambda_i = j_j . w over the row's two
// bodies and a row update costs O(12). In the same row order it computes the same lambda as the
// explicit path (solve_lcp over the assembled A) up to round-off.

#include "cps/body.h"
#include "cps/constraint.h"
#include "row_colours.h"
#include "solver.h"
#include "system.h"
#include "workers.h"

#include <array>
#include <vector>

namespace cps {

using Vec6 = Eigen::Matrix<double, 6, 1>;  ///< per body: linear then angular part

/// One row packed for the sweep, everything the sweep reads in one contiguous block (as the
/// constraint parts of Box2D v3 and Jolt): its bodies (static bodies and a fixed world point
/// share the extra slot n, whose w stays 0 and is never written), j (12), M^-1 j^T (12), its
/// bounds and mu in Scalar (double, or float for RowPrecision::single_precision: 128 bytes a row,
/// two whole cache lines, instead of 240), and 1 / A_jj of the stored numbers in double. A row
/// with one movable body keeps it in half a (its halves are swapped if needed), so b == n marks a
/// one-body row.
template <class Scalar>
struct alignas(sizeof(Scalar) == sizeof(float) ? 64 : 16) PackedRow {
  std::array<Scalar, 12> j{};        ///< [j_a (6), j_b (6)]: the row of J
  std::array<Scalar, 12> minv_jt{};  ///< [M_a^-1 j_a (6), M_b^-1 j_b (6)]
  double inv_diagonal = 0.0;         ///< 1 / A_jj (kg); 0 for a row that touches no movable body
  Scalar c_min = 0;                  ///< lower force limit (N)
  Scalar c_max = 0;                  ///< upper force limit (N)
  Scalar mu = 0;                     ///< friction coefficient of a friction row (dimensionless)
  int normal_row = -1;               ///< a friction row's contact row (its position), for the coupled limit
  int a = 0;                         ///< body slot of half a
  int b = 0;                         ///< body slot of half b
};

/// Buffers of the matrix-free solve, sized by prepare() and reused from step to step, so a step
/// allocates nothing once they have reached their largest size.
struct MatrixFreeSystem {
  using Row = PackedRow<double>;
  using FloatRow = PackedRow<float>;
  /// Consecutive rows on the same two body slots (the rows of one manifold): PGS sweeps them as
  /// a block. Each sees the others' updates through the coupling A_ki / A_kk (k > i) instead of
  /// through w, so the rows of a run do not wait on each other's w stores and the first products
  /// j . w of a run are independent.
  ///
  /// Coloured PGS also sweeps kLanes runs of one colour with the same row count side by side,
  /// one run in each lane of 4-wide vectors: such a Run (lanes = kLanes) holds their rows
  /// interleaved (row i of lane L at position begin + lanes i + L) and their coupling likewise
  /// (entry e of lane L at offset + lanes e + L).
  struct Run {
    int begin = 0;   ///< first row
    int count = 0;   ///< rows of each run, 1..kMaxRun
    int offset = 0;  ///< start of its coupling (lanes m (m - 1) / 2 entries); -1: swept row by row
    int lanes = 1;   ///< runs side by side: 1, or kLanes
  };
  /// Runs a lane group sweeps side by side.
  static constexpr int kLanes = 4;
  /// Runs shorter than this (a single contact point: 3 rows) are swept row by row through w: for
  /// them the block measured no faster (funnel scene).
  static constexpr int kMinBlock = 4;
  /// Most rows in a run: the rows of a full manifold (a contact and two friction rows a point).
  static constexpr int kMaxRun = 3 * kMaxManifoldPoints;
  /// The packed rows in sweep order: position i holds row perm[i] (row order when perm is
  /// empty). A friction row's normal_row is a position too. `rows` for double precision,
  /// `float_rows` for single (the other is left empty).
  std::vector<Row> rows;
  std::vector<FloatRow> float_rows;
  RowPrecision precision = RowPrecision::double_precision;  ///< prepare()'s: which of the two
  /// Coloured PGS: the row at each position (c), the rows' sweep order by graph colour
  /// (row_colours.h); empty for PGS and Jacobi, which keep row order.
  std::vector<int> perm;
  std::vector<int> position;     ///< coloured PGS: perm's inverse (c; row index -> position)
  /// The runs, in sweep order. Coloured PGS: sweep colour k's (the k-th swept, sweep_colour(k))
  /// are runs[sweep_start[k], sweep_start[k + 1]).
  std::vector<Run> runs;
  ColourStarts sweep_start{};
  RowColours colours;            ///< coloured PGS: the rows' runs and colours
  bool runs_ready = false;       ///< runs and coupling's places built for these rows (prepare or first PGS solve)
  bool coupling_ready = false;   ///< coupling blocks formed (by the first sweep of a solve after the runs)
  /// Per block run of m rows: the strict lower triangle of its m x m coupling, column by column
  /// (column i: A_ki / A_kk for k = i+1..m-1; dimensionless), for double rows; `float_coupling`
  /// holds it rounded to float for float rows (the other is left empty).
  std::vector<double> coupling;
  std::vector<float> float_coupling;
  std::vector<double> diagonal;  ///< per position: A_jj = j M^-1 j^T (1/kg)
  std::vector<double> b;         ///< per position: right-hand side of Eq. 6.2.9 (m/s^2)
  std::vector<double> next;      ///< Jacobi: the sweep's new values (N)
  std::vector<double> swept;     ///< coloured PGS: lambda by position (N)
  std::vector<Vec6> w;           ///< per body, and one zero slot: M^-1 J^T lambda
  std::vector<Mat3> inv_inertia; ///< per body: world inverse inertia this step (1/(kg m^2))
};

/// Packs the rows (c) for bodies (n) and the sweeps of `kind`: j, minv_jt, diagonal, 1 / A_jj
/// and the bounds, and the world inverse inertia per body, resizing the buffers (no allocation
/// once they are big enough). For SolverKind::coloured_pgs it colours the rows first
/// (row_colours.h) and packs them in sweep order, so that the sweeps read them in order. Rows
/// refer to bodies by index or kWorldBody. The packing and the coupling blocks are shared among
/// `workers`' threads (nullptr: the calling thread; the same numbers for every count; the
/// colouring stays on one). `precision`: j, M^-1 j^T, the bounds and mu stored in double or
/// rounded to float (so is the coupling of a run, which the first sweep forms),
/// A_jj and the coupling then formed from the stored numbers (so the sweeps solve that system
/// consistently). `spans`: the rows' stretches on the same two bodies (colour_spans), given by
/// the row builder so that coloured PGS cuts its runs without reading every row; nullptr: cut
/// from the rows (the same runs). Source: Eq. 6.2.9, A_jj = j M^-1 j^T. Throws
/// std::invalid_argument when the spans' counts do not add up to c.
void prepare(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
             const std::vector<Body>& bodies, SolverKind kind, Workers* workers = nullptr,
             RowPrecision precision = RowPrecision::double_precision,
             const std::vector<RowSpan>* spans = nullptr);

/// Fills s.b (c): b_j = v_j / dt - j_j . (v1 / dt + M^-1 f_ext) (Eq. 6.2.9) with f_ext (6n:
/// force and torque per body, N and N m; the explicit path reads the same vector), v1 from the
/// bodies' momenta now and the inverse inertia of prepare(), and v_j the row's push and bias
/// (TargetTerms as in assemble_rhs; push_from_rest: b_j = push_j / dt). dt in s, > 0. Shared
/// among `workers`' threads as prepare(). No errors.
void rhs(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
         const std::vector<Body>& bodies, const Eigen::VectorXd& f_ext, double dt,
         TargetTerms terms, Workers* workers = nullptr);

/// Solves the bounded system with `iterations` sweeps of PGS, coloured PGS (in the sweep order of
/// prepare(), a colour's runs shared among `workers`' threads; nullptr: one thread; the same
/// lambda for every thread count; its blocks on 4-wide vectors, in AVX2 where the CPU has it and
/// SSE2 otherwise, the same numbers both ways) or Jacobi, the bounds of solve_lcp
/// (c_min, c_max from the rows, or the coupled friction limit), into lambda (resized to c, N).
/// It starts from `initial` (c values, N; warm starting, Sec. 6.2.3) when given, with
/// w = M^-1 J^T initial, else from lambda = 0 and w = 0; a row that touches no movable body
/// starts at 0 whatever the guess (as solve_lcp). s must be prepared for these rows and this
/// kind (coloured PGS or not), and s.b filled. Throws std::logic_error when it is not.
void solve(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows, FrictionModel friction,
           SolverKind kind, int iterations, std::vector<double>& lambda,
           const std::vector<double>* initial = nullptr, Workers* workers = nullptr);

/// f = f_ext + J^T lambda (6n, N and N m) for the lambda of the last solve(), per body from its
/// w = M^-1 J^T lambda: f_c = M w (Eq. 6.2.1), with m and the world inertia of prepare() (the
/// inverse of its I^-1), equal to the sum over the rows to round-off. A static body's entries
/// hold f_ext alone (its w is the fixed slot's 0). bodies: n, as given to prepare(); f_ext: 6n;
/// f resized to 6n (no allocation once it has it). Shared among `workers`' threads, the same
/// result for every count. No errors.
void constraint_forces(const MatrixFreeSystem& s, const std::vector<Body>& bodies,
                       const Eigen::VectorXd& f_ext, Eigen::VectorXd& f, Workers* workers = nullptr);

namespace detail {
/// Whether coloured PGS's sweeps may take their AVX2 build where the CPU has it (true by
/// default). Both builds give the same numbers; false runs the baseline build, for the test that
/// checks it. No errors.
void allow_coloured_avx2(bool allowed);
bool coloured_avx2_allowed();
/// Whether coloured PGS's prepare() may put runs side by side in lanes (Run::lanes; true by
/// default). Both ways give the same numbers; false sweeps every run on its own, for the test
/// that checks it. No errors.
void allow_coloured_lanes(bool allowed);
bool coloured_lanes_allowed();
}  // namespace detail

/// The natural-map residual of lcp_residual for the lambda that solve() left (using its w),
/// per row: the largest value and the sum of squares (N, N^2).
void residual(const MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
              FrictionModel friction, const std::vector<double>& lambda, double& max,
              double& sum_squares);

/// The system s holds, written out: A = J M^-1 J^T (c x c, 1/kg) from the packed rows' j and
/// M^-1 j^T, b (c, m/s^2)
/// and the limits (c each). For capturing a step (cps/step_system.h); not used by the sweeps.
/// s must be prepared and its b filled. No errors.
void explicit_system(const MatrixFreeSystem& s, SparseRowMatrix& A, Eigen::VectorXd& b,
                     RowLimits& limits);

}  // namespace cps
