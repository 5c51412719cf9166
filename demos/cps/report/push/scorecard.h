#pragma once
// The mass ratio scorecard of `cps report push`: for every push method, the top-to-bottom mass
// ratios that a 2-box stack, a 4-box stack and a rope holding a heavy end keep for 10 s from a
// standing start, at the paper's settings and at the settings of the method's own source, and
// beside them the paper's push with every step's A lambda = b solved exactly (Siconos).

#include "report/csv.h"
#include "report/push/cases.h"

#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cps::cli {

/// The scorecard's ratios are 2^1, 2^2, ..., 2^kScoreRatioPowers (dimensionless).
inline constexpr int kScoreRatioPowers = 17;
/// How long each run lasts (s of simulated time).
inline constexpr double kScoreSeconds = 10.0;
/// At the end (the last HardCaseWatch::kHoldS of the run) a held case has no overlap deeper than
/// the method's penetration slop by more than this, and no rod off its length by more (m).
inline constexpr double kScoreErrorM = 1e-3;
/// ... and no body's centre faster than this (m/s).
inline constexpr double kScoreSpeedMps = 1e-3;

/// The exact row's solves count as exact when their natural-map residual is under this fraction
/// of the problem's force scale (analysis::solve_exact(s, tolerance)): 1e-6, where the reference's
/// 1e-9 refuses many steps of the stacks' redundant corner contacts.
inline constexpr double kScoreExactTolerance = 1e-6;

/// The three cases, each built at rest on its supports (scenes/stress):
/// - two_box: a cube of R kg on a cube of 1 kg on the ground (populate_mass_ratio_stack, 2);
/// - four_box: four 1 kg to R kg cubes, each R^(1/3) times the one below (the same, 4);
/// - rope: a block of R times a link's mass on 20 rods and links (populate_heavy_rope_ratio).
enum class ScoreCase { two_box, four_box, rope };
inline constexpr std::array<ScoreCase, 3> kScoreCases = {ScoreCase::two_box, ScoreCase::four_box,
                                                         ScoreCase::rope};

/// The case's name in score.csv ("2-box", "4-box", "rope"). No errors.
const char* score_case_name(ScoreCase c);

/// Where a row's settings come from: the paper's (the cases' world: dt 1/60 s, 25 PGS sweeps,
/// beta 0.2, mu 0.5, with only push changed) or the method's own source's (score_source).
enum class ScoreSettings { paper, source };

/// One row of the scorecard: a method at a setting, the tuned avbd (penalties started at
/// kTunedAvbdKStart), or the exact solve (the paper's push and settings, every solve replaced by
/// analysis::solve_exact through World::set_solve_override).
struct ScoreRow {
  Method method;
  ScoreSettings settings = ScoreSettings::paper;
  std::optional<double> k_start;  ///< N/m: avbd_k_start of the tuned row
  bool exact = false;

  /// What score.csv's column variant says: "", "avbd_k_start=1e+06" or "exact solve".
  std::string variant() const;
};

/// One run: a row's case at one ratio.
struct ScoreCell {
  double ratio = 0.0;  ///< top (or end) mass over bottom (or link) mass, dimensionless
  /// Whether it held: it stayed sane, no body left its place (its centre farther than half the
  /// cube edge, or a link's radius for the rope, from where it was built, for
  /// HardCaseWatch::kHoldS; as the hard cases count it) in the whole run, and over the last
  /// HardCaseWatch::kHoldS the constraint error and the speeds stayed within kScoreErrorM and
  /// kScoreSpeedMps. nullopt: not run (skipped says why).
  std::optional<bool> held;
  /// Why it did not hold, the first of: "diverged at T s", "left at T s", "not in place at the
  /// end", "error E m", "speed V m/s"; or why it was not run (the exact solve's refusal); ""
  /// when it held.
  std::string why;
  double end_error_m = std::nan("");    ///< m: largest overlap beyond the slop, or rod error, at the end
  double end_speed_mps = std::nan("");  ///< m/s: largest centre speed at the end
  double seconds = 0.0;                 ///< s: simulated until (a run that left or diverged stops there)
};

/// The world of a row's case: the case's paper world (mass_ratio_world_def, heavy_rope_world_def)
/// with the row's push, or for ScoreSettings::source that method's source settings on top
/// (score_source), the case's friction kept; avbd_k_start from the row. Throws std::logic_error
/// if a scene the source settings come from is missing from this build.
WorldDef score_world(ScoreCase c, const ScoreRow& row);

/// The source of a method's own settings and what they are, a sentence for push.md's legend.
/// No errors.
std::string score_source(const Method& m);

/// Runs one cell: the case at `ratio` (> 0) under `row` for kScoreSeconds, stopping early once
/// a body has left its place or the state is not sane. An exact row whose solve fails (no
/// Siconos, or a step it refuses) gives held = nullopt with the reason. No other errors.
ScoreCell run_score_cell(ScoreCase c, double ratio, const ScoreRow& row);

/// The scorecard's rows: every method of `methods` at the paper's and at its source's settings,
/// then avbd tuned at both (if avbd is among them), then the exact solve.
std::vector<ScoreRow> score_rows(const std::vector<Method>& methods);

/// A row with its cells: cells[case][k] is the ratio 2^(k + 1).
struct ScoreResult {
  ScoreRow row;
  std::array<std::vector<ScoreCell>, 3> cells;
};

/// Runs every cell of every row, calling tick after each (rows x 3 x kScoreRatioPowers calls).
std::vector<ScoreResult> run_scorecard(const std::vector<ScoreRow>& rows,
                                       const std::function<void()>& tick);

/// The largest ratio R such that every ratio of the scorecard up to R held (0 when 2 did not): a
/// cell that was not run ends the count as one that failed. No errors.
double held_up_to(const std::vector<ScoreCell>& cells);

/// score.csv: a row per cell; columns settings, push, variant, case, mass_ratio, held (1, 0 or
/// "" when not run), why, end_error_m, end_speed_mps, seconds_s, dt_s, iterations.
CsvTable score_table(const std::vector<ScoreResult>& results);

/// push.md's scorecard section: the legend, a summary table (held up to, per case and setting)
/// and a table per case of every ratio. No errors.
std::string score_markdown(const std::vector<ScoreResult>& results,
                           const std::vector<Method>& methods);

}  // namespace cps::cli
