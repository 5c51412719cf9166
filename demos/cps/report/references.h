#pragma once
// Solver error and time-step error apart (`cps report`): the solver error of sampled
// steps against their exact solution (demos/analysis/exact_lcp.h), the time until which two
// independent references of the trajectory agree (PGS at many sweeps, and the exact solve, at
// the same small dt), and the energy over time of each push method. The computations; the
// report's CSVs, diagrams and paragraphs of them are reference_report.h's.

#include "report/plan.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace cps::cli {

/// The sweep counts of PGS and Jacobi whose error the solver-error diagram draws (count).
inline constexpr int kSolverErrorSweepCounts[] = {1, 5, 25, 100};
/// Steps sampled along a run for the solver-error diagram (count): full and quick sweeps. Each
/// costs one exact solve (Siconos' Lemke), its nearest-solution projection and 8 sweeps.
inline constexpr int kSolverErrorSamples = 60;
inline constexpr int kSolverErrorSamplesQuick = 20;

/// One solve of a sampled step, judged against its exact solution (criteria.h).
struct SolverErrorPoint {
  std::int64_t step = 0;  ///< World::counters().steps before the step
  double t_s = 0.0;       ///< simulated time at the step's start (s)
  int solve = 0;          ///< which solve of the step (StepSystem::solve)
  int rows = 0;           ///< rows of the system (count)
  std::string method;     ///< "exact", "pgs" or "jacobi"
  int sweeps = 0;         ///< sweeps from lambda = 0 (0 for exact)
  /// |lambda - lambda*| / |lambda*| to the nearest exact solution (dimensionless); NaN when
  /// refused, +inf when the sweeps overflowed.
  double relative = std::nan("");
  /// dt |A (lambda - lambda*)| (m/s): the rows' velocity error after the step.
  double velocity_mps = std::nan("");
  /// The largest natural-map residual of lambda (N; 0 exactly at a solution).
  double residual_N = std::nan("");
  /// Why the exact solve refused this system ("" when it solved it): the point then has no
  /// errors, and the report lists it.
  std::string refused;
};

/// The solver error of `samples` (>= 1) steps spread evenly over the run of `spec` to its
/// horizon (RunSpec::horizon_s): every solve of each sampled step captured (World::set_solve_observer),
/// solved exactly, and PGS and Jacobi at kSolverErrorSweepCounts sweeps from 0 judged against
/// it; one "exact" point per solve (its residual) and one per method and count. `no_solve`
/// counts the sampled steps without a solve (no contact or rod). A run that blows up ends the
/// sampling. Throws UsageError for an unknown scene.
std::vector<SolverErrorPoint> sample_solver_error(const RunSpec& spec, int samples, int& no_solve);

/// The order a method shows between three runs at steps h, h / 2 and h / 4 (Richardson), and the
/// error that leaves the finest: with an error C h^p, the distances between successive runs are
/// d_coarse = C h^p (1 - 2^-p) (h against h / 2) and d_fine = d_coarse / 2^p (h / 2 against
/// h / 4), so p = log2(d_coarse / d_fine) and the finest run's error is d_fine / (2^p - 1).
/// Distances in any unit (m, deg), the error in the same.
struct ObservedOrder {
  double order = std::nan("");  ///< p (dimensionless); NaN if a distance is NaN or both are 0
  /// d_fine / (2^p - 1); 0 when d_fine is 0 (both 0: the runs agree exactly); NaN when p <= 0
  /// or a distance is NaN: the distances do not shrink with the step, and bound no error.
  double error = std::nan("");
};
ObservedOrder observed_order(double d_coarse, double d_fine);

/// The local order between two runs of errors e_a and e_b at n_a < n_b substeps (or iterations):
/// log(e_a / e_b) / log(n_b / n_a) (dimensionless; 1: the error halves when n doubles). NaN where
/// an error is not positive and finite or n_b <= n_a.
double local_order(double e_a, int n_a, double e_b, int n_b);

/// The distance (m) within which the two references must stay: this fraction (dimensionless) of
/// the largest movable body's size, 1 % (2.4 cm on the stack's 2.4 m cubes, 1 cm between the
/// funnel's 1 m balls): small beside the bodies, so that references within it draw the same
/// scene.
inline constexpr double kAgreementFraction = 0.01;
/// The most solves (with rows) the exact reference takes per scene (count): the check of the
/// agreement ends there. Measured in a quick report (load about 10 on 2 cores): 300 solves took
/// 1.3 s of CPU on the funnel (about 150 rows) and 0.55 s on the pendulum grid.
inline constexpr long kAgreementSolves = 3000;

