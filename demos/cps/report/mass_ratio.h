#pragma once
// The mass ratio study of the report: a heavy cube resting on a light one (stress scenes
// mass_ratio_R), run for each ratio, solver and push method; does the stack hold?

#include "report/csv.h"
#include "scene.h"
#include "stress/mass_ratio.h"

#include <cmath>
#include <string>
#include <vector>

namespace cps::cli {

/// The mass ratios R (heavy cube mass / light cube mass, dimensionless) of the report's mass
/// ratio table (stress scenes mass_ratio_R), ascending.
inline constexpr double kMassRatios[] = {10.0, 100.0, 1000.0};

/// How long each run of the mass ratio table lasts (s of simulated time).
inline constexpr double kPairSeconds = 5.0;

/// The iteration count of the table's main columns (the paper's).
inline constexpr int kPairTableIterations = 25;

/// How far the heavy cube's centre may be from its stacked height and the pair still count as
/// held (m): h / 2 (h = scenes::kMassRatioHalfEdge), a light cube crushed by under a quarter of
/// its edge. Squeezed out from under, the heavy cube drops to h, 2 h lower.
inline constexpr double kHeldHeightTolerance = 0.5 * scenes::kMassRatioHalfEdge;
/// The overlap (m) under which a pair that is stacked also counts as holding (iterations_holding,
/// and the report's column): 1 cm, a fiftieth of the cubes' half edge.
inline constexpr double kHoldingOverlapM = 0.01;

/// The heavy cube's stacked height (m): 3 h, on the light cube, on the ground.
inline constexpr double kStackedHeight = 3.0 * scenes::kMassRatioHalfEdge;

/// The mass ratio pair (stress scenes mass_ratio_R: a heavy cube of R kg resting on a light cube
/// of 1 kg on the ground, both of half edge h = scenes::kMassRatioHalfEdge) at the end of a run.
struct PairOutcome {
  bool finite = false;                    ///< false: the run blew up (nothing below is measured)
  double light_offset_m = std::nan("");   ///< light cube centre to the heavy cube's vertical axis
  double heavy_height_m = std::nan("");   ///< heavy cube centre height; 3 h = 1.5 m when stacked
  double overlap_m = std::nan("");        ///< deepest overlap between any two bodies now (m)
  /// Held: the light cube is still between the heavy cube and the ground, its centre within h
  /// of the heavy cube's vertical axis and the heavy cube's centre within kHeldHeightTolerance
  /// of its stacked height kStackedHeight.
  bool held = false;
};

/// Runs the pair of mass ratio `ratio` (> 0) from rest for `seconds` (s) at the paper's settings
/// (scenes::mass_ratio_world_def(): 60 Hz, beta 0.2, mu 0.5) with this solver, push and
/// iteration count (>= 1). A run that blows up (sane_state) stops and returns finite = false.
PairOutcome run_pair(double ratio, SolverKind solver, PushMode push, int iterations,
                     double seconds);

/// One row of the mass ratio table: a ratio, solver and push; the pair after kPairSeconds at
/// kPairTableIterations iterations; and the iteration counts of 1, 2, 4, ..., 256 with which it
/// holds with under 1 cm of overlap, ascending (holding need not be monotone in the count).
struct PairRow {
  double mass_ratio = 0.0;
  SolverKind solver = SolverKind::pgs;
  PushMode push = PushMode::baumgarte;
  PairOutcome outcome;
  std::vector<int> iterations_holding;
};

/// The rows of the mass ratio table, not yet run (outcome and iterations_holding empty): a row
/// per ratio of kMassRatios, push method (every choice of the world parameter push, in the
/// table's order) and solver (pgs, jacobi; pgs alone for a push that does not read the solver,
/// push_reads), in that order.
std::vector<PairRow> mass_ratio_rows();

/// The study id of a row (studies.h): "mass_ratio.R.SOLVER.PUSH", R as number() writes it
/// ("mass_ratio.1000.jacobi.split"). No errors.
std::string pair_id(const PairRow& row);

/// Runs one row of mass_ratio_rows: its outcome at kPairTableIterations and the iteration
/// counts 1, 2, 4, ..., 256 that hold (run_pair, kPairSeconds each). Rows are independent.
void run_pair_row(PairRow& row);

/// The table as mass_ratio.csv: columns study (pair_id), solver, push, iterations, mass_ratio, seconds (s), held
/// (1 or 0), heavy_height_m, light_offset_m, overlap_m (m; "" where the run blew up) and
/// iterations_holding (space-separated counts).
CsvTable mass_ratio_table(const std::vector<PairRow>& rows);

}  // namespace cps::cli
