#pragma once
// The rows of one solve of A lambda = b as CSV, so that anyone can solve the step again with
// cps's own bounds: written beside `cps export --fclib`'s files and `cps simulate
// --solver-error`'s CSV.

#include "cps/step_system.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace cps::cli {

/// The columns of system_rows: row, kind (contact, friction or rod), then `place` if given,
/// c_min_N, c_max_N (the row's bounds, N), mu (its friction coefficient, dimensionless),
/// normal_row (a friction row's contact row, -1 for none), b_mps2 (b_j, m/s^2), A_jj_per_kg
/// (A's diagonal, 1/kg), lambda_engine_N (the engine's lambda) and lambda_exact_N (`exact`, N).
/// `place_column` names the optional column ("" for none).
std::string system_rows_header(const std::string& place_column);

/// One CSV line per row of `s`, each starting with `leading` (e.g. "300,0," for columns the
/// caller adds in front), numbers to 17 significant digits. `place` (s.rows() entries, or empty
/// for no such column) fills the column after kind. `exact` (s.rows() entries, N; empty: the
/// column left empty) is an exact solution of the step, e.g. its least-norm one.
std::string system_rows(const StepSystem& s, const std::string& leading,
                        const std::vector<std::string>& place, const Eigen::VectorXd& exact);

}  // namespace cps::cli