/// The time (s) until which the distances `distance_m` (m) at the ascending times `t_s` (s)
/// stay within `tolerance_m`: the last time before the first distance beyond it (0 when the
/// first is beyond it, or NaN is met first), +inf when none is. Throws std::invalid_argument
/// when the lists differ in size.
double agreement_horizon(const std::vector<double>& t_s, const std::vector<double>& distance_m,
                         double tolerance_m);

/// Two references of a scene's trajectory at the same small dt (reference_substeps of the sweep
/// per 1/60 s frame: those of the trajectory error's reference; the run's push and friction
/// model, cold): PGS at kReferenceIterations sweeps, and the exact solve of every step's system
/// (World::set_solve_override with analysis::solve_exact), stepped side by side and compared
/// every step.
struct ReferenceAgreement {
  double tolerance_m = 0.0;  ///< kAgreementFraction of the largest movable body (m)
  std::vector<double> t_s;         ///< once a frame (1/60 s) and at the end: the time (s)
  std::vector<double> distance_m;  ///< the references' RMS distance then (m)
  /// agreement_horizon of every step's distance (s): +inf when they stayed within the tolerance
  /// until checked_until_s.
  double horizon_s = std::numeric_limits<double>::infinity();
  double checked_until_s = 0.0;  ///< how far they were stepped (s)
  /// Why they stopped before the requested time: "" (they reached it), the budget of exact
  /// solves (kAgreementSolves), an exact solve refused (its step and message), or a reference
  /// that blew up.
  std::string stopped;
  long exact_solves = 0;    ///< solves with rows the exact reference made (count)
  double exact_cpu_s = 0.0; ///< CPU time of the exact reference's steps (s, thread clock)
};

/// Steps the two references of `spec` (its solver, iterations, substeps and warm start replaced)
/// to `until_s` (s) or until max_solves exact solves (see ReferenceAgreement). Throws UsageError
/// for an unknown scene.
ReferenceAgreement compare_references(const RunSpec& spec, double until_s, long max_solves);

/// The agreement of a paper scene's references at the paper's push and friction model
/// (compare_references up to its trajectory time, kAgreementSolves), computed once per process
/// and kept; nullptr for a scene judged by its own reference solution (has_reference_solution)
/// or not one of the paper's.
/// `quick`: the quick sweep's (its reference_substeps).
const ReferenceAgreement* scene_agreement(const scenes::Scene& scene, bool quick);

/// The time (s) at which a run of `scene` measures its trajectory error: its
/// report_trajectory_time_s (within its horizon), or, when its references part before it
/// (scene_agreement of the sweep, quick or full), their horizon rounded down to a whole 1/60 s
/// frame, at least one frame.
double trajectory_time_of(const scenes::Scene& scene, bool quick);
/// trajectory_time_of with the references' agreement given (nullptr: none), as a report written
/// from the studies' CSVs has it. Steps no world. No errors.
double trajectory_time_with(const scenes::Scene& scene, const ReferenceAgreement* agreement);

/// One push method's energy over time at the paper's settings otherwise (PGS, 25 iterations,
/// 1 substep, fixed friction, cold): per recorded step (step 0, every `every`-th and the last)
/// the simulated time (s), kinetic, potential and total mechanical energy (J,
/// scenes::mechanical_energy), the deepest contact (m) and the largest rod length error (m).
struct EnergyTrace {
  std::string push;
  std::vector<double> t_s, kinetic_J, potential_J, total_J, penetration_m, rod_error_m;
  /// The time (s) the run blew up (sane_state), or NaN.
  double diverged_at_s = std::nan("");
};

/// The energy traces of `scene` for every push method of the table (parameter("push")), each
/// to the scene's report horizon (of the quick sweep when `quick`: Scene::report_horizon_s)
/// with at most `max_points` (>= 2) recorded steps. Throws UsageError for an unknown scene.
std::vector<EnergyTrace> energy_traces(const std::string& scene, int max_points, bool quick);

}  // namespace cps::cli
